"""A model's boundary moved along its normal, joined at corners (sim2d.offset), against closed forms."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from localizer import Line, outline_from_pieces, polygon_crossing
from sim2d.machining import machined_outline
from sim2d.noise import load_noise
from sim2d.offset import offset_boundary
from sim2d.quasistatic import outline_touch
from sim2d.sampled import model_sample


def _area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _distance_to_polygon(xy, poly):
    """Each point's distance to the closed polygon ``poly`` (brute force over its edges)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    ab = b - a
    rel = xy[:, None, :] - a[None]
    t = np.clip(np.einsum("nkj,kj->nk", rel, ab) / np.einsum("kj,kj->k", ab, ab), 0.0, 1.0)
    return np.min(np.hypot(*(rel - t[..., None] * ab).transpose(2, 0, 1)), axis=1)


def _polygon(points):
    return outline_from_pieces([Line(points[k], points[(k + 1) % len(points)]) for k in range(len(points))])


@settings(max_examples=25, deadline=None)
@given(offset=st.floats(-3.0, 3.0).filter(lambda o: abs(o) > 1e-3))
def test_a_square_moved_evenly_is_the_offset_square(offset):
    # inward: a smaller square with sharp corners; outward: rounded by arcs of radius |offset| about each
    # corner (area L² + 4·L·o + π·o²); every point |offset| from the model's square, none crossing
    side = 20.0
    square = _polygon([(0.0, 0.0), (side, 0.0), (side, side), (0.0, side)])
    arcs, _, normal = model_sample(square, 0.05)
    out_arcs, xy = offset_boundary(square, arcs, normal, np.full(arcs.size, offset))
    corners = np.array([(0.0, 0.0), (side, 0.0), (side, side), (0.0, side)])
    np.testing.assert_allclose(_distance_to_polygon(xy, corners), abs(offset), atol=1e-9)
    assert polygon_crossing(np.vstack([xy, xy[:1]])) is None
    assert np.all(np.diff(out_arcs) >= 0)
    if offset < 0:
        assert _area(xy) == pytest.approx((side - 2 * abs(offset)) ** 2, rel=1e-3)
    else:  # the rounds are drawn every 5°: their polygon's area is a little short of the circle's
        assert _area(xy) == pytest.approx(side**2 + 4 * side * offset + math.pi * offset**2, rel=2e-3)


@settings(max_examples=25, deadline=None)
@given(offset=st.floats(-1.0, 1.0).filter(lambda o: abs(o) > 1e-3), notch=st.floats(0.05, 1.2))
def test_a_notch_moved_evenly_does_not_cross_itself(offset, notch):
    # a plate with a V notch (a concave corner of exterior angle -2·notch and two convex ones): moved out
    # the notch's pieces overlap, moved in the convex corners' do: each cut where it meets the other, so
    # every point is |offset| from the model and the boundary is simple
    w, depth = 30.0, 6.0
    half = min(depth * math.tan(0.5 * math.pi - notch), 10.0)
    top = [(w / 2 + half, 20.0), (w / 2, 20.0 - depth), (w / 2 - half, 20.0)]
    pts = [(0.0, 0.0), (w, 0.0), (w, 20.0), *top, (0.0, 20.0)]
    plate = _polygon(pts)
    # where the overlap reaches further than a piece is long, the pieces' offsets meet pieces beyond: the
    # world is then refused as crossing itself (world_part), not joined
    shortest = min(math.dist(pts[k], pts[(k + 1) % len(pts)]) for k in range(len(pts)))
    assume(all(abs(offset) * math.tan(0.5 * abs(c.angle)) < 0.4 * shortest for c in plate.corners))
    arcs, _, normal = model_sample(plate, 0.02)
    _, xy = offset_boundary(plate, arcs, normal, np.full(arcs.size, offset))
    assert polygon_crossing(np.vstack([xy, xy[:1]])) is None
    np.testing.assert_allclose(_distance_to_polygon(xy, np.array(pts)), abs(offset), atol=1e-6)


def test_a_jaw_meets_a_machined_convex_corner_where_the_model_says():
    # rolling in on a curve's end, the jaw reaches the corner when its angle reaches the curve's end
    # tangent, machined or not: within the machining's slope error (tens of µm of arc), never the
    # degree early that a point moved along the outgoing normal alone, 9 µm proud of the curve, made it
    from localizer import CircularArc

    r = 48.0
    piece = CircularArc((0.0, 0.0), r, -0.5, 1.4)  # centre, radius, start angle, sweep
    a0 = (r * math.cos(-0.5), r * math.sin(-0.5))
    a1 = (r * math.cos(0.9), r * math.sin(0.9))
    outline = outline_from_pieces([piece, Line(a1, a0)])
    corner = next(c for c in outline.corners if abs(c.arc - r * 1.4) < 1e-6)
    th_in = float(outline.tangent_angle_at_arc(corner.arc - 1e-9))
    noise = load_noise("paper")
    for seed in range(12):
        world = machined_outline(outline, noise, np.random.default_rng(seed))
        for before in (1.0, 0.5, 0.2):
            phi = th_in - math.radians(before)
            _, _, arc, _, _ = outline_touch(world, tuple(outline.point_at_arc(corner.arc)), phi, 50.0)
            model = corner.arc - r * math.radians(before)
            assert abs(arc - model) < 0.15, (seed, before, arc - model)
