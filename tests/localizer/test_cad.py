"""CAD outlines read from DXF (written here with ezdxf) and SVG (written here as text): perimeters
against closed forms, units, the y flip, the outer loop, the first point, and the errors."""

import math
import os

import ezdxf
import numpy as np
import pytest
from scipy.special import ellipe

from localizer import PartError, load_outline

W, H, R = 60.0, 40.0, 6.0
FILLETED = 2 * (W + H) - 8 * R + 2 * math.pi * R  # four quarter-circle fillets


def bulge(quarter_ccw=True):
    return math.tan(math.radians(90.0) / 4.0) * (1 if quarter_ccw else -1)


def bracket_dxf(path, units=4, scale=1.0):
    """A filleted rectangle as one closed LWPOLYLINE with bulges (layer OUTLINE), a hole and a title
    on other layers."""
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = units
    msp = doc.modelspace()
    b = bulge()
    pts = [
        (R, 0, 0),
        (W - R, 0, b),
        (W, R, 0),
        (W, H - R, b),
        (W - R, H, 0),
        (R, H, b),
        (0, H - R, 0),
        (0, R, b),
    ]
    pts = [(x * scale, y * scale, bb) for x, y, bb in pts]
    msp.add_lwpolyline(pts, format="xyb", close=True, dxfattribs={"layer": "OUTLINE"})
    msp.add_circle((W / 2 * scale, H / 2 * scale), 5 * scale, dxfattribs={"layer": "HOLES"})
    msp.add_text("BRACKET", dxfattribs={"layer": "TITLE"})
    doc.saveas(path)
    return path


def test_a_filleted_polyline_has_its_closed_form_perimeter_and_no_corner(tmp_path):
    o = load_outline(bracket_dxf(tmp_path / "bracket.dxf"))
    assert o.perimeter == pytest.approx(FILLETED, abs=1e-9)
    assert o.corners == ()
    assert o.point_at_arc(0.0) == pytest.approx([R, 0.0])
    assert any("CIRCLE" in note or "loop" in note for note in o.ignored)
    assert any("TEXT" in note for note in o.ignored)


def test_a_polyline_read_from_ezdxfs_packed_vertices_is_its_public_reading(tmp_path):
    """The vertices read from ezdxf's packed array, and through get_points where that array is not as
    expected (another ezdxf): the same pieces, to the bit, bulges and all."""
    from types import SimpleNamespace

    from localizer.geometry._dxf import _polyline

    e = ezdxf.readfile(bracket_dxf(tmp_path / "bracket.dxf")).modelspace().query("LWPOLYLINE")[0]
    public = SimpleNamespace(lwpoints=list(e.lwpoints), get_points=e.get_points, closed=e.closed)
    packed = _polyline(e, "LWPOLYLINE", 2.0, "here")
    assert len(packed) == 8 and packed == _polyline(public, "LWPOLYLINE", 2.0, "here")
    assert repr(packed) == repr(_polyline(public, "LWPOLYLINE", 2.0, "here"))


@pytest.mark.parametrize("units, size", [(1, 25.4), (5, 10.0), (4, 1.0)])
def test_dxf_units_are_read_into_millimetres(tmp_path, units, size):
    o = load_outline(bracket_dxf(tmp_path / "b.dxf", units=units))
    assert o.perimeter == pytest.approx(FILLETED * size, rel=1e-12)


def test_loose_lines_and_arcs_are_chained_into_the_loop(tmp_path):
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    # a 30 x 20 plate with a 10 mm half-circle bump on its top edge; some pieces drawn backwards
    msp.add_line((0, 0), (30, 0))
    msp.add_line((30, 20), (30, 0))  # backwards
    msp.add_line((30, 20), (20, 20))
    msp.add_arc((15, 20), 5, 0, 180)  # counter-clockwise from (20, 20) to (10, 20)
    msp.add_line((0, 20), (10, 20))  # backwards
    msp.add_line((0, 20), (0, 0))
    doc.saveas(tmp_path / "plate.dxf")
    o = load_outline(tmp_path / "plate.dxf")
    assert o.perimeter == pytest.approx(30 + 20 + 10 + math.pi * 5 + 10 + 20, abs=1e-9)
    # corners: four of the plate (+π/2 each) and two where the bump leaves and rejoins the edge (−π/2)
    assert sorted(round(c.angle, 12) for c in o.corners) == sorted(
        [round(-math.pi / 2, 12)] * 2 + [round(math.pi / 2, 12)] * 4
    )


