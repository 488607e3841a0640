import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from localizer import Part, PartError, load_part, part_from_points
from tests.localizer.reference import DenseCurve, random_part_points


def circle_points(n=64, r=40.0):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[r * np.cos(a), r * np.sin(a)]


def ellipse_points(n=48, a=40.0, b=25.0):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[a * np.cos(t), b * np.sin(t)]


TREFOIL = None


def trefoil():
    global TREFOIL
    if TREFOIL is None:
        a = np.linspace(0, 2 * np.pi, 90, endpoint=False)
        r = 50 + 8 * np.cos(3 * a) + 3 * np.sin(5 * a)
        TREFOIL = part_from_points(np.c_[r * np.cos(a), r * np.sin(a)], name="trefoil")
    return TREFOIL


def test_circle_perimeter_and_curvature_match_analytic():
    part = part_from_points(circle_points(128, 40.0))
    assert part.perimeter == pytest.approx(2 * np.pi * 40.0, rel=1e-7)
    t = np.linspace(0, 128, 1000, endpoint=False)
    # the interpolating spline ripples around the circle: curvature within 5e-4 relative
    assert np.allclose(part.curvature(t), 1 / 40.0, rtol=5e-4)
    assert np.allclose(np.linalg.norm(part.point(t), axis=1), 40.0, atol=1e-5)


def test_ellipse_perimeter_matches_ramanujan():
    a, b = 40.0, 25.0
    h = ((a - b) / (a + b)) ** 2
    ramanujan = np.pi * (a + b) * (1 + 3 * h / (10 + np.sqrt(4 - 3 * h)))
    part = part_from_points(ellipse_points(96, a, b))
    assert part.perimeter == pytest.approx(ramanujan, rel=1e-6)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_arc_length_and_angle_agree_with_dense_reference(seed):
    pts = random_part_points(np.random.default_rng(seed))
    part = part_from_points(pts)
    ref = DenseCurve(pts)
    assert part.perimeter == pytest.approx(ref.perimeter, abs=1e-9)
    t = np.random.default_rng(seed + 10).uniform(0, part.n_knots, 200)
    sig_ref = np.interp(t, ref.t, ref.sigma)  # only used where exact: at grid points below
    tg = ref.t[::97]
    assert np.allclose(part.arc_at_param(tg), ref.sigma[::97], atol=1e-9)
    assert np.allclose(part.tangent_angle(tg), ref.theta[::97] - ref.theta[0] + part.tangent_angle(0.0), atol=1e-12)
    assert sig_ref.shape == t.shape


def test_spline_is_c2_at_the_knots_and_interpolates():
    pts = random_part_points(np.random.default_rng(5), n=30)
    part = part_from_points(pts)
    k = np.arange(30.0)
    eps = 1e-9
    assert np.allclose(part.point(k), part.points, atol=1e-12)
    assert np.allclose(part.derivative(k - eps), part.derivative(k + eps), atol=1e-6)
    assert np.allclose(part.curvature(k - eps), part.curvature(k + eps), atol=1e-6)


def test_segments_wrap_past_the_first_point():
    part = trefoil()
    P = part.perimeter
    s, t = 80.0, 5.0  # t < s: the stretch wraps through parameter 0
    assert part.arc_length(s, t) + part.arc_length(t, s) == pytest.approx(P, abs=1e-9)
    assert part.total_curvature(s, t) + part.total_curvature(t, s) == pytest.approx(2 * np.pi, abs=1e-12)
    assert part.arc_length(s, t) == pytest.approx(part.arc_at_param(t + 90) - part.arc_at_param(s), abs=1e-12)
    assert part.total_curvature(0.0, 90.0) == pytest.approx(2 * np.pi, abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.floats(-400.0, 1200.0))
def test_param_at_arc_inverts_arc_length(sigma):
    part = trefoil()
    t = part.param_at_arc(np.array([sigma]))
    assert part.arc_at_param(t)[0] == pytest.approx(sigma, abs=1e-9)


