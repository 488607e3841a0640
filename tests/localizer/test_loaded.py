"""Parts read from files are kept while the file's bytes are the same (localizer.geometry._loaded)."""

import os

import numpy as np
import pytest

from localizer import PartError, WheelJaw, forget_loaded, load_outline, load_part, wheel_reach_for
from localizer.geometry import LOADED_PARTS


def _circle_file(path, radius):
    """A 24-point circle of ``radius`` mm as x,y rows of fixed width (the file's size does not depend on it)."""
    a = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    path.write_text("".join(f"{x:+09.3f},{y:+09.3f}\n" for x, y in zip(radius * np.cos(a), radius * np.sin(a))))


def test_the_same_file_read_again_is_the_same_part_with_its_tables():
    first = load_part("parts/kidney.csv")
    reach = wheel_reach_for(first, WheelJaw(5.0))
    again = load_part("parts/kidney.csv")
    assert again is first and wheel_reach_for(again, WheelJaw(5.0)) is reach
    assert load_part("parts/bracket.dxf") is load_part("parts/bracket.dxf")


def test_a_file_edited_to_the_same_size_and_time_stamp_is_read_again(tmp_path):
    """The key is the bytes, not the file's size or time stamp: a 10 mm circle rewritten as a 20 mm one of
    the same length, its time stamp set back, reads as the 20 mm circle (perimeter within 0.1% of 2πr)."""
    path = tmp_path / "c.csv"
    _circle_file(path, 10.0)
    small = load_part(path)
    stat = path.stat()
    _circle_file(path, 20.0)
    assert path.stat().st_size == stat.st_size
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    large = load_part(path)
    assert large is not small
    assert large.perimeter == pytest.approx(2 * np.pi * 20.0, rel=1e-3)
    assert small.perimeter == pytest.approx(2 * np.pi * 10.0, rel=1e-3)


def test_a_refused_file_is_not_kept(tmp_path):
    path = tmp_path / "c.csv"
    path.write_text("0,0\n1,0\n")
    with pytest.raises(PartError, match="4 points|fewer"):
        load_part(path)
    with pytest.raises(PartError, match="4 points|fewer"):
        load_part(path)  # asked again: refused again, not an earlier answer
    _circle_file(path, 10.0)
    assert load_part(path).perimeter == pytest.approx(2 * np.pi * 10.0, rel=1e-3)


def test_a_drawing_read_with_other_options_is_another_outline():
    drawn = load_outline("parts/profile.svg", facets=None)
    assert drawn is not load_outline("parts/profile.svg")
    assert drawn is load_outline("parts/profile.svg", facets=None)


def test_at_most_LOADED_PARTS_are_kept_the_least_recently_read_dropped_first(tmp_path):
    forget_loaded()
    paths = []
    for k in range(LOADED_PARTS + 1):
        paths.append(tmp_path / f"c{k}.csv")
        _circle_file(paths[-1], 10.0 + k)
    first = load_part(paths[0])
    second = load_part(paths[1])
    for p in paths[2:LOADED_PARTS]:
        load_part(p)
    assert load_part(paths[0]) is first  # read again: now the most recent
    load_part(paths[LOADED_PARTS])  # one more than is kept: the least recent (paths[1]) goes
    assert load_part(paths[0]) is first
    assert load_part(paths[1]) is not second


def test_forget_loaded_reads_every_file_again():
    first = load_part("parts/trefoil.json")
    forget_loaded()
    again = load_part("parts/trefoil.json")
    assert again is not first and np.array_equal(again.points, first.points)