def test_a_layer_can_be_chosen_and_a_missing_one_is_named(tmp_path):
    path = bracket_dxf(tmp_path / "b.dxf")
    hole = load_outline(path, layer="HOLES")
    assert hole.perimeter == pytest.approx(2 * math.pi * 5, abs=1e-9)
    with pytest.raises(PartError, match="no entity on layer 'NOPE'; layers: .*OUTLINE"):
        load_outline(path, layer="NOPE")


def test_a_cubic_spline_is_read_as_bezier_pieces(tmp_path):
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    ctrl = [(0, 0), (20, -10), (40, 10), (60, 0)]
    spline = msp.add_open_spline(ctrl, degree=3)
    msp.add_line((60, 0), (60, 30))
    msp.add_line((60, 30), (0, 30))
    msp.add_line((0, 30), (0, 0))
    doc.saveas(tmp_path / "s.dxf")
    o = load_outline(tmp_path / "s.dxf")
    # independent: ezdxf's own dense flattening of the spline, plus the three lines
    pts = np.array([(v.x, v.y) for v in spline.construction_tool().approximate(200_000)])
    dense = float(np.hypot(*np.diff(pts, axis=0).T).sum())
    assert o.perimeter == pytest.approx(dense + 30 + 60 + 30, abs=1e-6)


def ellipse_perimeter(a, b):
    """4a·E(m), m = 1 − b²/a²: the complete elliptic integral of the second kind (scipy)."""
    return 4 * a * ellipe(1 - (b / a) ** 2)


def test_a_dxf_ellipse_is_exact_whatever_its_extrusion(tmp_path):
    a, b, tilt = 30.0, 12.0, 0.3
    for extrusion in ((0, 0, 1), (0, 0, -1)):
        doc = ezdxf.new()
        doc.header["$INSUNITS"] = 4
        major = (a * math.cos(tilt), a * math.sin(tilt))
        e = doc.modelspace().add_ellipse((5, 6), major_axis=major, ratio=b / a, dxfattribs={"extrusion": extrusion})
        doc.saveas(tmp_path / "e.dxf")
        o = load_outline(tmp_path / "e.dxf")
        assert o.perimeter == pytest.approx(ellipse_perimeter(a, b), abs=1e-9)
        assert o.corners == ()
        # curvature against the closed form a·b / (a² sin² t + b² cos² t)^{3/2} at the points' own t
        sigma = np.linspace(0, o.perimeter, 97, endpoint=False)
        q = o.point_at_arc(sigma) - [5, 6]
        x = q[:, 0] * math.cos(tilt) + q[:, 1] * math.sin(tilt)
        y = -q[:, 0] * math.sin(tilt) + q[:, 1] * math.cos(tilt)
        assert (x / a) ** 2 + (y / b) ** 2 == pytest.approx(1.0, abs=1e-12)
        t = np.arctan2(y / b, x / a)
        kappa = a * b / (a**2 * np.sin(t) ** 2 + b**2 * np.cos(t) ** 2) ** 1.5
        assert o.curvature(sigma) == pytest.approx(kappa, rel=1e-9)
        assert e.dxf.extrusion.z == extrusion[2]


def test_a_dxf_elliptical_arc_closed_by_a_line(tmp_path):
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_ellipse((0, 0), major_axis=(20, 0), ratio=0.5, start_param=0.0, end_param=math.pi)
    msp.add_line((-20, 0), (20, 0))
    doc.saveas(tmp_path / "half.dxf")
    o = load_outline(tmp_path / "half.dxf")
    assert o.perimeter == pytest.approx(ellipse_perimeter(20, 10) / 2 + 40, abs=1e-9)
    assert [c.angle for c in o.corners] == pytest.approx([math.pi / 2] * 2, abs=1e-9)


