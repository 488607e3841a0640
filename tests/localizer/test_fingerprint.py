"""localizer.fingerprint: one name per geometry, whatever the file is called, and another for any change."""

import json
from pathlib import Path

import numpy as np
import pytest

from localizer import QUANTUM_MM, fingerprint, load_part, part_from_points

PARTS = Path(__file__).resolve().parents[2] / "parts"
SHIPPED = ("cam.json", "trefoil.json", "ellipse.json", "kidney.csv", "bracket.dxf", "profile.svg")


def test_a_file_read_twice_or_copied_under_another_name_has_one_fingerprint(tmp_path):
    for name in SHIPPED:
        copy = tmp_path / f"renamed{Path(name).suffix}"
        copy.write_bytes((PARTS / name).read_bytes())
        once = fingerprint(load_part(PARTS / name))
        assert once == fingerprint(load_part(PARTS / name)) == fingerprint(load_part(copy))


def test_every_shipped_part_has_its_own():
    marks = [fingerprint(load_part(PARTS / name)) for name in SHIPPED]
    assert len(set(marks)) == len(marks)
    assert all(len(m) == 16 and int(m, 16) >= 0 for m in marks)


@pytest.mark.parametrize("move_mm", [3.0, 1e-3])
def test_a_knot_moved_changes_it(move_mm):
    doc = json.loads((PARTS / "cam.json").read_text())
    before = fingerprint(part_from_points(doc["points"]))
    points = np.array(doc["points"], dtype=float)
    points[5, 1] += move_mm
    assert fingerprint(part_from_points(points)) != before


def test_other_units_are_another_part(tmp_path):
    doc = json.loads((PARTS / "trefoil.json").read_text())
    inches = tmp_path / "trefoil-in.json"
    inches.write_text(json.dumps(dict(doc, units="in")))
    assert fingerprint(load_part(inches)) != fingerprint(load_part(PARTS / "trefoil.json"))


def test_rounding_keeps_arithmetic_noise_out():
    # the same shape computed through another route (a shift there and back) lands on the same quanta
    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    pts = np.c_[30 * np.cos(a), 18 * np.sin(a)]
    there_and_back = (pts + 1234.5678) - 1234.5678
    assert np.abs(there_and_back - pts).max() < 1e-9 < QUANTUM_MM
    assert fingerprint(part_from_points(there_and_back)) == fingerprint(part_from_points(pts))
