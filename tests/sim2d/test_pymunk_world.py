"""The pymunk world against the kinematic (quasi-static) one, and its own properties."""

import math
from pathlib import Path

import numpy as np
import pytest

from localizer import load_part
from sim2d.pymunk_world import PymunkWorld, polygonise
from sim2d.quasistatic import QuasiStaticWorld
from tests.localizer.test_facets import polyline_dxf

PARTS = Path(__file__).resolve().parents[2] / "parts"


def frame(part, arc):
    t = part.param_at_arc(arc)
    phi = float(part.tangent_angle(t))
    return part.point(t), phi, np.array([math.cos(phi), math.sin(phi)]), np.array([-math.sin(phi), math.cos(phi)])


@pytest.fixture(scope="module")
def cam():
    return load_part(PARTS / "cam.json")


def test_polygon_meets_the_chord_tolerance(cam):
    pts = polygonise(cam, 1e-3)
    mid = 0.5 * (pts[1:] + pts[:-1])
    # distance from chord midpoints to the spline: below the tolerance
    t = np.linspace(0, cam.n_knots, 200000, endpoint=False)
    curve, normal = cam.point(t), cam.normal(t)
    d = []
    for m in mid[:: max(1, len(mid) // 60)]:
        k = int(np.argmin(np.hypot(*(curve - m).T)))
        d.append(abs(float((m - curve[k]) @ normal[k])))  # distance along the normal (the sagitta)
    assert max(d) <= 1e-3 * 1.01


@pytest.mark.parametrize("arc", [15.0, 80.0, 150.0, 220.0])
def test_pymunk_agrees_with_the_kinematic_world(cam, arc):
    c, phi, e, m = frame(cam, arc)
    pw, qw = PymunkWorld(cam), QuasiStaticWorld(cam)
    pw.set_hand(*(c + 20 * e - 1.0 * m), phi)
    for press in (0.5, 1.0):
        pose = (*(c + 20 * e + press * m), phi)
        pw.set_hand(*pose)
        qw.set_hand(*pose)
        a, b = pw.contact(), qw.contact()
        assert a.force == pytest.approx(b.force, abs=0.01)  # N
        assert a.jaw_position == pytest.approx(b.jaw_position, abs=0.01)  # mm
        assert cam.arc_at_param(a.param) == pytest.approx(cam.arc_at_param(b.param), abs=0.01)


def test_deterministic(cam):
    out = []
    for _ in range(2):
        c, phi, e, m = frame(cam, 60.0)
        w = PymunkWorld(cam)
        w.set_hand(*(c + 10 * e - 1.0 * m), phi)
        w.set_hand(*(c + 10 * e + 0.8 * m), phi + 0.01)
        k = w.contact()
        out.append((k.force, k.jaw_position, tuple(w.jaw_body.position), w.jaw_body.angle))
    assert out[0] == out[1]


def test_jaw_bridges_a_concavity_in_pymunk_too():
    part = load_part(PARTS / "trefoil.json")
    t = np.linspace(0, part.n_knots, 9000, endpoint=False)
    concave = float(part.arc_at_param(t[np.argmin(part.curvature(t))]))
    c, phi, e, m = frame(part, concave)
    pw, qw = PymunkWorld(part), QuasiStaticWorld(part)
    # approach from far out along the normal, then press: the jaw stops on the hull
    pw.set_hand(*(c - 30.0 * m), phi)
    for s in np.arange(-29.0, 1.0, 1.0):
        pw.set_hand(*(c + s * m), phi)
        if pw.contact().force > 0.2:
            break
    a = pw.contact()
    qw.set_hand(*pw.hand)
    b = qw.contact()
    assert a.force > 0.2
    assert part.curvature(a.param) > 0
    assert abs(float(part.arc_offset(part.arc_at_param(a.param), concave))) > 3.0
    assert part.arc_at_param(a.param) == pytest.approx(part.arc_at_param(b.param), abs=0.05)


def chord_error(outline, tolerance):
    """(the arcs of the pymunk polygon's vertices, the largest distance of the model from the chord over
    it, mm)."""
    from sim2d.sampled import SampledPart, model_sample

    arcs, xy, _ = model_sample(outline)
    pts = polygonise(SampledPart(outline, arcs, xy), tolerance)
    # the vertices are model samples: found by position
    index = {tuple(p): i for i, p in enumerate(xy)}
    vert = np.array([index[tuple(p)] for p in pts[:-1]])
    worst = 0.0
    for a, b in zip(vert, np.append(vert[1:], vert[0] + len(arcs))):
        seg = xy[np.arange(a, b + 1) % len(arcs)]
        d = seg[-1] - seg[0]
        n = np.array([-d[1], d[0]]) / np.hypot(*d)
        worst = max(worst, float(np.abs((seg - seg[0]) @ n).max()))
    return arcs[vert], worst


@pytest.mark.parametrize("n", [100, 2000, 20000])
def test_a_faceted_drawing_gets_the_vertices_its_curve_needs_not_one_per_facet(tmp_path, n):
    """A 60 × 20 mm ellipse drawn as n segments reads as thousands of short arcs; the world's polygon
    still meets the chord tolerance and has about as many vertices at 20 000 facets as at 100."""
    from localizer import load_outline

    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    outline = load_outline(polyline_dxf(np.c_[60.0 * np.cos(t), 20.0 * np.sin(t)], tmp_path / f"e{n}.dxf"))
    assert len(outline.pieces) >= n
    at, worst = chord_error(outline, 1e-3)
    assert worst <= 1e-3
    # 2π·60 mm at the sagitta rule with the ellipse's largest curvature (60/20²) bounds the count
    assert len(at) <= 1.1 * 2.0 * np.pi * 60.0 / math.sqrt(8.0 * 1e-3 / (60.0 / 400.0)) + 10


@pytest.mark.parametrize("name", ["bracket.dxf", "profile.svg"])
def test_a_drawings_polygon_meets_the_chord_tolerance_with_one_chord_per_face(name):
    from localizer import Line, load_outline

    outline = load_outline(PARTS / name)
    at, worst = chord_error(outline, 1e-3)
    assert worst <= 1e-3
    # a face (a line) is one chord: a vertex at each end, none between
    faces = [(a, a + p.length) for a, p in zip(outline.starts, outline.pieces) if isinstance(p, Line)]
    assert faces
    for a, b in faces:
        assert np.abs(at - a).min() < 0.005 and np.abs(at - b % outline.perimeter).min() < 0.005
        assert not np.any((at > a + 0.005) & (at < b - 0.005))
