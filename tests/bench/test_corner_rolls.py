"""Rolls that start or end exactly at a drawing's corner: the solver against bench.corner_rolls' reference
built from the pieces (issue 30: one rule for "at a corner")."""

import math
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bench.corner_rolls import CornerRoll, TurningReference, check_rolls, corner_rolls
from localizer import Line, load_outline, outline_from_pieces

ROOT = Path(__file__).resolve().parents[2]
# the shipped drawings, and a held-out cam whose corners a sum of arcs reaches through the seam
DRAWINGS = ["parts/bracket.dxf", "parts/profile.svg", "bench/parts/cad-heldout/cam-09.svg"]


@cache
def drawing(name):
    outline = load_outline(ROOT / name)
    return outline, TurningReference(outline)


def test_the_reference_turns_once_and_knows_a_rectangles_corners():
    pts = [(0, 0), (40, 0), (40, 20), (0, 20)]
    box = outline_from_pieces([Line(pts[i], pts[(i + 1) % 4]) for i in range(4)])
    ref = TurningReference(box)
    assert ref.total == pytest.approx(2 * math.pi, abs=1e-12)
    assert ref.range(40.0) == pytest.approx((0.0, math.pi / 2))
    assert ref.range(120.0) == pytest.approx((2 * math.pi - math.pi / 2, 2 * math.pi))  # the seam, a lap on
    assert ref.range(50.0) == pytest.approx((math.pi / 2, math.pi / 2))
    for name in DRAWINGS:
        assert drawing(name)[1].total == pytest.approx(2 * math.pi, abs=1e-9)


@pytest.mark.parametrize("name,lengths", [(DRAWINGS[0], 12), (DRAWINGS[1], 3), (DRAWINGS[2], 3)])
def test_every_roll_at_a_convex_corner_is_found_and_nothing_infeasible(name, lengths):
    outline, ref = drawing(name)
    rolls = corner_rolls(outline, ref, np.linspace(0.08, 0.60, lengths) * ref.perimeter)
    assert len(rolls) == 4 * lengths * sum(c.angle > 0 for c in outline.corners) > 0
    out = check_rolls(outline, rolls, ref)
    assert (out["missed"], out["infeasible"]) == (0, 0), out["examples"]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    which=st.sampled_from(DRAWINGS),
    corner=st.integers(0, 10),
    start=st.floats(0.0, 1.0),
    fraction=st.floats(0.05, 0.95),
    ccw=st.booleans(),
)
def test_a_roll_whose_end_lands_on_a_corner_through_the_seam_is_found(which, corner, start, fraction, ccw):
    """The length is the distance from a start anywhere to a corner, so that the end is the corner up to
    rounding, on either side of it, often past the first point."""
    outline, ref = drawing(which)
    convex = [c for c in outline.corners if c.angle > 0]
    c = convex[corner % len(convex)]
    P = ref.perimeter
    s = start * P
    L = (c.arc - s) % P if ccw else (s - c.arc) % P
    if not 0.02 * P < L < 0.98 * P or min(abs((s - k.arc + P / 2) % P - P / 2) for k in outline.corners) < 1e-6:
        return  # too short, or the start is itself at a corner (the ends at corners are the next test's)
    # the jaw's angle at the end (unrolled: a lap on where the end passed the first point) within the corner's
    before, after = ref.range(s + L if ccw else s - L)
    assert after - before == pytest.approx(c.angle, abs=1e-9)  # the reference sees the corner there
    alpha = before + fraction * (after - before)
    roll = CornerRoll("ccw" if ccw else "cw", s, L, alpha - ref.range(s)[1 if ccw else 0], True)
    out = check_rolls(outline, [roll], ref)
    assert (out["missed"], out["infeasible"]) == (0, 0), out["examples"]


@pytest.mark.parametrize("name", DRAWINGS)
def test_an_arc_within_rounding_of_a_corner_is_at_it_on_either_side_and_through_the_seam(name):
    outline, _ = drawing(name)
    P = outline.perimeter
    for i, c in enumerate(outline.corners):
        for sigma in (c.arc, c.arc + 1e-13 * P, c.arc - 1e-13 * P, c.arc + P, c.arc - P, c.arc - 3 * P + 5e-13 * P):
            assert outline.corner_at(sigma) == i
            # the angles on the two sides are the corner's, a whole number of laps on
            lap = math.floor((sigma - c.arc) / P + 0.5)
            after = float(outline.tangent_angle_at_arc(sigma)) - 2 * math.pi * lap
            before = float(outline.tangent_angle_at_arc(sigma, side="before")) - 2 * math.pi * lap
            assert after - before == pytest.approx(c.angle, abs=1e-12)
            assert after == pytest.approx(float(outline.tangent_angle_at_arc(c.arc)), abs=1e-9)
        assert outline.corner_at(c.arc + 1e-6) == -1 and outline.corner_at(c.arc - 1e-6) == -1


@pytest.mark.parametrize("name", DRAWINGS)
def test_a_roll_from_one_corner_to_another_is_found_both_ways(name):
    """Both ends on corners, the length their difference (through the seam for half of them): the rolls
    whose end the issue found landing 1e-14 short of a corner and read on the wrong side of it."""
    outline, ref = drawing(name)
    P = ref.perimeter
    convex = [c for c in outline.corners if c.angle > 0]
    rolls = []
    for c1 in convex:
        for c2 in convex:
            L = (c2.arc - c1.arc) % P
            if not 0.02 * P < L < 0.98 * P:
                continue
            for f1, f2 in ((0.25, 0.75), (0.75, 0.25)):
                b1, a1 = ref.range(c1.arc)
                b2, a2 = ref.range(c1.arc + L)
                rolls.append(CornerRoll("ccw", c1.arc, L, b2 + f2 * (a2 - b2) - (b1 + f1 * (a1 - b1)), False))
                b2, a2 = ref.range(c2.arc - L)
                rolls.append(
                    CornerRoll("cw", c2.arc, L, b2 + f2 * (a2 - b2) - (ref.range(c2.arc)[0] + f1 * c2.angle), False)
                )
    if not rolls:
        pytest.skip(f"{name} has one convex corner")
    out = check_rolls(outline, rolls, ref)
    assert (out["missed"], out["infeasible"]) == (0, 0), out["examples"]
