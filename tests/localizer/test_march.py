"""The paper's marching algorithm against the exact solver and against Proposition 1 / Theorem 2."""

import numpy as np
import pytest

from localizer import MarchOptions, QueryError, feasible_segments, march, part_from_points
from tests.localizer.test_part import ellipse_points, trefoil

H = 1e-4  # coarser than the paper's 1e-5 to keep the tests fast; the bench uses 1e-5


def ellipse():
    return part_from_points(ellipse_points(48, 40.0, 25.0))


def queries(part, starts, lengths):
    for s0, L in zip(starts, lengths):
        yield L, float(part.tangent_angle_at_arc(s0 + L) - part.tangent_angle_at_arc(s0))


def exact_slope(part, seg):
    return float(part.curvature(seg.end_param) - part.curvature(seg.start_param))


@pytest.mark.parametrize(
    "make, starts, lengths",
    [
        (ellipse, [10.0, 70.0, 150.0], [20.0, 35.0, 12.0]),
        (trefoil, [30.0, 100.0, 200.0, 310.0], [25.0, 40.0, 10.0, 60.0]),
    ],
)
def test_tight_march_finds_the_exact_segments_to_the_step(make, starts, lengths):
    """With tight tolerances the march lands on every exact root, to the grid's resolution."""
    part = make()
    vmax = float(part.speed(np.linspace(0, part.n_knots, 20000)).max())
    for L, w in queries(part, starts, lengths):
        exact = feasible_segments(part, L, w)
        marched = march(part, L, w, MarchOptions(step=H, length_tol=1e-9, turn_tol=1e-9)).segments
        assert len(marched) == len(exact)
        for m, e in zip(marched, exact):
            assert abs(part.arc_offset(m.start_arc, e.start_arc)) <= H * vmax
            assert m.kind == "simple"


def test_tight_march_spans_inflections():
    part = trefoil()
    t = np.linspace(0, part.n_knots, 90000, endpoint=False)
    k = part.curvature(t)
    spanned = 0
    for L, w in queries(part, [30.0, 100.0, 200.0, 310.0], [25.0, 40.0, 10.0, 60.0]):
        for m in march(part, L, w, MarchOptions(step=H, length_tol=1e-9, turn_tol=1e-9)).segments:
            inside = (t - m.start_param) % part.n_knots <= (m.end_param - m.start_param) % part.n_knots
            spanned += bool(np.any(np.diff(np.sign(k[inside])) != 0))
    assert spanned >= 10


@pytest.mark.parametrize("make", [ellipse, trefoil])
def test_paper_tolerances(make):
    """At the paper's tolerances every exact root is found to within what the tolerances allow,
    and every marched segment is feasible to those tolerances."""
    part = make()
    for L, w in queries(part, [15.0, 120.0, 180.0], [22.0, 30.0, 8.0]):
        exact = feasible_segments(part, L, w)
        marched = march(part, L, w, MarchOptions(step=H))
        assert marched.segments
        for e in exact:
            allowed = 2 * 0.0004 / abs(exact_slope(part, e)) + 2 * 0.004 + 0.01
            assert min(abs(part.arc_offset(m.start_arc, e.start_arc)) for m in marched.segments) <= allowed
        for m in marched.segments:
            assert abs(part.arc_length(m.start_param, m.end_param) - L) <= 0.004 + 1e-3
            assert m.residual <= 0.0004 + 1e-4


def test_iterates_converge_linearly_with_the_curvature_ratio():
    """Proposition 1: e_{i+1}/e_i -> κ(s*)/κ(t*) (or its inverse, by the case of eq. 7)."""
    part = trefoil()
    checked = 0
    for L, w in queries(part, [100.0, 200.0], [40.0, 10.0]):
        exact = feasible_segments(part, L, w)
        for m in march(part, L, w, MarchOptions(step=H, length_tol=1e-10, turn_tol=1e-10)).segments:
            e = min(exact, key=lambda e: abs(part.arc_offset(m.start_arc, e.start_arc)))
            ks, kt = part.curvature(e.start_param), part.curvature(e.end_param)
            if ks * kt <= 0 or m.iterations < 10:  # mixed modes use bisection
                continue
            err = np.abs(part.arc_offset(np.array(m.iterates), e.start_arc))
            tail = err[(err > 1e-6) & (err < 1e-1)]
            assert np.all(np.diff(tail) < 0)
            ratio = tail[1:] / tail[:-1]
            predicted = min(ks / kt, kt / ks)
            assert np.median(ratio) == pytest.approx(predicted, abs=0.01)
            checked += 1
    assert checked >= 6


def test_theorem_2_step_bound():
    part = trefoil()
    for L, w in queries(part, [30.0, 100.0, 200.0], [25.0, 40.0, 10.0]):
        res = march(part, L, w, MarchOptions(step=H))
        assert 0 < res.steps <= 6 * res.grid_cells


def test_clockwise_march_matches_exact():
    part = trefoil()
    s0, L = 40.0, 25.0
    w = float(part.tangent_angle_at_arc(s0 - L) - part.tangent_angle_at_arc(s0))
    m = feasible_segments(
        part, L, w, direction="cw", method="march", marching=MarchOptions(step=H, length_tol=1e-9, turn_tol=1e-9)
    )
    e = feasible_segments(part, L, w, direction="cw")
    assert len(m) == len(e)
    assert all(abs(part.arc_offset(a.start_arc, b.start_arc)) < 1e-3 for a, b in zip(m, e))
    assert all(g.direction == "cw" and g.turn == w for g in m)


def test_bad_step():
    with pytest.raises(QueryError, match="step=0.3 must divide the parameter period 90"):
        march(trefoil(), 10.0, 0.1, MarchOptions(step=0.3))


def test_a_zero_of_curvature_that_keeps_its_sign_is_no_inflection():
    """Footnote 5: only sign changes are inflections; at a zero the side is κ' 's."""
    from localizer.solve._march_grid import _sign_regions

    h = 0.01
    x = np.arange(401) * h  # one period of 4 parameter units, last sample = first
    kappa = np.cos(np.pi * x / 2) ** 2 - 0.0  # touches zero at x = 1 and 3, never negative
    kappa[-1] = kappa[0]
    z, after = _sign_regions(kappa, h)
    assert z.size == 0
    kappa2 = np.cos(np.pi * x / 2)  # simple zeros at x = 1 and 3
    kappa2[-1] = kappa2[0]
    z2, after2 = _sign_regions(kappa2, h)
    assert np.allclose(z2, [1.0, 3.0], atol=1e-3)
    assert list(after2) == [-1.0, 1.0]
