"""Reading an SVG drawing (svgelements) as exact pieces: paths, rectangles, circles and ellipses, in
millimetres by the document's size and viewBox, y flipped up; what is not an outline is skipped and listed."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

from .._errors import PartError
from ._cad_loops import chain_loops, check_pieces
from ._outline import JOIN_TOL
from ._pieces import CircularArc, CubicBezier, Line, Piece, elliptical_arc

__all__ = ["SVG_UNITS", "read_svg"]

#: SVG length units in mm.
SVG_UNITS = {"mm": 1.0, "cm": 10.0, "in": 25.4, "pt": 25.4 / 72.0, "pc": 25.4 / 6.0, "px": 25.4 / 96.0, "": None}


_NUMBER = re.compile(r"\d+(?:\.\d*)?|\.\d+")


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


def read_svg(path: Path, element: str | None) -> tuple[list[list[Piece]], list[str]]:
    try:
        import svgelements as se
    except ImportError:  # pragma: no cover - a dependency of the package
        raise PartError("reading SVG needs svgelements: pip install svgelements") from None
    text = _svg_text(path)
    # the parser builds every segment before one can be counted (a 50 MB path: 70 s, 1.5 GB): a segment
    # takes at most 7 numbers (an arc), so more numbers than 7 pieces' worth is surely too many pieces
    check_pieces(path, len(_NUMBER.findall(text)) // 7)
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
            check_pieces(path, count)
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
    loops.extend(chain_loops(loose, str(path), ignored))
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
