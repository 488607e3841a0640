"""The simulated worlds' dense samples of a part and its machining's harmonics are sized before they are built
(localizer.check_grid): a part too long for them is refused by name with the figure, at once; the largest
generated parts are not."""

import tracemalloc
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

import localizer.geometry._limits as limits
from localizer import Line, PartError, load_part, outline_from_pieces, part_from_points
from sim2d.machining import machined_part
from sim2d.noise import load_noise
from sim2d.sampled import model_sample
from sim2d.wheel_world import WheelWorld

ROOT = Path(__file__).resolve().parents[2]


@contextmanager
def nothing_built():
    """The block allocates under 64 MB: what it refuses would take gigabytes (counted, not timed, so that a
    loaded machine does not matter)."""
    tracemalloc.start()
    try:
        yield
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64 * 2**20


class Passed(Exception):
    """The sample's check passed (raised in place of sampling)."""


def test_a_drawing_in_metres_is_refused_before_it_is_sampled():
    big = outline_from_pieces(
        [Line((0, 0), (1e6, 0)), Line((1e6, 0), (1e6, 5e5)), Line((1e6, 5e5), (0, 5e5)), Line((0, 5e5), (0, 0))],
        name="rect",
    )
    with (
        nothing_built(),
        pytest.raises(
            PartError,
            match=r"part 'rect' is 3 000 000 mm around: the simulated part's grid every 0\.005 mm "
            r"would need 6e8 points",
        ),
    ):
        model_sample(big)


def test_the_wheel_world_refuses_a_spline_part_in_metres():
    a = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    big = part_from_points(np.c_[5e3 * np.cos(a), 3e3 * np.sin(a)], name="oval")
    with (
        nothing_built(),
        pytest.raises(PartError, match=r"part 'oval' is 25 \d{3} mm around: the wheel world's grid every 0\.01 mm"),
    ):
        WheelWorld(big, big, 5.0)


def test_the_machining_of_a_part_in_kilometres_is_refused_before_its_harmonics_are_summed():
    a = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    big = part_from_points(np.c_[1e8 * np.cos(a), 6e7 * np.sin(a)], name="oval")
    with (
        nothing_built(),
        pytest.raises(
            PartError,
            match=r"part 'oval' is 5\.1e8 mm around: the simulated machining's grid every 20 mm would need 2\.6e7 "
            r"harmonics, more than the 262 144 it may have; is the part in the right units \(mm\), and "
            r"machining_wavelength=20 mm meant\?",
        ),
    ):
        machined_part(big, load_noise("paper"), np.random.default_rng(0))


@pytest.mark.parametrize(
    "name",
    ["heldout-e/glyph-18.json", "heldout-g/star-12.json", "cad-heldout/plate-04.dxf", "cad-heldout-e/plate-08.dxf"],
)
def test_the_largest_generated_parts_are_sampled(name, monkeypatch):
    part = load_part(ROOT / "bench/parts" / name)

    def check_then_stop(*args, **kwargs):
        limits.check_grid(*args, **kwargs)
        raise Passed

    monkeypatch.setattr("sim2d.sampled.check_grid", check_then_stop)
    monkeypatch.setattr("sim2d.wheel_world.check_grid", check_then_stop)
    monkeypatch.setattr("sim2d.machining.check_grid", check_then_stop)
    with pytest.raises(Passed):
        model_sample(part)
    if not part.corners:
        with pytest.raises(Passed):
            WheelWorld(part, part, 5.0)
        with pytest.raises(Passed):
            machined_part(part, load_noise("paper"), np.random.default_rng(0))
