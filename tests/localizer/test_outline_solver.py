"""Feasible segments on outlines with corners, against an independent reference: the tangent angle
of a dense polyline through the outline (chord directions, unwrapped), not the outline's own θ."""

import math
from pathlib import Path

import numpy as np
import pytest

from localizer import Line, QueryError, elliptical_arc, load_outline, outline_from_pieces, outline_segments

from .reference import ChordAngle

PARTS = Path(__file__).resolve().parents[2] / "parts"


def near_a_piece_end(outline, sigma, margin):
    d = np.abs(
        (np.asarray(sigma)[..., None] - outline.starts[None, :-1] + outline.perimeter / 2) % outline.perimeter
        - outline.perimeter / 2
    )
    return (d < margin).any(axis=-1)


@pytest.fixture(scope="module", params=["bracket.dxf", "profile.svg", "half-ellipse"])
def outline(request):
    if request.param == "half-ellipse":  # rational Béziers: three quarters of an ellipse and two lines
        arcs = elliptical_arc((0.0, 0.0), (40.0, 0.0), (0.0, 15.0), -0.5 * math.pi, math.pi)
        return outline_from_pieces([*arcs, Line((-40.0, 0.0), (0.0, 0.0)), Line((0.0, 0.0), (0.0, -15.0))])
    return load_outline(PARTS / request.param)


def test_a_roll_is_found_where_it_was_made(outline):
    ref = ChordAngle(outline)
    rng = np.random.default_rng(16)
    tried = 0
    while tried < 40:
        s0, L = rng.uniform(0, outline.perimeter), rng.uniform(3.0, 40.0)
        if near_a_piece_end(outline, [s0, s0 + L], 0.5).any():
            continue
        tried += 1
        omega = float(ref(s0 + L) - ref(s0))
        segs = outline_segments(outline, L, omega)
        hit = [
            g
            for g in segs
            if abs(((g.start_arc - s0 + outline.perimeter / 2) % outline.perimeter) - outline.perimeter / 2) < 0.02
            or (g.kind == "continuum" and (s0 - g.start_arc) % outline.perimeter <= g.span + 0.02)
        ]
        assert hit, (s0, L, omega, [(g.start_arc, g.kind) for g in segs])


def test_every_segment_found_fits_the_reference(outline):
    ref = ChordAngle(outline)
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(30):
        L, omega = rng.uniform(3.0, 40.0), rng.uniform(-0.5, 1.5)
        for g in outline_segments(outline, L, omega):
            if g.kind != "simple" or near_a_piece_end(outline, [g.start_arc, g.start_arc + L], 0.05).any():
                continue
            assert float(ref(g.start_arc + L) - ref(g.start_arc)) == pytest.approx(omega, abs=2e-3)
            checked += 1
    assert checked > 10


def test_clockwise_rolling_reverses_the_stretch():
    o = load_outline(PARTS / "profile.svg")
    ccw = outline_segments(o, 12.0, 0.3)
    cw = outline_segments(o, 12.0, -0.3, direction="cw")
    assert sorted(round(g.end_arc, 9) for g in cw) == sorted(round(g.start_arc, 9) for g in ccw)


def test_a_corner_start_fits_every_rotation_of_its_jump():
    pts = [(0, 0), (40, 0), (40, 20), (0, 20)]
    box = outline_from_pieces([Line(pts[i], pts[(i + 1) % 4]) for i in range(4)])
    for omega in (0.1, 0.7, 1.5):
        corners = sorted(round(g.start_arc, 9) for g in outline_segments(box, 10.0, omega) if g.kind == "corner")
        # starting at a corner, or ending at one 10 mm on
        assert corners == [0.0, 30.0, 40.0, 50.0, 60.0, 90.0, 100.0, 110.0]
    # more than the jump: nothing
    assert outline_segments(box, 10.0, 1.7) == []


def test_bad_queries():
    o = load_outline(PARTS / "bracket.dxf")
    with pytest.raises(QueryError, match="length=0"):
        outline_segments(o, 0.0, 0.1)
    with pytest.raises(QueryError, match="direction"):
        outline_segments(o, 5.0, 0.1, direction="up")
    assert math.isfinite(o.perimeter)


def test_feasible_segments_solves_an_outline_with_the_outline_solver():
    from localizer import feasible_segments

    bracket = load_outline(PARTS / "bracket.dxf")
    found = 0
    for length, turn, direction in ((12.0, 0.3, "ccw"), (30.0, math.pi / 2, "ccw"), (8.0, -0.4, "cw")):
        got = feasible_segments(bracket, length, turn, direction=direction)
        assert got == outline_segments(bracket, length, turn, direction=direction)
        found += len(got)
    assert found > 0
    with pytest.raises(QueryError, match="marching reference is for splines"):
        feasible_segments(bracket, 12.0, 0.3, method="march")


def test_two_roots_closer_than_the_sampling_step_are_both_found_on_bezier_pieces():
    # cam-05 of the held-out CAD family: for L = 5 mm, h(σ) = θ(σ + L) − θ(σ) has a maximum near
    # σ = 75.74 with both ends on Béziers. Just below it, two starts 0.002 mm apart fit: sampling
    # every 0.01 mm and refining sign changes missed both; the certified cells find both, against
    # a reference of sign changes on a 1e-5 mm grid refined by Brent
    from scipy.optimize import brentq, minimize_scalar

    cam = load_outline(Path(__file__).resolve().parents[2] / "bench" / "parts" / "cad-heldout" / "cam-05.svg")
    L = 5.0

    def h(x):
        return cam.tangent_angle_at_arc(np.asarray(x) + L) - cam.tangent_angle_at_arc(x)

    top = minimize_scalar(lambda x: -float(h(x)), bounds=(75.6, 75.9), method="bounded", options={"xatol": 1e-10})
    for sep in (0.002, 0.0005):
        omega = float(h(top.x)) - 0.11076 * (sep / 2) ** 2 / 2
        grid = np.arange(top.x - 0.01, top.x + 0.01, 1e-5)
        gs = h(grid) - omega
        ref = [
            brentq(lambda x, w=omega: float(h(x)) - w, grid[i], grid[i + 1], xtol=1e-13)
            for i in np.flatnonzero(np.sign(gs[:-1]) * np.sign(gs[1:]) < 0)
        ]
        assert len(ref) == 2 and abs(ref[1] - ref[0] - sep) < 0.1 * sep
        found = sorted(s.start_arc for s in outline_segments(cam, L, omega) if abs(s.start_arc - top.x) < 0.05)
        assert len(found) == 2 and np.allclose(found, ref, atol=1e-8), (sep, found, ref)
