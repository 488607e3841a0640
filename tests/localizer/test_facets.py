"""Faceted drawings read as the curves they trace (issue 35): closed polylines of 100 to 200 000
vertices on circles, ellipses and a filleted plate, written as a DXF LWPOLYLINE, as loose LINEs and
as an SVG polygon, against the closed forms of the shapes they sample; drawings with true corners
faceted, against the drawing itself.

The rule (localizer.geometry._facets): a vertex between two segments that turns by at most 15° and whose
fillet passes within 0.05 mm of it is smooth and becomes the arc tangent to both segments reaching
halfway along the shorter; any other vertex is a corner. On a regular N-gon of circumradius r the
fillets are its inscribed circle, radius r·cos(π/N), exactly.
"""

import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from scipy.spatial import cKDTree
from scipy.special import ellipe

from localizer import (
    FACETS,
    ContactFilter,
    FacetRule,
    Line,
    PartError,
    load_outline,
    outline_from_pieces,
    outline_segments,
    read_facets,
)

PARTS = Path(__file__).resolve().parents[2] / "parts"


def circle(n, r=50.0):
    t = 2 * np.pi * np.arange(n) / n
    return np.c_[r * np.cos(t), r * np.sin(t)]


def ellipse(n, a=60.0, b=20.0):
    t = 2 * np.pi * np.arange(n) / n
    return np.c_[a * np.cos(t), b * np.sin(t)]


W, H, R = 80.0, 40.0, 6.0
PLATE = 2 * (W + H) - 8 * R + 2 * math.pi * R


def plate(n):
    """A W × H plate with fillets of radius R, each fillet drawn as (n − 4)/4 chords at equal angles
    (as CAD exports tessellate arcs), each edge as one segment."""
    k = max(2, (n - 4) // 4)
    out = []
    for i, (cx, cy) in enumerate([(W - R, R), (W - R, H - R), (R, H - R), (R, R)]):
        a = -np.pi / 2 + i * np.pi / 2 + (np.pi / 2) * np.arange(k + 1) / k
        out.append(np.c_[cx + R * np.cos(a), cy + R * np.sin(a)])
    return np.vstack(out)


def perimeter(pts):
    return float(np.sum(np.linalg.norm(np.diff(np.vstack([pts, pts[:1]]), axis=0), axis=1)))


def ezdxf_polyline_dxf(pts, path):
    """A drawing (mm) of one closed LWPOLYLINE through ``pts``, written by ezdxf."""
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    # the points appended to the entity's array: add_lwpolyline's own loop takes minutes at 200 000
    doc.modelspace().add_lwpolyline([], close=True).lwpoints.extend([(x, y, 0, 0, 0) for x, y in pts.tolist()])
    doc.saveas(path)
    return path


def vertex_tags(xy):
    """An LWPOLYLINE's vertices as ezdxf writes them: x (10) and y (20) each by ``str``, no width or
    bulge tags when they are zero."""
    return "".join(f" 10\n{x}\n 20\n{y}\n" for x, y in xy)


def polyline_dxf(pts, path):
    """The file :func:`ezdxf_polyline_dxf` writes, byte for byte (test_the_polyline_drawings_are_ezdxfs): ezdxf
    writes the drawing with the first vertex, and the others are spliced into its text after it, where
    ezdxf's own export takes a second and a half at 200 000 vertices."""
    xy = pts.tolist()
    one = ezdxf_polyline_dxf(pts[:1], path).read_text(encoding="utf-8")
    head = " 90\n1\n 70\n1\n" + vertex_tags(xy[:1])  # the vertex count, the closed flag, the vertex
    assert one.count(head) == 1
    path.write_text(one.replace(head, f" 90\n{len(xy)}\n 70\n1\n" + vertex_tags(xy)), encoding="utf-8")
    return path


def lines_dxf(pts, path, seed=0):
    """Every edge a loose LINE, in a shuffled order, half of them drawn backwards."""
    rng = np.random.default_rng(seed)
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    xy = pts.tolist()
    for i in rng.permutation(len(pts)):
        a, b = tuple(xy[i]), tuple(xy[(i + 1) % len(pts)])
        msp.add_line(*((b, a) if rng.random() < 0.5 else (a, b)))
    doc.saveas(path)
    return path


def polygon_svg(pts, path):
    points = " ".join(f"{x!r},{-y!r}" for x, y in pts.tolist())  # the reader flips y
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="-100 -100 200 200">'
        f'<polygon points="{points}"/></svg>'
    )
    return path


