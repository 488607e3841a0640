"""Outlines read from CAD files: DXF (ezdxf) and SVG (svgelements), as exact pieces.

Conventions (docs/cad.md): millimetres; y up (an SVG's y axis points down and is flipped, so the
part is not mirrored); the outline is the outer closed loop, the one of largest area, unless a DXF
layer or an SVG element id is named; the first point is the first vertex of the DXF entity or the
first ``M`` of the SVG path the loop starts with. Everything else in the file (holes, text,
dimensions, other layers) is ignored and listed in :attr:`localizer.Outline.ignored`.

The readers are imported only when a CAD file is read: ``import localizer`` needs neither.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, cast

import numpy as np

from .._errors import PartError
from ._facets import FACETS, FacetRule, read_facets
from ._limits import MAX_PART_BYTES, MAX_PIECES, check_size, count_text
from ._outline import JOIN_TOL, Outline, outline_from_pieces
from ._pieces import CircularArc, CubicBezier, Line, Piece, elliptical_arc

__all__ = ["load_outline", "CAD_SUFFIXES"]

#: File suffixes read as CAD outlines.
CAD_SUFFIXES = (".dxf", ".svg")
#: DXF ``$INSUNITS`` codes and their size in mm (0, unitless, is taken as mm).
DXF_UNITS = {0: 1.0, 1: 25.4, 2: 304.8, 4: 1.0, 5: 10.0, 6: 1000.0, 13: 1e-3}
#: SVG length units in mm.
SVG_UNITS = {"mm": 1.0, "cm": 10.0, "in": 25.4, "pt": 25.4 / 72.0, "pc": 25.4 / 6.0, "px": 25.4 / 96.0, "": None}
#: DXF entities that are not part of an outline: skipped and reported.
DXF_NOTES = {
    "TEXT",
    "MTEXT",
    "DIMENSION",
    "HATCH",
    "INSERT",
    "POINT",
    "LEADER",
    "MLEADER",
    "ATTDEF",
    "SOLID",
    "VIEWPORT",
}


def load_outline(
    path: str | Path, *, layer: str | None = None, element: str | None = None, facets: FacetRule | None = FACETS
) -> Outline:
    """The outline of the CAD file at ``path`` (``.dxf`` or ``.svg``), in mm, counter-clockwise.

    Parameters
    ----------
    path : str or Path
    layer : str, optional
        DXF only: read the outline from this layer (default: every layer).
    element : str, optional
        SVG only: read the outline from the element with this id (default: every path and shape).
    facets : FacetRule or None
        Which vertices between straight segments are smooth, read as the curve the segments trace
        (:func:`localizer.read_facets`); None: every vertex that turns by more than 1e-3 rad is a
        corner, as drawn.

    Raises
    ------
    PartError
        Unreadable file, unknown units, an entity kind that cannot be read exactly (named), a
        zero-length piece, no closed loop, several largest loops of equal area, a loop that
        crosses itself.
    """
    path = Path(path)
    check_size(path, MAX_PART_BYTES, "CAD file")
    suffix = path.suffix.lower()
    if suffix == ".dxf":
        if element is not None:
            raise PartError(f"{path}: element={element!r} is for SVG files; a DXF names a layer")
        loops, ignored = _read_dxf(path, layer)
    elif suffix == ".svg":
        if layer is not None:
            raise PartError(f"{path}: layer={layer!r} is for DXF files; an SVG names an element id")
        loops, ignored = _read_svg(path, element)
    else:
        raise PartError(f"{path}: not a CAD file (use one of {list(CAD_SUFFIXES)})")
    chosen, rest = _outer(loops, str(path))
    if rest:
        ignored.append(f"{rest} other closed loop(s) (holes or other outlines)")
    if facets is not None:
        chosen = read_facets(chosen, facets)
    outline = outline_from_pieces(chosen, name=path.stem)
    return Outline(outline.pieces, outline.name, ignored=tuple(ignored))


# ------------------------------------------------------------------ DXF
def _read_dxf(path: Path, layer: str | None) -> tuple[list[list[Piece]], list[str]]:
    try:
        from ezdxf.filemanagement import readfile
        from ezdxf.lldxf.const import DXFError
    except ImportError:  # pragma: no cover - a dependency of the package
        raise PartError("reading DXF needs ezdxf: pip install ezdxf") from None
    try:
        doc = readfile(str(path))
    except (OSError, DXFError) as exc:
        raise PartError(f"{path}: cannot read the DXF file ({exc})") from None
    code = int(doc.header.get("$INSUNITS", 0))
    if code not in DXF_UNITS:
        raise PartError(f"{path}: $INSUNITS={code} is not a length unit rolltouch reads (use mm, cm, m, in, ft or µm)")
    k = DXF_UNITS[code]
    msp = doc.modelspace()
    layers = {e.dxf.layer for e in msp}
    if layer is not None and layer not in layers:
        raise PartError(f"{path}: no entity on layer {layer!r}; layers: {sorted(layers)}")
    pieces: list[Piece] = []
    loops: list[list[Piece]] = []
    ignored: list[str] = []
    count = 0  # pieces so far, an entity counted before it is built
    for e in msp:
        kind = e.dxftype()
        count += len(cast(Any, e)) if kind in ("LWPOLYLINE", "POLYLINE") else 1
        _check_pieces(path, count)
        if layer is not None and e.dxf.layer != layer:
            ignored.append(f"{kind} on layer {e.dxf.layer!r}")
            continue
        if kind in DXF_NOTES:
            ignored.append(f"{kind} on layer {e.dxf.layer!r}")
            continue
        where = f"{path}: {kind} (handle {e.dxf.handle}, layer {e.dxf.layer!r})"
        if kind == "LINE":
            pieces.append(_line(_pt(e.dxf.start, k), _pt(e.dxf.end, k), where))
        elif kind in ("ARC", "CIRCLE") and not float(e.dxf.radius) > 0:
            raise PartError(f"{where}: radius={float(e.dxf.radius)!r} must be positive")
        elif kind == "ARC":
            sweep = (float(e.dxf.end_angle) - float(e.dxf.start_angle)) % 360.0 or 360.0
            pieces.append(
                CircularArc(
                    _pt(e.dxf.center, k), float(e.dxf.radius) * k, math.radians(e.dxf.start_angle), math.radians(sweep)
                )
            )
        elif kind == "CIRCLE":
            loops.append([CircularArc(_pt(e.dxf.center, k), float(e.dxf.radius) * k, 0.0, 2.0 * math.pi)])
        elif kind in ("LWPOLYLINE", "POLYLINE"):
            chain = _polyline(e, kind, k, where)
            if _closed(e, kind):
                loops.append(chain)
            else:
                pieces.extend(chain)
        elif kind == "SPLINE":
            pieces.extend(_spline(e, k, where))
        elif kind == "ELLIPSE" and abs(float(e.dxf.ratio) - 1.0) > 1e-12:
            # the minor axis follows the extrusion, and t runs counter-clockwise about it
            ce = cast(Any, e).construction_tool()
            t0, t1 = float(ce.start_param), float(ce.end_param)
            t1 = t0 + ((t1 - t0) % (2 * math.pi) or 2 * math.pi)
            arcs = elliptical_arc(_pt(ce.center, k), _pt(ce.major_axis, k), _pt(ce.minor_axis, k), t0, t1)
            if t1 - t0 >= 2 * math.pi - 1e-12:
                loops.append(list(arcs))
            else:
                pieces.extend(arcs)
        elif kind == "ELLIPSE":
            c, major = e.dxf.center, e.dxf.major_axis
            r = math.hypot(major.x, major.y) * k
            a0 = math.atan2(major.y, major.x) + float(e.dxf.start_param)
            sweep = (float(e.dxf.end_param) - float(e.dxf.start_param)) % (2 * math.pi) or 2 * math.pi
            arc = CircularArc(_pt(c, k), r, a0, sweep)
            if sweep >= 2 * math.pi - 1e-12:
                loops.append([arc])
            else:
                pieces.append(arc)
        else:
            raise PartError(
                f"{where}: cannot be read exactly; rolltouch reads LINE, ARC, CIRCLE, ELLIPSE, LWPOLYLINE,"
                " POLYLINE and SPLINE outlines"
            )
    loops.extend(_chain(pieces, str(path), ignored))
    return loops, ignored


_NUMBER = re.compile(r"\d+(?:\.\d*)?|\.\d+")


def _check_pieces(path: Path, count: int) -> None:
    """Refuse a drawing of more than :data:`MAX_PIECES` pieces, before building the one past it."""
    if count > MAX_PIECES:
        raise PartError(
            f"{path}: more than {count_text(MAX_PIECES)} pieces (line segments, arcs, curves) in the drawing, more "
            "than an outline may have: export its curves with a coarser chord tolerance, or as arcs and splines"
        )


def _pt(v: Any, k: float) -> tuple[float, float]:
    return float(v[0]) * k, float(v[1]) * k


def _line(a: tuple[float, float], b: tuple[float, float], where: str) -> Line:
    if math.dist(a, b) <= 1e-12:
        raise PartError(f"{where}: a piece of zero length at ({a[0]:.6g}, {a[1]:.6g}) mm; remove the repeated point")
    return Line(a, b)


def _bulge(a: tuple[float, float], b: tuple[float, float], bulge: float, where: str) -> Piece:
    """The piece from a to b with DXF ``bulge`` (tan of a quarter of the included angle; > 0 counter-clockwise)."""
    if abs(bulge) <= 1e-15:
        return _line(a, b, where)
    chord = math.dist(a, b)
    if chord <= 1e-12:
        raise PartError(f"{where}: an arc of zero chord at ({a[0]:.6g}, {a[1]:.6g}) mm")
    theta = 4.0 * math.atan(bulge)
    radius = chord / (2.0 * abs(math.sin(theta / 2.0)))
    h = (chord / 2.0) / math.tan(theta / 2.0)  # from the chord's midpoint to the centre, to its left
    mx, my = (a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0
    nx, ny = -(b[1] - a[1]) / chord, (b[0] - a[0]) / chord
    cx, cy = mx + h * nx, my + h * ny
    return CircularArc((cx, cy), radius, math.atan2(a[1] - cy, a[0] - cx), theta)


def _closed(e: Any, kind: str) -> bool:
    return bool(e.closed) if kind == "LWPOLYLINE" else bool(e.is_closed)


def _polyline(e: Any, kind: str, k: float, where: str) -> list[Piece]:
    if kind == "LWPOLYLINE":
        verts = [(float(x) * k, float(y) * k, float(b)) for x, y, b in e.get_points("xyb")]
    else:
        verts = [(float(v.dxf.location[0]) * k, float(v.dxf.location[1]) * k, float(v.dxf.bulge)) for v in e.vertices]
    n = len(verts)
    last = n if _closed(e, kind) else n - 1
    return [_bulge(verts[i][:2], verts[(i + 1) % n][:2], verts[i][2], f"{where}, vertex {i}") for i in range(last)]


def _spline(e: Any, k: float, where: str) -> list[Piece]:
    """A SPLINE's Bézier pieces. A rational one (NURBS weights) is split as the polynomial B-spline of
    its homogeneous points (w·x, w·y, w), whose Béziers are the rational pieces' homogeneous points."""
    from ezdxf.math import BSpline, Vec3

    bs = e.construction_tool()
    rational = bool(bs.is_rational)
    degree = int(bs.degree)
    if degree not in (1, 2, 3):
        raise PartError(f"{where}: a SPLINE of degree {degree}; rolltouch reads degrees 1 to 3")
    if rational:
        w = [float(v) for v in bs.weights()]
        if not all(math.isfinite(v) and v > 0 for v in w):
            raise PartError(f"{where}: NURBS weights {w} must be positive")
        cps = [Vec3(float(p.x) * v, float(p.y) * v, v) for p, v in zip(bs.control_points, w, strict=True)]
        bs = BSpline(cps, order=degree + 1, knots=bs.knots())
    try:
        parts = list(bs.bezier_decomposition())
    except Exception as exc:  # ezdxf refuses splines it cannot split (e.g. unclamped)
        raise PartError(f"{where}: cannot split the SPLINE into Bézier pieces ({exc})") from None
    out: list[Piece] = []
    for cps in parts:
        h = np.array([[float(c.x), float(c.y), float(c.z) if rational else 1.0] for c in cps])
        p = [_pt(q[:2] / q[2], k) for q in h]
        if degree == 1:
            out.append(_line(p[0], p[1], where))
        elif not rational and degree == 2:
            out.append(CubicBezier.from_quadratic(p[0], p[1], p[2]))
        elif not rational:
            out.append(CubicBezier(p[0], p[1], p[2], p[3]))
        else:
            if degree == 2:  # degree elevation of the homogeneous points
                h = np.array([h[0], (h[0] + 2 * h[1]) / 3, (2 * h[1] + h[2]) / 3, h[2]])
                p = [_pt(q[:2] / q[2], k) for q in h]
            out.append(CubicBezier(p[0], p[1], p[2], p[3], (h[0, 2], h[1, 2], h[2, 2], h[3, 2])))
    return out