def test_clockwise_points_are_reoriented_keeping_the_first_point():
    pts = ellipse_points()
    cw = np.vstack([pts[:1], pts[:0:-1]])
    part = part_from_points(cw)
    assert np.allclose(part.points[0], pts[0])
    assert np.allclose(part.points, pts)
    assert part.total_curvature(0.0, part.n_knots) == pytest.approx(2 * np.pi)


def test_load_json_and_csv(tmp_path):
    pts = ellipse_points()
    (tmp_path / "e.json").write_text(json.dumps({"name": "e", "units": "cm", "points": (pts / 10).tolist()}))
    part = load_part(tmp_path / "e.json")
    assert part.name == "e"
    assert np.allclose(part.points, pts)
    (tmp_path / "e.csv").write_text("# comment\nx,y\n" + "\n".join(f"{x},{y}" for x, y in pts))
    part2 = load_part(tmp_path / "e.csv")
    assert part2.perimeter == pytest.approx(part.perimeter, abs=1e-12)


@pytest.mark.parametrize(
    "points, match",
    [
        ([[0, 0], [1, 0], [1, 1]], "at least 4 points, got 3"),
        ([[0, 0], [1, 0], [1, np.nan], [0, 1]], r"point 2 is \[1.0, nan\]: NaN or inf"),
        ([[0, 0], [1, 0], [1, np.inf], [0, 1]], "NaN or inf"),
        ([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1]], "points 1 and 2 coincide"),
        ([[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]], "points 4 and 0 coincide"),
        ([[0, 0], [1, 1], [1, 0], [0, 1]], "crosses itself"),
        ([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], r"shape \(N, 2\)"),
        ([["a", 0], [1, 0], [1, 1], [0, 1]], "list of"),
    ],
)
def test_bad_points_raise_part_error(points, match):
    with pytest.raises(PartError, match=match):
        part_from_points(points)


def test_self_crossing_figure_eight_is_refused():
    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    pts = np.c_[30 * np.sin(a), 15 * np.sin(2 * a)]
    with pytest.raises(PartError, match="crosses itself"):
        part_from_points(pts)


def test_locally_looping_outline_is_refused():
    # a star-shaped outline with one point pulled across its neighbours
    a = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    pts = np.c_[40 * np.cos(a), 40 * np.sin(a)]
    pts[5], pts[6] = pts[6].copy(), pts[5].copy()
    with pytest.raises(PartError, match="crosses itself"):
        part_from_points(pts)


def test_bad_files(tmp_path):
    with pytest.raises(PartError, match="cannot read part file"):
        load_part(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(PartError, match="not valid JSON"):
        load_part(tmp_path / "bad.json")
    (tmp_path / "units.json").write_text(json.dumps({"units": "furlong", "points": ellipse_points().tolist()}))
    with pytest.raises(PartError, match="unknown units 'furlong'"):
        load_part(tmp_path / "units.json")
    (tmp_path / "nopts.json").write_text(json.dumps({"name": "x"}))
    with pytest.raises(PartError, match='"points"'):
        load_part(tmp_path / "nopts.json")
    (tmp_path / "bad.csv").write_text("x,y\n1,2\n3,oops\n")
    with pytest.raises(PartError, match="row 3"):
        load_part(tmp_path / "bad.csv")


def test_part_is_immutable():
    part = trefoil()
    with pytest.raises(AttributeError):
        part.perimeter = 1.0
    with pytest.raises(ValueError):
        part.points[0, 0] = 1.0
    assert isinstance(part, Part)


def test_arc_offset_is_the_signed_shortest_way_round():
    part = trefoil()
    P = part.perimeter
    assert part.arc_offset(5.0, P - 5.0) == pytest.approx(10.0)
    assert part.arc_offset(P - 5.0, 5.0) == pytest.approx(-10.0)
    assert part.arc_offset(3.0 + 2 * P, 1.0) == pytest.approx(2.0)
    off = part.arc_offset(np.linspace(0, 3 * P, 101), 17.0)
    assert np.all(off >= -P / 2) and np.all(off < P / 2)
