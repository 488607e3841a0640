import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from localizer import ExactOptions, QueryError, feasible_segments, part_from_points
from tests.localizer.reference import DenseCurve, random_part_points
from tests.localizer.test_part import circle_points, ellipse_points, trefoil


def circular_distance(a, b, P):
    return np.abs((np.asarray(a) - np.asarray(b) + P / 2) % P - P / 2)


def test_circle_every_start_is_feasible_iff_turn_is_length_over_radius():
    n, R, L = 128, 40.0, 17.3
    part = part_from_points(circle_points(n, R))
    P = part.perimeter
    starts = np.array([s.start_arc for s in feasible_segments(part, L, 2 * np.pi * L / P)])
    # the spline ripples with the knots: g crosses zero at least twice per knot
    # interval, so feasible starts are dense: no gap longer than one knot spacing
    gaps = np.diff(np.concatenate([starts, [starts[0] + P]]))
    assert len(starts) >= n and gaps.max() <= P / n * 1.01
    for factor in (0.99, 1.01):
        assert feasible_segments(part, L, factor * L / R) == []


def test_ellipse_roots_come_in_symmetric_pairs():
    part = part_from_points(ellipse_points(48, 40.0, 25.0))
    P = part.perimeter
    for L, w in [(20.0, 0.5), (35.0, 0.9), (8.0, 0.35), (60.0, 1.9)]:
        starts = np.array([s.start_arc for s in feasible_segments(part, L, w)])
        assert len(starts) > 0 and len(starts) % 2 == 0
        # point symmetry (rotation by pi): start -> start + P/2
        rot = np.sort(np.mod(starts + P / 2, P))
        assert np.allclose(circular_distance(rot, starts, P), 0, atol=1e-8)
        # mirror symmetry about the x axis: [s, s+L] -> [-s-L, -s]
        mir = np.sort(np.mod(-starts - L, P))
        assert np.allclose(circular_distance(mir, starts, P), 0, atol=1e-8)


@pytest.mark.parametrize("seed, convex", [(s, c) for s in range(4) for c in (True, False)])
def test_agrees_with_dense_brute_force(seed, convex):
    rng = np.random.default_rng(100 + seed)
    pts = random_part_points(rng, convex=convex)
    part = part_from_points(pts)
    ref = DenseCurve(pts)
    P = part.perimeter
    for _ in range(3):
        L = rng.uniform(0.03, 0.6) * P
        s0 = rng.uniform(0, P)
        w = float(ref.theta_at(s0 + L) - ref.theta_at(s0))
        expect = ref.feasible_starts(L, w)
        got = feasible_segments(part, L, w)
        starts = np.array([s.start_arc for s in got])
        assert len(starts) == len(expect), (L, w, starts, expect)
        assert np.allclose(circular_distance(starts, expect, P), 0, atol=1e-6)
        assert all(s.kind == "simple" for s in got)


@pytest.mark.parametrize("seed", range(3))
def test_agrees_with_dense_brute_force_on_a_rough_traced_outline(seed):
    """90 points, harmonics to 24 and ±0.25 mm jitter: curvature changing ~30 times faster than the
    trefoil's, many roots per query; every one found, none extra."""
    rng = np.random.default_rng(300 + seed)
    pts = random_part_points(rng, n=90, convex=False, harmonics=24, jitter=0.25)
    part = part_from_points(pts)
    ref = DenseCurve(pts)
    P = part.perimeter
    for _ in range(3):
        L = rng.uniform(5.0, 60.0)
        s0 = rng.uniform(0, P)
        w = float(ref.theta_at(s0 + L) - ref.theta_at(s0))
        expect = ref.feasible_starts(L, w)
        starts = np.array([s.start_arc for s in feasible_segments(part, L, w)])
        assert len(starts) == len(expect), (L, w, starts, expect)
        assert np.allclose(circular_distance(starts, expect, P), 0, atol=1e-6)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), frac=st.floats(0, 1, exclude_max=True), lfrac=st.floats(0.01, 0.9))
def test_true_start_is_among_candidates(seed, frac, lfrac):
    part = part_from_points(random_part_points(np.random.default_rng(seed)))
    P = part.perimeter
    s0, L = frac * P, lfrac * P
    w = float(part.total_curvature(part.param_at_arc(s0), part.param_at_arc(s0 + L)))
    segs = feasible_segments(part, L, w)
    d = circular_distance([s.start_arc for s in segs], s0, P)
    if d.min() <= 1e-6:
        return
    # otherwise the truth must lie in the flat cluster that a "double" root stands
    # for: g stays within 1e-9 rad of zero all the way from the truth to it
    s = segs[int(np.argmin(d))]
    assert s.kind == "double" and d.min() < 0.01
    between = np.linspace(s0, s0 + ((s.start_arc - s0 + P / 2) % P - P / 2), 50)
    g = part.tangent_angle_at_arc(between + L) - part.tangent_angle_at_arc(between) - w
    assert np.abs(g).max() <= 1e-9


def test_segments_are_exact():
    part = trefoil()
    for L, w in [(20.0, 0.3), (30.0, 0.1), (10.0, -0.05), (50.0, 1.0)]:
        segs = feasible_segments(part, L, w)
        assert segs
        for s in segs:
            assert part.arc_length(s.start_param, s.end_param) == pytest.approx(L, abs=1e-9)
            assert part.total_curvature(s.start_param, s.end_param) == pytest.approx(w, abs=1e-11)
            assert part.arc_at_param(s.start_param) == pytest.approx(s.start_arc, abs=1e-9)
            assert 0 <= s.start_arc < part.perimeter and 0 <= s.end_arc < part.perimeter