# ------------------------------------------------------------------ SVG
def _svg_scale(text: str, path: Path) -> tuple[float, tuple[float, float], str]:
    """mm per user unit from the root's width and viewBox, the viewBox's origin (user units: the
    parser moves it to 0, 0 and it is put back), and the text with the root's width and height
    removed (so the parser maps the viewBox one to one)."""
    m = re.search(r"<svg\b[^>]*>", text)
    if m is None:
        raise PartError(f"{path}: no <svg> element")
    root = m.group(0)

    def attr(name: str) -> str | None:
        a = re.search(rf'\s{name}\s*=\s*["\']([^"\']*)["\']', root)
        return a.group(1).strip() if a else None

    width, box = attr("width"), attr("viewBox")
    scale = 1.0  # user unit = 1 mm without a physical size
    origin = (0.0, 0.0)
    if box is not None:
        vb = [float(v) for v in re.split(r"[\s,]+", box) if v]
        if len(vb) != 4 or vb[2] <= 0 or vb[3] <= 0:
            raise PartError(f"{path}: viewBox={box!r} is not 'min-x min-y width height'")
        origin = (vb[0], vb[1])
    if width is not None and not width.endswith("%"):
        w = re.fullmatch(r"([0-9.eE+-]+)\s*([a-z]*)", width)
        if w is None or w.group(2) not in SVG_UNITS:
            raise PartError(f"{path}: width={width!r}: use a number with mm, cm, in, pt, pc or px")
        unit = SVG_UNITS[w.group(2)]
        if not float(w.group(1)) > 0:
            raise PartError(f"{path}: width={width!r} of the drawing must be positive")
        if unit is not None:
            width_mm = float(w.group(1)) * unit
            # a physical size without a viewBox: user units are CSS px
            scale = width_mm / vb[2] if box is not None else 25.4 / 96.0
    stripped = root
    for name in ("width", "height"):
        stripped = re.sub(rf'\s{name}\s*=\s*["\'][^"\']*["\']', "", stripped)
    return scale, origin, text.replace(root, stripped, 1)