def tangent_jump(outline, delta=1e-6):
    """The largest turn of the tangent across a meeting of two pieces, less what the curvature on
    either side turns over ``delta`` mm, rad (zero on a curve without corners, up to rounding)."""
    at = outline.starts[1:-1]
    theta = outline.tangent_angle_at_arc(at + delta) - outline.tangent_angle_at_arc(at - delta)
    kappa = np.abs(outline.curvature_at_arc(at + delta)) + np.abs(outline.curvature_at_arc(at - delta))
    return float(np.max(np.abs(theta) - kappa * delta))


@pytest.mark.parametrize("n", [100, 1000, 20000, 200000])
def test_a_regular_polygon_reads_as_its_inscribed_circle(tmp_path, n):
    r = 50.0
    outline = load_outline(polyline_dxf(circle(n, r), tmp_path / "circle.dxf"))
    inner = r * math.cos(math.pi / n)
    assert outline.corners == ()
    assert outline.turning == pytest.approx(2 * math.pi, abs=1e-9)
    assert outline.perimeter == pytest.approx(2 * math.pi * inner, rel=1e-9)
    s = np.linspace(0.0, outline.perimeter, 5001)
    assert np.abs(np.hypot(*outline.point_at_arc(s).T) - inner).max() < 1e-9
    # each fillet's radius from its vertex's turn: the drawing's coordinates (to 1e-12 mm or so) over a
    # facet of 1.6 µm at 200 000 vertices
    assert np.abs(outline.curvature_at_arc(s) * inner - 1.0).max() < 1e-6
    polygon = 2 * n * r * math.sin(math.pi / n)
    if n >= 2000:  # dense: the target
        assert abs(outline.perimeter - polygon) <= 1e-6 * polygon