def test_a_nurbs_circle_is_a_circle(tmp_path):
    """The textbook degree-2 NURBS circle (nine control points, corner weights 1/√2): the reader
    splits it as the B-spline of its homogeneous points, so it is a circle to rounding."""
    r, w = 20.0, math.sqrt(0.5)
    cps = [(r, 0), (r, r), (0, r), (-r, r), (-r, 0), (-r, -r), (0, -r), (r, -r), (r, 0)]
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    knots = [0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4]
    doc.modelspace().add_rational_spline(cps, [1, w, 1, w, 1, w, 1, w, 1], degree=2, knots=knots)
    doc.saveas(tmp_path / "c.dxf")
    o = load_outline(tmp_path / "c.dxf")
    assert o.perimeter == pytest.approx(2 * math.pi * r, abs=1e-9)
    sigma = np.linspace(0, o.perimeter, 101, endpoint=False)
    assert np.hypot(*o.point_at_arc(sigma).T) == pytest.approx(r, abs=1e-12)
    assert o.curvature(sigma) == pytest.approx(1 / r, rel=1e-9)
    # arc position is arc length: the points' polar angle grows as σ / r
    angle = np.unwrap(np.arctan2(*o.point_at_arc(sigma)[:, ::-1].T))
    assert angle - angle[0] == pytest.approx(sigma / r, abs=1e-9)


def test_a_weighted_cubic_spline_matches_ezdxf_dense(tmp_path):
    cps = [(0, 0), (10, 25), (40, 30), (60, 0)]
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    spline = msp.add_rational_spline(cps, [1.0, 3.0, 0.5, 1.0], degree=3)
    msp.add_line((60, 0), (0, 0))
    doc.saveas(tmp_path / "w.dxf")
    o = load_outline(tmp_path / "w.dxf")
    pts = np.array([(v.x, v.y) for v in spline.construction_tool().approximate(400_000)])
    dense = float(np.hypot(*np.diff(pts, axis=0).T).sum())
    assert o.perimeter == pytest.approx(dense + 60, abs=1e-6)


def test_unreadable_entities_and_units_are_named(tmp_path):
    bracket_dxf(tmp_path / "u.dxf", units=3)  # miles
    with pytest.raises(PartError, match=r"\$INSUNITS=3"):
        load_outline(tmp_path / "u.dxf")
    doc = ezdxf.new()
    doc.modelspace().add_line((0, 0), (10, 0))
    doc.saveas(tmp_path / "open.dxf")
    with pytest.raises(PartError, match="no closed loop"):
        load_outline(tmp_path / "open.dxf")


SVG = """<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {vw} {vh}">
  <text x="0" y="10">PROFILE</text>
  <g transform="translate(10, 10)">
    <path id="profile" d="M 0 0 L 60 0 A 10 10 0 0 1 70 10 L 70 40 Q 70 50 60 50 L 0 50 Z"/>
  </g>
  <circle id="hole" cx="40" cy="35" r="4"/>
</svg>"""
# the quadratic's length: from (70, 40) via (70, 50) to (60, 50)
_t = np.linspace(0, 1, 400_001)[:, None]
_q = (1 - _t) ** 2 * np.array([70, 40]) + 2 * (1 - _t) * _t * np.array([70, 50]) + _t**2 * np.array([60, 50])
QUAD = float(np.hypot(*np.diff(_q, axis=0).T).sum())
PROFILE = 60 + math.pi * 10 / 2 + 30 + QUAD + 60 + 50


def test_an_svg_path_in_user_units_is_millimetres_with_y_up(tmp_path):
    (tmp_path / "p.svg").write_text(SVG.format(w="100", h="80", vw=100, vh=80))
    o = load_outline(tmp_path / "p.svg")
    assert o.perimeter == pytest.approx(PROFILE, abs=1e-6)
    # the path's first M, transformed and flipped
    assert o.point_at_arc(0.0) == pytest.approx([10.0, -10.0], abs=1e-12)
    poly = o.sample(0.5)
    assert 0.5 * np.sum(poly[:-1, 0] * poly[1:, 1] - poly[1:, 0] * poly[:-1, 1]) > 0  # counter-clockwise
    # the arc and the quadratic join their lines tangentially: the only corners are the two ends of
    # the closing line, both convex quarter turns
    assert [c.angle for c in o.corners] == pytest.approx([math.pi / 2] * 2)


def test_an_svg_with_a_physical_size_is_scaled_exactly(tmp_path):
    (tmp_path / "p.svg").write_text(SVG.format(w="50mm", h="40mm", vw=100, vh=80))
    o = load_outline(tmp_path / "p.svg")
    assert o.perimeter == pytest.approx(PROFILE / 2, abs=1e-6)
    assert o.point_at_arc(0.0) == pytest.approx([5.0, -5.0], abs=1e-12)


