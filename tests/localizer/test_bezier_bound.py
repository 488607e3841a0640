"""The bound of |dκ/ds| on a Bézier from its Bernstein coefficients (the outline solver's certificate),
against closed forms and dense finite differences, and two roots closer than any sampling grid."""

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from localizer import CubicBezier, feasible_segments, load_outline
from localizer.solve._bezier_bound import kappa_slope_bound

ROOT = Path(__file__).resolve().parents[2]
DRAWINGS = sorted(
    [p for p in (ROOT / "parts").iterdir() if p.suffix in (".dxf", ".svg")]
    + [p for p in (ROOT / "bench" / "parts").glob("cad-heldout*/*") if p.suffix in (".dxf", ".svg")]
)


def slope_by_differences(piece, s, h=1e-4):
    """dκ/ds by central differences of the piece's own curvature (mm⁻²), at arcs ``s`` kept h inside."""
    s = np.clip(s, h, piece.length - h)
    return (np.asarray(piece.curvature(s + h)) - np.asarray(piece.curvature(s - h))) / (2 * h)


def test_a_circle_drawn_as_a_rational_bezier_has_a_curvature_that_does_not_change():
    quarter = CubicBezier.from_quadratic((10.0, 0.0), (10.0, 10.0), (0.0, 10.0), weight=math.sqrt(0.5))
    assert np.allclose(quarter.curvature(np.linspace(0, quarter.length, 9)), 0.1, atol=1e-12)
    u = np.linspace(0.0, 1.0, 11)
    assert np.all(kappa_slope_bound(quarter, u[:-1], u[1:]) < 1e-9)


def test_a_parabola_s_bound_holds_and_is_close_on_short_intervals():
    # y = x² / 20 from x = -10 to 10 as a cubic: κ' has a closed form in x
    piece = CubicBezier.from_quadratic((-10.0, 5.0), (0.0, -5.0), (10.0, 5.0))
    u = np.linspace(0.0, 1.0, 201)
    bound = kappa_slope_bound(piece, u[:-1], u[1:])
    x = -10.0 + 20.0 * 0.5 * (u[:-1] + u[1:])  # the parameter is affine in x here
    a = 1.0 / 20.0
    # κ = 2a / (1 + 4a²x²)^(3/2), ds/dx = (1 + 4a²x²)^(1/2): dκ/ds = −24a³x / (1 + 4a²x²)³
    exact = np.abs(-24 * a**3 * x / (1 + 4 * a**2 * x**2) ** 3)
    assert np.all(bound >= exact)
    assert np.all(bound <= exact + 2e-4)  # within one cell's change (the largest |κ''| × 0.1 mm)


@pytest.mark.parametrize("path", DRAWINGS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_the_bound_holds_on_a_dense_sample_of_every_shipped_and_held_out_drawing(path):
    outline = load_outline(path)
    beziers = [p for p in outline.pieces if isinstance(p, CubicBezier)]
    if not beziers:
        pytest.skip(f"{path.name} has no Bézier")
    for piece in beziers:
        cells = max(8, int(math.ceil(piece.length / 0.1)))
        s = np.linspace(0.0, piece.length, cells + 1)
        u = np.asarray(piece.param(s))
        bound = kappa_slope_bound(piece, u[:-1], u[1:])
        dense = np.linspace(0.0, piece.length, 8 * cells + 1)[1:-1]
        cell = np.minimum((dense / (piece.length / cells)).astype(int), cells - 1)
        sampled = np.abs(slope_by_differences(piece, dense))
        # finite differences are good to ~1e-8 of the slope's scale; the bound must be above the sample
        assert np.all(sampled <= bound[cell] * (1 + 1e-6) + 1e-9), path.name


def test_two_roots_closer_than_the_grid_are_both_found():
    """A rotation just past g's minimum on the profile's Bézier: two starts 4 µm apart, both rolls, where
    the solver's cells are 10 µm."""
    outline = load_outline(ROOT / "parts" / "profile.svg")
    P = outline.perimeter
    starts = np.asarray(outline.starts)

    def on_a_bezier(y):
        k = int(np.searchsorted(starts, y % P, "right") - 1)
        return isinstance(outline.pieces[k], CubicBezier) and np.min(np.abs(y % P - starts)) > 1.0

    def g0(x):
        return float(outline.tangent_angle_at_arc(x + L) - outline.tangent_angle_at_arc(x))

    def dg(x):
        return float(outline.curvature_at_arc(x + L) - outline.curvature_at_arc(x))

    # a smooth extremum of g0, both ends well inside Bézier pieces
    xs = np.arange(0.0, P, 0.05)
    for L in np.linspace(0.1, 0.9, 33) * P:
        d = outline.curvature_at_arc(xs + L) - outline.curvature_at_arc(xs)  # dg over xs, in one call
        found = [
            brentq(dg, xs[i], xs[i + 1], xtol=1e-14)
            for i in np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)
            if on_a_bezier(xs[i]) and on_a_bezier(xs[i] + L)
        ]
        if found:
            x = found[0]
            break
    else:
        pytest.fail("no smooth extremum of g with both ends on the profile's Béziers")
    curvature2 = (dg(x + 1e-4) - dg(x - 1e-4)) / 2e-4
    delta = 0.002
    omega = g0(x) + 0.5 * curvature2 * delta**2
    truth = [brentq(lambda y: g0(y) - omega, x - 5 * delta, x, xtol=1e-13)]
    truth.append(brentq(lambda y: g0(y) - omega, x, x + 5 * delta, xtol=1e-13))
    assert 0.003 < truth[1] - truth[0] < 0.005
    got = sorted(s.start_arc for s in feasible_segments(outline, L, omega) if abs(s.start_arc - x) < 0.1)
    assert got == pytest.approx(truth, abs=1e-9)
