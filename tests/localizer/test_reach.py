"""Where a straight jaw reaches: against a brute-force reading of the definition on a dense sample."""

import math
from pathlib import Path

import numpy as np
import pytest

from localizer import QueryError, Reach, StraightJaw, calibration_arc, load_outline, load_part, part_from_points

ROOT = Path(__file__).resolve().parents[2]


def brute_touchable(part, arc, d, half=50.0, clearance=0.1, per_piece=64):
    """The definition, on its own dense sample: lay the edge along the tangent at ``arc`` with the
    contact at ``d`` on it; no other point may lie beyond the edge deeper than ``clearance``."""
    t = part.param_at_arc(arc)
    p, e = part.point(t), part.tangent(t)
    q = part.sample(per_piece) - p
    w = q @ e
    depth = q[:, 0] * e[1] - q[:, 1] * e[0]
    inside = (w >= -half - d) & (w <= half - d)
    return not np.any(inside & (depth > clearance))


def numpy_intervals(pts, points, tangents, clearance, half, tiny, origins=None):
    """The reach's intervals as numpy computes them, in blocks of rows of every pair of points: the
    reference the compiled loop must equal to the bit."""
    n, m = len(pts), points.size
    lo, hi = np.full(m, -np.inf), np.full(m, np.inf)
    lo_sure, hi_sure = np.full(m, -np.inf), np.full(m, np.inf)
    k = np.arange(n)

    def interval(w, block):
        w_plus = np.where(block & (w > 0), w, np.inf).min(axis=1)
        w_minus = np.where(block & (w < 0), w, -np.inf).max(axis=1)
        here = (block & (w == 0)).any(axis=1)
        return np.where(here, np.inf, half - w_plus), np.where(here, -np.inf, -half - w_minus)

    for start in range(0, m, 128):
        rows = np.arange(start, min(start + 128, m))
        i = points[rows]
        here = pts[i] if origins is None else origins[rows]
        q = pts[(i[:, None] + k[None, :]) % n] - here[:, None, :]
        e = tangents[rows, None, :]
        w = np.einsum("bnk,bnk->bn", q, e)
        dep = q[..., 0] * e[..., 1] - q[..., 1] * e[..., 0]
        lo[rows], hi[rows] = interval(w, dep > clearance)
        clear_of = dep < -clearance
        ahead = np.where(clear_of[:, 1:].any(axis=1), np.argmax(clear_of[:, 1:], axis=1) + 1, n)
        behind = np.where(clear_of[:, :0:-1].any(axis=1), np.argmax(clear_of[:, :0:-1], axis=1) + 1, n)
        cap = ((k[None, :] < ahead[:, None]) | (k[None, :] > n - behind[:, None])) & (dep <= tiny)
        lo_sure[rows], hi_sure[rows] = interval(w, (dep > -clearance) & ~cap)
    return lo, hi, lo_sure, hi_sure


@pytest.mark.parametrize("name", ["trefoil.json", "kidney.csv", "bracket.dxf", "star"])
def test_the_compiled_intervals_are_numpys_to_the_bit(name, star):
    part = star if name == "star" else (load_outline if name.endswith(".dxf") else load_part)(ROOT / "parts" / name)
    for clearance in (0.0, 0.1):
        r = Reach(part, clearance=clearance)
        pts = np.asarray(part.point_at_arc(r.sigma))
        tiny = 1e-9 * max(1.0, float(np.ptp(pts)))  # as the reach rounds a depth
        theta = np.asarray(part.tangent_angle_at_arc(r.sigma))
        tan = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
        ref = numpy_intervals(pts, np.arange(r.sigma.size), tan, clearance, r.jaw.half, tiny)
        lo, hi = ref[0], ref[1]
        for got, want in zip(
            (r.lo, r.hi, r.lo_sure, r.hi_sure), (lo, hi, np.maximum(lo, ref[2]), np.minimum(hi, ref[3]))
        ):
            assert np.array_equal(got, want)
        # every part has points the jaw reaches whole, in part, and not at all: each branch is taken
        assert (r.lo <= -r.jaw.half).any() and (r.lo > -r.jaw.half).any() and (r.lo >= r.hi).any()
        # off the grid and off the tangent, as on a convex corner
        rng = np.random.default_rng(1)
        arc, angle = rng.uniform(0, part.perimeter, 300), rng.uniform(-np.pi, np.pi, 300)
        i = np.mod(np.rint(arc / r.h).astype(np.int64), r.sigma.size)
        tan = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
        origins = np.asarray(part.point_at_arc(arc), dtype=float)
        lo, hi, lo_sure, hi_sure = numpy_intervals(pts, i, tan, clearance, r.jaw.half, tiny, origins)
        got = r.at_angle(arc, angle)
        for a, b in zip(got, (lo, hi, np.maximum(lo, lo_sure), np.minimum(hi, hi_sure))):
            assert np.array_equal(a, b)