def test_an_svg_element_can_be_chosen(tmp_path):
    (tmp_path / "p.svg").write_text(SVG.format(w="100", h="80", vw=100, vh=80))
    assert load_outline(tmp_path / "p.svg", element="hole").perimeter == pytest.approx(8 * math.pi, abs=1e-6)
    with pytest.raises(PartError, match="no path or shape with id 'x'; ids: \\['hole', 'profile'\\]"):
        load_outline(tmp_path / "p.svg", element="x")


def test_elliptical_svg_arcs_are_exact_in_a_path_and_an_ellipse(tmp_path):
    svg = """<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
      <path id="p" d="M 20 50 A 30 12 0 0 1 80 50 A 30 12 0 0 1 20 50 Z"/>
      <path id="d" d="M 0 0 L 50 0 A 20 10 0 0 1 50 20 L 0 20 Z"/>
      <ellipse id="q" cx="50" cy="50" rx="30" ry="12" transform="rotate(20 50 50)"/></svg>"""
    (tmp_path / "e.svg").write_text(svg)
    for element in ("p", "q"):
        assert load_outline(tmp_path / "e.svg", element=element).perimeter == pytest.approx(
            ellipse_perimeter(30, 12), abs=1e-9
        )
    # a D: three lines and half an ellipse, its 20 mm chord the y semi-axis (10) twice, bulging by rx = 20
    d = load_outline(tmp_path / "e.svg", element="d")
    assert d.perimeter == pytest.approx(50 + 20 + 50 + ellipse_perimeter(20, 10) / 2, abs=1e-9)
    far = d.point_at_arc(np.linspace(0, d.perimeter, 20001))[:, 0].max()
    assert far == pytest.approx(70.0, abs=1e-4)


def test_two_equal_loops_need_a_choice(tmp_path):
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg"><rect id="a" x="0" y="0" width="10" height="10"/>'
        '<rect id="b" x="20" y="0" width="10" height="10"/></svg>'
    )
    (tmp_path / "two.svg").write_text(svg)
    with pytest.raises(PartError, match="2 loops of equal area .*name the layer"):
        load_outline(tmp_path / "two.svg")
    assert load_outline(tmp_path / "two.svg", element="b").perimeter == pytest.approx(40.0, abs=1e-12)


def test_the_shipped_bracket_and_profile():
    from pathlib import Path

    parts = Path(__file__).resolve().parents[2] / "parts"
    bracket = load_outline(parts / "bracket.dxf")
    # faces plus three quarter-circle fillets (R8, R8, R10): the closed form, to 1e-9 mm
    assert bracket.perimeter == pytest.approx(72 + 24 + 22 + 10 + 20 + 10 + 20 + 30 + math.pi / 2 * 26, abs=1e-9)
    assert sorted(round(c.angle, 12) for c in bracket.corners) == sorted(
        [round(math.pi / 2, 12)] * 3 + [round(-math.pi / 2, 12)] * 2
    )
    assert bracket.point_at_arc(0.0) == pytest.approx([0.0, 0.0])
    profile = load_outline(parts / "profile.svg")
    assert profile.point_at_arc(0.0) == pytest.approx([0.0, 0.0], abs=1e-12)  # the path's first M, y up
    assert len(profile.corners) == 3 and all(c.angle > 0 for c in profile.corners)
    from localizer import Outline, load_part

    # load_part reads a drawing as its outline; a point file takes no layer or element
    via_load_part = load_part(parts / "bracket.dxf")
    assert isinstance(via_load_part, Outline) and via_load_part.perimeter == bracket.perimeter
    with pytest.raises(PartError, match="layer='outline'.*point file"):
        load_part(parts / "cam.json", layer="outline")


def test_smooth_joins_written_with_rounded_coordinates_are_not_corners(tmp_path):
    """Béziers joined smoothly, written with 3 decimals (as exporters do): the rounding breaks each
    join by up to about 1e-4 rad, which must not make corners (a concave one would be a place the
    jaw cannot touch in the middle of a smooth stretch); the one real corner stays."""
    a = np.linspace(0, 2 * np.pi, 7)[:-1]
    pts = np.c_[40 * np.cos(a), 30 * np.sin(a)]
    tan = np.c_[-40 * np.sin(a), 30 * np.cos(a)] * (2 * np.pi / 6) / 3
    tan[0] = 0.0  # a sharp point at the first: its controls lie on the chords
    d = [f"M {pts[0][0]:.3f} {pts[0][1]:.3f}"]
    for i in range(6):
        j = (i + 1) % 6
        # unequal arms on the two sides of a join (still tangent): their rounding errors differ
        c1 = pts[i] + (0.8 * tan[i] if i else (pts[j] - pts[i]) / 3)
        c2 = pts[j] - (1.1 * tan[j] if j else (pts[j] - pts[i]) / 3)
        d.append("C " + " ".join(f"{v:.3f}" for v in (*c1, *c2, *pts[j])))
    (tmp_path / "r.svg").write_text(f'<svg xmlns="http://www.w3.org/2000/svg"><path d="{" ".join(d)} Z"/></svg>')
    o = load_outline(tmp_path / "r.svg")
    assert len(o.corners) == 1 and o.corners[0].arc == 0.0 and o.corners[0].angle > 0.5


