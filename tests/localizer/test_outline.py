"""Outlines of exact pieces (the geometry of CAD parts): against closed forms and dense references
written here, not the pieces' own tables."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from localizer import CircularArc, CubicBezier, Line, PartError, outline_from_pieces


def filleted_rectangle(w=40.0, h=20.0, r=5.0):
    return [
        Line((r, 0), (w - r, 0)),
        CircularArc((w - r, r), r, -math.pi / 2, math.pi / 2),
        Line((w, r), (w, h - r)),
        CircularArc((w - r, h - r), r, 0.0, math.pi / 2),
        Line((w - r, h), (r, h)),
        CircularArc((r, h - r), r, math.pi / 2, math.pi / 2),
        Line((0, h - r), (0, r)),
        CircularArc((r, r), r, math.pi, math.pi / 2),
    ]


def l_shape():
    # 30 x 30 with a 15 x 15 notch out of the top right: five convex corners, one concave
    pts = [(0, 0), (30, 0), (30, 15), (15, 15), (15, 30), (0, 30)]
    return [Line(pts[i], pts[(i + 1) % 6]) for i in range(6)]


def dense_length(piece, n=200_000):
    """Chord sum of the piece sampled at n equal steps of its own parameter (independent of its arc table)."""
    if isinstance(piece, CubicBezier):
        u = np.linspace(0.0, 1.0, n + 1)[:, None]
        p = [np.asarray(q) for q in (piece.p0, piece.p1, piece.p2, piece.p3)]
        xy = (1 - u) ** 3 * p[0] + 3 * (1 - u) ** 2 * u * p[1] + 3 * (1 - u) * u**2 * p[2] + u**3 * p[3]
    else:
        xy = piece.point(np.linspace(0.0, piece.length, n + 1))
    return float(np.hypot(*np.diff(xy, axis=0).T).sum())


def test_perimeter_of_a_filleted_rectangle_is_its_closed_form():
    o = outline_from_pieces(filleted_rectangle())
    assert o.perimeter == pytest.approx(2 * (40 + 20) - 8 * 5 + 2 * math.pi * 5, abs=1e-9)
    assert o.corners == () and o.turning == pytest.approx(2 * math.pi, abs=1e-12)
    # lines are straight, fillets curve at 1/r
    assert o.curvature_at_arc(o.starts[0] + 1.0) == 0.0
    assert o.curvature_at_arc(o.starts[1] + 1.0) == pytest.approx(1 / 5, abs=1e-15)


def test_sharp_corners_are_jumps_of_the_tangent_angle():
    pts = [(0, 0), (40, 0), (40, 20), (0, 20)]
    o = outline_from_pieces([Line(pts[i], pts[(i + 1) % 4]) for i in range(4)])
    assert o.perimeter == pytest.approx(120.0, abs=1e-12)
    assert [c.arc for c in o.corners] == pytest.approx([0.0, 40.0, 60.0, 100.0])
    assert [c.angle for c in o.corners] == pytest.approx([math.pi / 2] * 4)
    # θ is the value after the corner at the corner, before it with side="before"
    assert o.tangent_angle_at_arc(40.0) == pytest.approx(math.pi / 2)
    assert o.tangent_angle_at_arc(40.0, side="before") == pytest.approx(0.0)
    # one lap further on, 2π more
    assert o.tangent_angle_at_arc(40.0 + 120.0) == pytest.approx(math.pi / 2 + 2 * math.pi)


def test_a_concave_corner_turns_the_other_way_and_the_jumps_add_to_one_turn():
    o = outline_from_pieces(l_shape())
    angles = sorted(c.angle for c in o.corners)
    assert angles == pytest.approx([-math.pi / 2] + [math.pi / 2] * 5)
    assert sum(angles) == pytest.approx(2 * math.pi)


def test_a_clockwise_chain_is_reversed_with_its_first_point_first():
    cw = [p.reversed() for p in reversed(filleted_rectangle())]
    o = outline_from_pieces(cw)
    poly = o.sample(0.5)
    area = 0.5 * np.sum(poly[:-1, 0] * poly[1:, 1] - poly[1:, 0] * poly[:-1, 1])
    assert area > 0  # counter-clockwise
    assert o.point_at_arc(0.0) == pytest.approx(cw[0].start)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-30, 30), min_size=8, max_size=8))
def test_a_bezier_length_matches_a_dense_chord_sum(c):
    b = CubicBezier((c[0], c[1]), (c[2] + 40, c[3]), (c[4], c[5] + 40), (c[6] + 40, c[7] + 40))
    # a chord sum of n steps is short by about L·(h·κ)²/24: 1e-6 mm is far above that here
    assert b.length == pytest.approx(dense_length(b), rel=1e-7, abs=1e-6)


def test_a_straight_bezier_has_its_chord_length_exactly():
    b = CubicBezier((0, 0), (10, 5), (20, 10), (30, 15))  # evenly spaced control points: uniform speed
    assert b.length == pytest.approx(math.hypot(30, 15), abs=1e-12)
    assert b.curvature(np.linspace(0, b.length, 7)) == pytest.approx(np.zeros(7), abs=1e-12)


def test_bezier_arc_parameter_inverts_its_arc_length():
    b = CubicBezier((0, 0), (10, 30), (40, -20), (50, 10))
    s = np.linspace(0.0, b.length, 41)
    u = b.param(s)
    # independent: the arc length from 0 to u by a fine trapezoid rule on the parameter
    for si, ui in zip(s[1:], u[1:]):
        t = np.linspace(0.0, ui, 20001)[:, None]
        p = [np.asarray(q) for q in (b.p0, b.p1, b.p2, b.p3)]
        xy = (1 - t) ** 3 * p[0] + 3 * (1 - t) ** 2 * t * p[1] + 3 * (1 - t) * t**2 * p[2] + t**3 * p[3]
        assert float(np.hypot(*np.diff(xy, axis=0).T).sum()) == pytest.approx(si, abs=1e-5)


def _newton_in_numpy(b, s):
    """The arc's inversion as array arithmetic on the piece's own 16-point rule and speed (the reference the
    compiled loop must equal to the bit: each point stepped until within 1e-12 mm, then left alone; after a
    step of at most SHORT_STEP, the arc length is the last one plus the 4-point rule's over the step, its
    four terms added in order)."""
    from localizer.geometry._bezier_kernels import SHORT_STEP
    from localizer.geometry._numerics import gauss_legendre

    g4_x, g4_w = gauss_legendre(4)
    arc = np.clip(np.asarray(s, dtype=float), 0.0, b.length)
    k = np.clip(np.searchsorted(b._cum, arc, side="right") - 1, 0, len(b._breaks) - 2)
    lo, hi = b._breaks[k], b._breaks[k + 1]
    u = lo + (hi - lo) * (arc - b._cum[k]) / np.maximum(b._cum[k + 1] - b._cum[k], 1e-300)
    f = b._cum[k] + b._gauss_to(lo, u) - arc
    live = np.abs(f) > 1e-12
    for _ in range(50):
        if not live.any():
            break
        ul, fl = u[live], f[live]
        nxt = np.clip(ul - fl / np.maximum(b._speed(ul), 1e-300), lo[live], hi[live])
        d = nxt - ul
        terms = [b._speed(ul + d * x) * w for x, w in zip(g4_x, g4_w)]
        short = fl + (((terms[0] + terms[1]) + terms[2]) + terms[3]) * d
        again = b._cum[k[live]] + b._gauss_to(lo[live], nxt) - arc[live]
        u[live], f[live] = nxt, np.where(np.abs(d) <= SHORT_STEP, short, again)
        live &= np.abs(f) > 1e-12
    return u


@pytest.mark.parametrize("weights", [(1.0, 1.0, 1.0, 1.0), (1.0, 0.7, 0.7, 1.0), (2.0, 0.5, 1.5, 0.8)])
def test_the_compiled_arc_inversion_is_the_array_arithmetic_to_the_bit(weights):
    b = CubicBezier((0, 0), (10, 30), (40, -20), (50, 10), weights=weights)
    s = np.random.default_rng(5).uniform(0.0, b.length, 400)
    assert np.array_equal(b.param(s), _newton_in_numpy(b, s))
    assert b.param(float(s[0])) == _newton_in_numpy(b, s[:1])[0] and np.shape(b.param(float(s[0]))) == ()


def test_bezier_curvature_is_the_derivative_of_its_tangent_angle():
    b = CubicBezier((0, 0), (10, 30), (40, -20), (50, 10))
    s = np.linspace(1.0, b.length - 1.0, 25)
    ds = 1e-5
    dtheta = (b.tangent_angle(s + ds) - b.tangent_angle(s - ds)) / (2 * ds)
    assert b.curvature(s) == pytest.approx(dtheta, abs=1e-6)
    # unwrapped along the piece: no 2π steps
    assert np.abs(np.diff(b.tangent_angle(np.linspace(0, b.length, 400)))).max() < 0.1


def test_arc_points_lie_on_the_circle_and_reversal_retraces_them():
    a = CircularArc((3.0, -2.0), 7.5, 0.3, -1.9)
    s = np.linspace(0.0, a.length, 11)
    xy = a.point(s)
    assert np.hypot(xy[:, 0] - 3.0, xy[:, 1] + 2.0) == pytest.approx(np.full(11, 7.5), abs=1e-12)
    assert a.reversed().point(s[::-1]) == pytest.approx(xy, abs=1e-12)
    assert a.curvature(s) == pytest.approx(np.full(11, -1 / 7.5))


@pytest.mark.parametrize(
    "pieces, match",
    [
        ([], "no pieces"),
        ([Line((0, 0), (10, 0)), Line((10, 0), (10, 10)), Line((10, 10.1), (0, 0))], r"piece 1 ends at \(10.0, 10.0\)"),
        (
            [Line((0, 0), (10, 10)), Line((10, 10), (10, 0)), Line((10, 0), (0, 10)), Line((0, 10), (0, 0))],
            "crosses itself",
        ),
    ],
)
def test_bad_outlines_are_refused_naming_the_problem(pieces, match):
    with pytest.raises(PartError, match=match):
        outline_from_pieces(pieces, name="bad")


def test_degenerate_pieces_are_refused():
    with pytest.raises(PartError, match="zero length"):
        Line((1, 1), (1, 1))
    with pytest.raises(PartError, match="radius=-1"):
        CircularArc((0, 0), -1, 0.0, 1.0)
    with pytest.raises(PartError, match="cusp"):
        CubicBezier((0, 0), (0, 0), (0, 0), (10, 0))


def test_a_loop_that_folds_back_or_encloses_nothing_is_not_a_part():
    # (0,0) (50,0) (100,0) closed: a line drawn out and back; once it loaded as a 200 mm outline with two
    # -pi corners and localize took gigabytes
    there_and_back = [Line((0, 0), (50, 0)), Line((50, 0), (100, 0)), Line((100, 0), (0, 0))]
    with pytest.raises(PartError, match=r"folds back on itself at \(0\.000, 0\.000\) mm"):
        outline_from_pieces(there_and_back)
    # a stadium 1e-4 mm wide: no corner, a sliver with no inside
    w, length = 1e-4, 100.0
    stadium = [
        Line((0, 0), (length, 0)),
        CircularArc((length, w / 2), w / 2, -math.pi / 2, math.pi),
        Line((length, w), (0, w)),
        CircularArc((0, w / 2), w / 2, math.pi / 2, math.pi),
    ]
    with pytest.raises(PartError, match=r"encloses 0\.01 mm² with a perimeter of 200\.000 mm: it has no inside"):
        outline_from_pieces(stadium)
    # a knife edge of a real part (a 1° wedge) and a 1 mm strip a metre long are parts
    narrow = [Line((0, 0), (1000, 0)), Line((1000, 0), (1000, 1)), Line((1000, 1), (0, 1)), Line((0, 1), (0, 0))]
    assert len(outline_from_pieces(narrow).corners) == 4
    tip = (100 * math.cos(math.radians(1)), 100 * math.sin(math.radians(1)))
    wedge = outline_from_pieces([Line((0, 0), (100, 0)), Line((100, 0), tip), Line(tip, (0, 0))])
    assert max(abs(c.angle) for c in wedge.corners) == pytest.approx(math.radians(179), abs=1e-9)