@pytest.fixture(scope="module")
def star():
    # three deep lobes, concavities wider than the jaw: points below the hull are reachable
    a = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    r = 80 * (1 + 0.3 * np.cos(3 * a))
    return part_from_points(np.c_[r * np.cos(a), r * np.sin(a)], name="star")


def test_on_a_convex_part_the_whole_jaw_reaches_everywhere():
    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    cam = part_from_points(np.c_[40 * np.cos(a) + 3 * np.cos(2 * a), 30 * np.sin(a)])
    r = Reach(cam)
    assert r.full.all() and not np.any(r.hull_depth > 1e-6)
    assert r.touchable(np.linspace(0, cam.perimeter, 50, endpoint=False), jaw=49.0).all()


@pytest.mark.parametrize("name", ["trefoil.json", "kidney.csv"])
def test_the_interval_agrees_with_the_definition_on_the_shipped_parts(name):
    # never a place ruled out that the definition allows (the generous interval), never one called
    # surely clear that the definition blocks (the sure interval)
    part = load_part(ROOT / "parts" / name)
    r = Reach(part)
    rng = np.random.default_rng(3)
    blocked = 0
    for _ in range(400):
        arc, d = rng.uniform(0, part.perimeter), rng.uniform(-48, 48)
        if brute_touchable(part, arc, d):
            assert r.touchable(arc, jaw=d), (arc, d, r.interval(arc))
        else:
            assert not r.clear(arc, d), (arc, d, r.interval(arc, sure=True))
            blocked += 1
    assert 10 < blocked < 390


def test_below_the_hull_of_a_wide_concavity_only_one_end_of_the_jaw_reaches(star):
    r = Reach(star)
    deep = (r.hull_depth > 4.0) & r.touchable(r.sigma)
    assert deep.any()  # the old 4 mm hull tolerance left these out
    for i in np.flatnonzero(deep)[::25]:
        lo, hi = r.lo[i], r.hi[i]
        assert lo > -50 or hi < 50  # not the whole jaw
        for d in (max(lo, -50) + 0.5, min(hi, 50) - 0.5):
            if max(lo, -50) + 0.5 < min(hi, 50) - 0.5:
                assert brute_touchable(star, r.sigma[i], d)
        outside = hi + 1.0 if hi < 49 else lo - 1.0
        assert not brute_touchable(star, r.sigma[i], outside)


def test_a_concave_point_is_touched_nowhere(star):
    # its own neighbours are in the way (without the clearance that forgives a model error)
    r = Reach(star, clearance=0.0)
    kappa = np.asarray(star.curvature_at_arc(r.sigma))
    concave = kappa < -1e-3
    assert concave.any() and not r.touchable(r.sigma[concave]).any()


def test_calibration_is_at_the_most_curved_point_the_whole_jaw_reaches(star):
    arc = calibration_arc(star)
    r = Reach(star)
    full = r.sigma[r.full]
    kappa = np.asarray(star.curvature_at_arc(full))
    assert r.full[int(np.rint(arc / r.h)) % r.sigma.size]
    assert float(star.curvature_at_arc(arc)) == pytest.approx(kappa.max(), rel=1e-6)
    for d in np.linspace(-50, 50, 11):  # the 11 taps all touch there
        assert brute_touchable(star, arc, d)


def test_calibration_avoids_a_sharp_bump_inside_a_concavity():
    # the most curved point is a small bump at the bottom of a valley: the whole jaw cannot reach it
    # (calibrating there pressed 15 mm into thin air), so calibration goes elsewhere
    a = np.linspace(0, 2 * np.pi, 240, endpoint=False)
    r = 80 * (1 + 0.3 * np.cos(3 * a)) + 3.0 * np.exp(-0.5 * (np.angle(np.exp(1j * (a - np.pi / 3))) / 0.03) ** 2)
    part = part_from_points(np.c_[r * np.cos(a), r * np.sin(a)], name="star with a bump")
    t = np.linspace(0, part.n_knots, 20 * part.n_knots, endpoint=False)
    sharpest = float(part.arc_at_param(t[np.argmax(part.curvature(t))]))
    assert not brute_touchable(part, sharpest, 0.0)
    arc = calibration_arc(part)
    assert abs(part.arc_offset(arc, sharpest)) > 10.0
    assert all(brute_touchable(part, arc, d) for d in np.linspace(-50, 50, 11))


def test_bad_jaws_and_settings_are_refused():
    with pytest.raises(QueryError, match="jaw length=-1"):
        StraightJaw(-1.0)
    with pytest.raises(QueryError, match="length=nan"):
        StraightJaw(math.nan)
    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    disc = part_from_points(np.c_[np.cos(a), np.sin(a)] * 30)
    with pytest.raises(QueryError, match="clearance=-0.1"):
        Reach(disc, clearance=-0.1)
    assert str(StraightJaw()) == "straight:100"