def test_part_files_that_are_not_parts_name_the_file(tmp_path):
    from localizer import load_part

    cases = {
        "binary.json": os.urandom(2000),
        "deep.json": ("[" * 100_000 + "]" * 100_000).encode(),
        "wide.csv": ("x,y\n1," + "9" * 200_000 + "\n").encode(),
    }
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
        with pytest.raises(PartError) as info:
            load_part(tmp_path / name)
        assert str(tmp_path / name) in str(info.value)
    huge = tmp_path / "huge.json"
    with open(huge, "wb") as f:  # sparse: 1 GB that takes no disk
        f.truncate(2**30)
    with pytest.raises(PartError, match="more than the 64 MB a part file may have"):
        load_part(huge)
    with pytest.raises(PartError, match="more than the 64 MB a CAD file may have"):
        huge.rename(tmp_path / "huge.dxf")
        load_outline(tmp_path / "huge.dxf")


CIRCLE_SVG = (
    '<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="100mm" viewBox="0 0 100 100">'
    "<!-- pièce --><{shape}/></svg>\n"
)


@pytest.mark.parametrize(
    "width, shape, match",
    [
        ("100mm", 'circle id="c" cx="50" cy="50" r="-20"', r"Circle c: r='-20' is negative"),
        ("100mm", 'ellipse id="e" cx="50" cy="50" rx="20" ry="-10"', r"Ellipse e: ry='-10' is negative"),
        ("100mm", 'rect id="r" x="10" y="10" width="-50" height="30"', r"Rect r: width='-50' is negative"),
        ("-100mm", 'circle id="c" cx="50" cy="50" r="20"', r"width='-100mm' of the drawing must be positive"),
    ],
)
def test_negative_svg_sizes_are_refused_by_name(tmp_path, width, shape, match):
    # SVG makes a negative size an error; the parser drew r="-20" as a circle of 20, width="-100mm" turned
    # the drawing inside out ("arc radius=-20.0 mm")
    f = tmp_path / "neg.svg"
    f.write_text(CIRCLE_SVG.format(w=width, shape=shape), encoding="utf-8")
    with pytest.raises(PartError, match=match):
        load_outline(f)


@pytest.mark.parametrize("encoding", ["ISO-8859-1", "UTF-16", "UTF-8"])
def test_an_svg_is_read_in_the_encoding_it_declares(tmp_path, encoding):
    body = CIRCLE_SVG.format(w="100mm", shape='circle id="c" cx="50" cy="50" r="20"')
    f = tmp_path / "c.svg"
    f.write_bytes((f'<?xml version="1.0" encoding="{encoding}"?>\n' + body).encode(encoding))
    assert load_outline(f).perimeter == pytest.approx(2 * math.pi * 20, rel=1e-12)
    f.write_bytes(body.encode("latin-1"))  # no declaration: UTF-8, which this is not
    with pytest.raises(PartError, match=r"not valid utf-8 \(invalid continuation byte at byte \d+\)"):
        load_outline(f)
    f.write_bytes(('<?xml version="1.0" encoding="x-nonsense"?>\n' + body).encode("latin-1"))
    with pytest.raises(PartError, match="declares encoding='x-nonsense', which Python does not know"):
        load_outline(f)


def test_a_negative_dxf_radius_names_the_file_and_the_entity(tmp_path):
    doc = ezdxf.new()
    doc.modelspace().add_circle((0, 0), -5)
    f = tmp_path / "neg.dxf"
    doc.saveas(f)
    with pytest.raises(PartError, match=r"neg\.dxf: CIRCLE \(handle \w+, layer '0'\): radius=-5\.0 must be positive"):
        load_outline(f)