@pytest.mark.parametrize("n", [100, 2000, 20000, 200000])
def test_a_faceted_ellipse_has_no_corner_and_the_ellipse_perimeter_to_the_facets_own_error(tmp_path, n):
    a, b = 60.0, 20.0
    pts = ellipse(n, a, b)
    outline = load_outline(polyline_dxf(pts, tmp_path / "ellipse.dxf"))
    exact = 4 * a * ellipe(1 - (b / a) ** 2)
    polygon = perimeter(pts)
    assert outline.corners == ()
    assert outline.turning == pytest.approx(2 * math.pi, abs=1e-9)
    # the polygon falls short of the ellipse by its chords' sagittas; the fillets cut the vertices by
    # as much again, twice: three times the polygon's own error, and the straight bits of under a
    # nanometre left between two fillets and dropped (1e-8 of the perimeter at 200 000 vertices)
    assert abs(outline.perimeter - exact) <= 3.0 * (exact - polygon) + 2e-8 * exact
    if n >= 2000:
        assert abs(outline.perimeter - polygon) <= 1e-6 * polygon
    if n <= 20000:
        assert tangent_jump(outline) < 1e-8  # each fillet's turn from its vertex's coordinates
        # each of 200 vertices' distance to the nearest of the outline's points every micrometre
        gaps, _ = cKDTree(outline.point_at_arc(np.arange(0.0, outline.perimeter, 0.001))).query(
            pts[:: max(1, n // 200)]
        )
        assert gaps.max() <= FACETS.chord_tolerance


@pytest.mark.parametrize("n", [100, 20000, 200000])
def test_a_plate_with_faceted_fillets_keeps_its_edges_and_has_no_corner(tmp_path, n):
    pts = plate(n)
    outline = load_outline(polyline_dxf(pts, tmp_path / "plate.dxf"))
    assert outline.corners == ()
    assert abs(outline.perimeter - PLATE) <= 3.0 * (PLATE - perimeter(pts)) + 2e-8 * PLATE
    faces = sorted(length for _, length in outline.faces if length > 1.0)
    k = max(2, (n - 4) // 4)
    facet = 2 * R * math.sin(math.pi / 4 / k)
    # each edge loses half a facet at each end to its end fillets, no more
    assert faces == pytest.approx([H - 2 * R - facet] * 2 + [W - 2 * R - facet] * 2, abs=1e-9)


def test_the_same_polygon_as_loose_lines_or_an_svg_polygon_reads_the_same(tmp_path):
    pts = ellipse(20000)
    ref = load_outline(polyline_dxf(pts, tmp_path / "e.dxf"))
    lines = load_outline(lines_dxf(pts, tmp_path / "lines.dxf"))
    assert lines.corners == () and lines.perimeter == pytest.approx(ref.perimeter, rel=1e-12)
    svg = load_outline(polygon_svg(ellipse(5000), tmp_path / "e.svg"))
    assert svg.corners == ()
    exact = 4 * 60.0 * ellipe(1 - (20.0 / 60.0) ** 2)
    assert abs(svg.perimeter - exact) <= 3.0 * (exact - perimeter(ellipse(5000))) + 2e-8 * exact


def test_the_polyline_drawings_are_ezdxfs(tmp_path, monkeypatch):
    """polyline_dxf writes what ezdxf writes for the same points, byte for byte (with ezdxf's option for
    comparing files: the same date and ids in every file), and ezdxf reads the points back exactly."""
    monkeypatch.setattr(ezdxf.options, "write_fixed_meta_data_for_testing", True)
    odd = np.array([[0.0, -0.0], [1e-300, 5e-324], [1e16, -1e16], [123456789.123456789, 1 / 3], [-2.5e-7, 7e15]])
    for pts in (circle(7), ellipse(9), plate(12), facet(load_outline(PARTS / "bracket.dxf"), 5.0), odd, odd[:1]):
        mine = polyline_dxf(pts, tmp_path / "mine.dxf").read_bytes()
        assert mine == ezdxf_polyline_dxf(pts, tmp_path / "ezdxf.dxf").read_bytes()
        back = ezdxf.readfile(tmp_path / "mine.dxf").modelspace().query("LWPOLYLINE")[0]
        assert back.closed and back.get_points("xyseb") == [(x, y, 0.0, 0.0, 0.0) for x, y in pts.tolist()]


def facet(outline, h):
    """The vertices of a polyline through ``outline``: every piece's start, and curved pieces every
    ``h`` mm or less (as a CAD export writes them)."""
    out = []
    for start, piece in zip(outline.starts[:-1], outline.pieces):
        m = 1 if isinstance(piece, Line) else max(2, math.ceil(piece.length / h))
        out.append(outline.point_at_arc(start + piece.length * np.arange(m) / m))
    return np.vstack(out)


@pytest.fixture(scope="module", params=["bracket.dxf", "profile.svg"])
def drawing(request):
    return load_outline(PARTS / request.param)


@pytest.mark.parametrize("h", [0.05, 0.5])
def test_a_faceted_drawing_has_exactly_the_drawings_corners(tmp_path, drawing, h):
    faceted = load_outline(polyline_dxf(facet(drawing, h), tmp_path / "f.dxf"))
    assert len(faceted.corners) == len(drawing.corners)
    here = faceted.point_at_arc([c.arc for c in faceted.corners])
    there = drawing.point_at_arc([c.arc for c in drawing.corners])
    assert np.abs(here - there).max() < 1e-9  # the same points of the drawing
    # each corner turns as drawn, plus half a facet's turn where a curve meets it
    worst_facet = h * max(float(np.abs(drawing.curvature_at_arc(np.arange(0, drawing.perimeter, 0.01))).max()), 0)
    assert [c.angle for c in faceted.corners] == pytest.approx([c.angle for c in drawing.corners], abs=worst_facet)


def test_the_solutions_on_a_faceted_drawing_are_those_on_the_drawing(tmp_path, drawing):
    """Every (L, Ω) from the drawing has the same solutions on the drawing faceted every 0.05 mm, within
    a facet (where an end of the roll is where a curve meets a straight edge, the faceted curve
    starts turning up to half a facet sooner, and the solution moves by as much)."""
    faceted = load_outline(polyline_dxf(facet(drawing, 0.05), tmp_path / "f.dxf"))
    rng = np.random.default_rng(3)
    for _ in range(6):
        s, length = rng.uniform(0, drawing.perimeter), rng.uniform(5.0, 40.0)
        turn = float(drawing.tangent_angle_at_arc(s + length) - drawing.tangent_angle_at_arc(s))
        here = faceted.point_at_arc([g.start_arc for g in outline_segments(faceted, length, turn)])
        there = drawing.point_at_arc([g.start_arc for g in outline_segments(drawing, length, turn)])
        assert len(here) == len(there)
        gap = np.hypot(*(here[:, None] - there[None]).transpose(2, 0, 1))
        assert gap.min(axis=0).max() < 0.05 and gap.min(axis=1).max() < 0.05


def test_the_filter_on_a_faceted_drawing_finds_the_contact_as_on_the_drawing(tmp_path):
    """Fed a noise-free roll over the profile's long Bézier (the travel from a dense sample of the
    drawing), the sequential filter is as sure on the profile faceted every 0.05 mm as on the
    profile, at the same place within a facet."""
    drawing = load_outline(PARTS / "profile.svg")
    faceted = load_outline(polyline_dxf(facet(drawing, 0.05), tmp_path / "f.dxf"))
    # a roll over a curve of the drawing: the contact's travel from a dense sample of the drawing
    curved = [
        (a, p.length) for a, p in zip(drawing.starts, drawing.pieces) if not isinstance(p, Line) and p.length > 12
    ]
    start = curved[0][0] + 2.0
    ahead = np.arange(start, start + curved[0][1] - 4.0, 0.002)
    theta = drawing.tangent_angle_at_arc(ahead)
    step = math.radians(0.2)

    def verdict(outline):
        flt = ContactFilter(outline, sd_position=0.01)
        for k in range(1, 600):
            j = int(np.argmax(theta >= theta[0] + k * step))
            if j == 0:
                break
            flt.update(float(ahead[j] - start), k * step)
            belief = flt.belief()
            if belief.mass >= 0.95:
                break
        return belief.mass, outline.point_at_arc(belief.map_arc), drawing.point_at_arc(ahead[j])

    mass0, at0, truth = verdict(drawing)
    mass1, at1, _ = verdict(faceted)
    assert mass0 >= 0.95 and mass1 >= 0.95
    assert math.dist(at0, truth) < 0.05 and math.dist(at1, truth) < 0.05


def test_the_rule_a_small_bend_between_short_segments_is_smooth_a_long_one_a_corner():
    def bend(edge, degrees):
        d = math.radians(degrees)
        b = (edge, 0.0)
        c = (edge + edge * math.cos(d), edge * math.sin(d))
        return [Line((0.0, 0.0), b), Line(b, c), Line(c, (0.0, 60.0)), Line((0.0, 60.0), (0.0, 0.0))]

    # 1° between 2 mm segments: the fillet (radius 115 mm) passes 0.004 mm from the vertex
    assert len(outline_from_pieces(read_facets(bend(2.0, 1.0))).corners) == 3
    # 3° between 20 mm segments: 0.13 mm away, beyond the chord tolerance: a corner
    assert len(outline_from_pieces(read_facets(bend(20.0, 3.0))).corners) == 4
    # 20° between 0.5 mm segments: within the chord tolerance but past the corner angle
    assert len(outline_from_pieces(read_facets(bend(0.5, 20.0))).corners) == 4
    hexagon = [Line(tuple(p), tuple(q)) for p, q in zip(circle(6), np.roll(circle(6), -1, axis=0))]
    assert read_facets(hexagon) == hexagon
    with pytest.raises(PartError):
        FacetRule(corner_angle=math.pi)
    with pytest.raises(PartError):
        FacetRule(chord_tolerance=-1.0)


def test_as_drawn_is_still_there(tmp_path):
    """``facets=None`` reads every vertex that turns by more than 1e-3 rad as a corner."""
    outline = load_outline(polyline_dxf(circle(100), tmp_path / "c.dxf"), facets=None)
    assert len(outline.corners) == 100