def test_negative_turn_across_a_concave_stretch():
    part = trefoil()
    t = np.linspace(0, part.n_knots, 5000)
    k = part.curvature(t)
    concave = part.arc_at_param(t[np.argmin(k)])  # deepest point of a concavity
    s0, L = concave - 4.0, 8.0
    w = float(part.tangent_angle_at_arc(s0 + L) - part.tangent_angle_at_arc(s0))
    assert w < 0
    segs = feasible_segments(part, L, w)
    assert circular_distance([s.start_arc for s in segs], part.wrap_arc(s0), part.perimeter).min() < 1e-8


def test_clockwise_rolling():
    part = trefoil()
    s0, L = 40.0, 25.0  # contact moves clockwise from 40 to 15
    w = float(part.tangent_angle_at_arc(s0 - L) - part.tangent_angle_at_arc(s0))
    assert w < 0
    segs = feasible_segments(part, L, w, direction="cw")
    best = min(segs, key=lambda s: abs(s.start_arc - s0))
    assert best.start_arc == pytest.approx(s0, abs=1e-8)
    assert best.end_arc == pytest.approx(s0 - L, abs=1e-8)
    assert best.direction == "cw"
    assert feasible_segments(part, L, -w, direction="ccw")  # the same stretch seen ccw


def test_unreachable_turn_gives_no_segment():
    part = trefoil()
    assert feasible_segments(part, 10.0, 3.0) == []


def test_circular_stretch_is_reported_as_continuum():
    # a circle whose knot spacing divides L: g vanishes identically
    n, R = 64, 40.0
    part = part_from_points(circle_points(n, R))
    L = part.perimeter / n * 5
    segs = feasible_segments(part, L, 2 * np.pi * L / part.perimeter, exact=ExactOptions(flat_tol=1e-9))
    assert segs and all(s.kind in ("continuum", "double", "simple") for s in segs)
    covered = sum(s.span for s in segs if s.kind == "continuum")
    assert covered == pytest.approx(part.perimeter, rel=1e-6)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(length=0.0, turn=0.1), r"length=0.0 mm is out of range"),
        (dict(length=-1.0, turn=0.1), "out of range"),
        (dict(length=1e4, turn=0.1), r"perimeter=337.7"),
        (dict(length=float("nan"), turn=0.1), "must be finite"),
        (dict(length=10.0, turn=float("inf")), "must be finite"),
        (dict(length="ten", turn=0.1), "must be numbers"),
        (dict(length=10.0, turn=0.1, method="newton"), r"unknown method 'newton'; use one of \['exact', 'march'\]"),
        (dict(length=10.0, turn=0.1, direction="up"), r"unknown direction 'up'; use one of \['ccw', 'cw'\]"),
    ],
)
def test_bad_queries(kwargs, match):
    with pytest.raises(QueryError, match=match):
        feasible_segments(trefoil(), **kwargs)


def test_part_argument_must_be_a_part():
    with pytest.raises(QueryError, match="must be a localizer.Part"):
        feasible_segments([[0, 0]], 1.0, 0.1)


@pytest.mark.parametrize("offset", [0.0, 1e-9, -1e-9, 1e-6])
def test_near_double_roots_are_found_not_skipped(offset):
    """Ω at (or within 1e-6 rad of) a local extremum of Φ(σ, σ+L): g touches zero."""
    from scipy.optimize import brentq

    part = trefoil()
    L = 20.0

    def dg(s):
        return float(part.curvature_at_arc(s + L) - part.curvature_at_arc(s))

    grid = np.linspace(0, part.perimeter, 2000, endpoint=False)
    vals = part.curvature_at_arc(grid + L) - part.curvature_at_arc(grid)  # dg over the grid, in one call
    i = int(np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0])
    s_star = brentq(dg, grid[i], grid[i + 1], xtol=1e-13)

    def phi(s):
        return float(part.tangent_angle_at_arc(s + L) - part.tangent_angle_at_arc(s))

    # step towards the inside of the extremum so that two roots exist for offset > 0
    curvature_sign = np.sign(phi(s_star + 0.01) + phi(s_star - 0.01) - 2 * phi(s_star))
    w = phi(s_star) + curvature_sign * offset
    segs = feasible_segments(part, L, w)
    near = [s for s in segs if abs(s.start_arc - s_star) < 0.05]
    if offset >= 0:
        assert near, "the tangency was skipped"
        assert all(s.residual < 1e-6 for s in near)
    if offset > 1e-8:  # two distinct roots, both found
        assert len(near) == 2 and all(s.kind == "simple" for s in near)


def test_a_start_at_the_seam_is_found():
    # g(σ) is periodic: a root at σ = 0 exactly, where g(0) is a rounding from zero, must be seen by the
    # first cell or the last, whichever side of zero that rounding fell (it fell between them for 9 of
    # these 3000 queries when g at P was evaluated again through the wrap)
    for seed in range(1000):
        part = part_from_points(random_part_points(np.random.default_rng(seed)))
        P = part.perimeter
        for lfrac in (0.01, 0.1, 0.4):
            L = lfrac * P
            w = float(part.total_curvature(part.param_at_arc(0.0), part.param_at_arc(L)))
            starts = [s.start_arc for s in feasible_segments(part, L, w)]
            assert circular_distance(starts, 0.0, P).min() <= 1e-6, (seed, lfrac)