def _svg_text(path: Path) -> str:
    """The SVG file's text, in the encoding it declares (a byte-order mark, or the XML declaration's
    ``encoding``; UTF-8 without either, as XML says), the declaration's encoding then dropped: the text
    is parsed as text."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise PartError(f"{path}: cannot read the SVG file ({exc.strerror or exc})") from None
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        encoding = "utf-16"
    elif raw.startswith(b"\xef\xbb\xbf"):
        encoding = "utf-8-sig"
    else:
        declared = re.match(rb"""\s*<\?xml[^>]*\bencoding\s*=\s*["']([A-Za-z0-9._-]+)["']""", raw)
        encoding = declared.group(1).decode("ascii") if declared else "utf-8"
    try:
        text = raw.decode(encoding)
    except LookupError:
        raise PartError(f"{path}: the SVG declares encoding={encoding!r}, which Python does not know") from None
    except UnicodeDecodeError as exc:
        raise PartError(f"{path}: the SVG is not valid {encoding} ({exc.reason} at byte {exc.start})") from None
    return re.sub(r"""^(\s*<\?xml[^>]*?)\s+encoding\s*=\s*["'][^"']*["']""", r"\1", text, count=1)


def _read_svg(path: Path, element: str | None) -> tuple[list[list[Piece]], list[str]]:
    try:
        import svgelements as se
    except ImportError:  # pragma: no cover - a dependency of the package
        raise PartError("reading SVG needs svgelements: pip install svgelements") from None
    text = _svg_text(path)
    # the parser builds every segment before one can be counted (a 50 MB path: 70 s, 1.5 GB): a segment
    # takes at most 7 numbers (an arc), so more numbers than 7 pieces' worth is surely too many pieces
    _check_pieces(path, len(_NUMBER.findall(text)) // 7)
    k, origin, text = _svg_scale(text, path)

    def pt(p: Any) -> tuple[float, float]:
        """A parsed point in mm, y up, in the drawing's own user coordinates."""
        return (float(p[0]) + origin[0]) * k, -(float(p[1]) + origin[1]) * k

    import io

    try:
        doc = se.SVG.parse(io.StringIO(text))
    except Exception as exc:  # the parser raises many kinds on malformed XML
        raise PartError(f"{path}: cannot parse the SVG ({exc})") from None
    shapes = [e for e in doc.elements() if isinstance(e, se.Shape)]
    ids = {e.id for e in shapes if e.id}
    if element is not None and element not in ids:
        raise PartError(f"{path}: no path or shape with id {element!r}; ids: {sorted(ids)}")
    loops: list[list[Piece]] = []
    loose: list[Piece] = []
    count = 0  # segments so far
    ignored: list[str] = [f"{type(e).__name__} element" for e in doc.elements() if isinstance(e, se.Text)]
    for shape in shapes:
        if element is not None and shape.id != element:
            ignored.append(f"{type(shape).__name__} {shape.id or '(no id)'}")
            continue
        where = f"{path}: {type(shape).__name__} {shape.id or '(no id)'}"
        _check_svg_sizes(shape, se, where)
        current: list[Piece] = []
        for seg in se.Path(shape).segments():
            count += 1
            _check_pieces(path, count)
            if isinstance(seg, se.Move):
                loose.extend(current)
                current = []
                continue
            if isinstance(seg, (se.Close, se.Line)):
                a, b = pt(seg.start), pt(seg.end)
                if math.dist(a, b) <= 1e-12:
                    if isinstance(seg, se.Close):
                        if current:
                            loops.append(current)
                        current = []
                        continue
                    raise PartError(f"{where}: a line of zero length at ({a[0]:.6g}, {a[1]:.6g}) mm")
                current.append(Line(a, b))
                if isinstance(seg, se.Close):
                    loops.append(current)
                    current = []
            elif isinstance(seg, se.CubicBezier):
                current.append(CubicBezier(pt(seg.start), pt(seg.control1), pt(seg.control2), pt(seg.end)))
            elif isinstance(seg, se.QuadraticBezier):
                p0, p1, p2 = (pt(q) for q in (seg.start, seg.control, seg.end))
                current.append(CubicBezier.from_quadratic(p0, p1, p2))
            elif isinstance(seg, se.Arc):
                if abs(float(seg.rx) - float(seg.ry)) > 1e-9 * max(float(seg.rx), float(seg.ry)):
                    current.extend(_svg_ellipse(seg, pt, where))
                    continue
                cx, cy = pt(seg.center)
                sx, sy = pt(seg.start)
                # y flipped: angles and the sense of the sweep change sign
                current.append(
                    CircularArc((cx, cy), float(seg.rx) * k, math.atan2(sy - cy, sx - cx), -float(seg.sweep))
                )
            else:
                raise PartError(f"{where}: a {type(seg).__name__} segment cannot be read")
        if current:
            if math.dist(current[0].start, current[-1].end) <= JOIN_TOL:
                loops.append(current)
            else:
                loose.extend(current)
    loops.extend(_chain(loose, str(path), ignored))
    return loops, ignored


def _check_svg_sizes(shape: Any, se: Any, where: str) -> None:
    """Refuse a circle's, an ellipse's or a rectangle's negative size (an error in SVG: the parser would
    draw it as if positive, or turn the outline inside out)."""
    sizes = {se.Circle: ("r", "rx", "ry"), se.Ellipse: ("rx", "ry"), se.Rect: ("width", "height", "rx", "ry")}
    names = next((n for kind, n in sizes.items() if isinstance(shape, kind)), ())
    for name in names:
        given = shape.values.get(name)
        try:
            negative = given is not None and float(re.sub(r"[a-z%]+$", "", str(given).strip())) < 0
        except ValueError:
            continue
        if negative:
            raise PartError(f"{where}: {name}={given!r} is negative; a size in SVG is positive")


# ------------------------------------------------------------------ loops
def _svg_ellipse(seg: Any, pt: Any, where: str) -> list[CubicBezier]:
    """An SVG elliptical arc (after its transforms) as rational Béziers in the part's frame: the
    conic's control points mapped by the same affine map as every other point (``pt``: units, y up),
    which keeps a rational Bézier exact."""
    rot = float(seg.get_rotation())
    a, b = float(seg.rx), float(seg.ry)
    cx, cy = float(seg.center.x), float(seg.center.y)
    u = (a * math.cos(rot), a * math.sin(rot))
    v = (-b * math.sin(rot), b * math.cos(rot))
    t0 = float(seg.get_start_t())
    t1 = float(seg.get_end_t())
    sweep = float(seg.sweep)
    dt = (t1 - t0) % (2 * math.pi) if sweep > 0 else -((t0 - t1) % (2 * math.pi))
    arcs = elliptical_arc((cx, cy), u, v, t0, t0 + dt)
    size = max(a, b)
    for q, want in ((arcs[0].p0, seg.start), (arcs[-1].p3, seg.end)):
        if math.dist(q, (float(want.x), float(want.y))) > 1e-7 * max(1.0, size):
            raise PartError(f"{where}: an elliptical arc whose axes are not perpendicular (a skewed transform)")
    # the control points through the same map as every other point (units, y flipped)
    return [CubicBezier(pt(q.p0), pt(q.p1), pt(q.p2), pt(q.p3), q.weights) for q in arcs]


def _chain(pieces: list[Piece], source: str, ignored: list[str]) -> list[list[Piece]]:
    """Loose pieces chained end to start (reversing pieces where needed) into closed loops; what
    does not close is reported in ``ignored``.

    A loop starts at the first unused piece; at each end the next piece is the first unused one in
    the file's order with an end within :data:`JOIN_TOL` (its start preferred), found among the
    ends' neighbours (scipy's k-d tree) so that 200 000 loose LINEs chain in about a second.
    """
    from scipy.spatial import cKDTree

    n = len(pieces)
    if n == 0:
        return []
    ends = np.array([p.start for p in pieces] + [p.end for p in pieces])  # start of i: i; end of i: n + i
    near = cKDTree(ends).query_ball_point(ends, JOIN_TOL)
    used = np.zeros(n, dtype=bool)
    loops: list[list[Piece]] = []
    first = 0
    while True:
        while first < n and used[first]:
            first += 1
        if first == n:
            return loops
        used[first] = True
        loop, at = [pieces[first]], n + first  # the endpoint the loop has reached
        while math.dist(loop[-1].end, loop[0].start) > JOIN_TOL:
            # the first unused piece with an end here; its start before its end
            options = sorted((e % n, e >= n) for e in near[at] if not used[e % n])
            if not options:
                ignored.append(f"an open chain of {len(loop)} piece(s) from {loop[0].start} to {loop[-1].end}")
                loop = []
                break
            i, reverse = options[0]
            used[i] = True
            loop.append(pieces[i].reversed() if reverse else pieces[i])
            at = i if reverse else n + i
        if loop:
            loops.append(loop)


def _area(loop: list[Piece]) -> float:
    pts = np.concatenate(
        [p.point(np.linspace(0.0, p.length, 65)[:-1]) if not isinstance(p, Line) else [p.start] for p in loop]
    )
    x, y = pts[:, 0], pts[:, 1]
    return float(0.5 * abs(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))


def _outer(loops: list[list[Piece]], source: str) -> tuple[list[Piece], int]:
    """The loop of largest area, and how many others there were."""
    if not loops:
        raise PartError(f"{source}: no closed loop (the outline's pieces do not meet end to start)")
    areas = np.array([_area(loop) for loop in loops])
    order = np.argsort(-areas)
    if len(loops) > 1 and areas[order[1]] >= areas[order[0]] * (1.0 - 1e-9):
        raise PartError(
            f"{source}: {int(np.sum(areas >= areas[order[0]] * (1 - 1e-9)))} loops of equal area "
            f"{areas[order[0]]:.6g} mm²: name the layer (DXF) or the element id (SVG)"
        )
    return loops[int(order[0])], len(loops) - 1
