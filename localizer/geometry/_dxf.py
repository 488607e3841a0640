"""Reading a DXF drawing (ezdxf) as exact pieces: lines, arcs, bulged polylines, ellipses and splines,
in millimetres by the drawing's ``$INSUNITS``; what is not an outline is skipped and listed."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, cast

import numpy as np

from .._errors import PartError
from ._cad_loops import chain_loops, check_pieces
from ._pieces import CircularArc, CubicBezier, Line, Piece, as_points, elliptical_arc, trusted_lines

__all__ = ["DXF_UNITS", "DXF_NOTES", "read_dxf"]

#: DXF ``$INSUNITS`` codes and their size in mm (0, unitless, is taken as mm).
DXF_UNITS = {0: 1.0, 1: 25.4, 2: 304.8, 4: 1.0, 5: 10.0, 6: 1000.0, 13: 1e-3}


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


def read_dxf(path: Path, layer: str | None) -> tuple[list[list[Piece]], list[str]]:
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
        check_pieces(path, count)
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
    loops.extend(chain_loops(pieces, str(path), ignored))
    return loops, ignored


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
        # ezdxf keeps the vertices packed, a row (x, y, start width, end width, bulge) each (its
        # LWPolylinePoints, VERTEX_SIZE 5): read as one array, not as a tuple a vertex
        packed = e.lwpoints
        if getattr(packed, "VERTEX_SIZE", None) == 5 and hasattr(packed, "values"):
            rows = np.asarray(packed.values, dtype=float).reshape(-1, 5)
            xy, bulge = rows[:, :2] * k, rows[:, 4]
        else:  # another ezdxf's layout: its public reading
            xyb = np.array(e.get_points("xyb"), dtype=float).reshape(-1, 3)
            xy, bulge = xyb[:, :2] * k, xyb[:, 2]
    else:
        xy = np.array([(float(v.dxf.location[0]), float(v.dxf.location[1])) for v in e.vertices]).reshape(-1, 2) * k
        bulge = np.array([float(v.dxf.bulge) for v in e.vertices])
    n = len(xy)
    last = n if _closed(e, kind) else n - 1
    if last <= 0:
        return []
    verts = as_points(xy)
    ends = verts[1:] + verts[:1]
    straight = bool(np.all(np.abs(bulge[:last]) <= 1e-15))
    if straight and np.isfinite(xy).all() and min(map(math.dist, verts[:last], ends[:last])) > 1e-12:
        return list(trusted_lines(verts[:last], ends[:last]))  # what _line makes of each, its checks passed
    bulges = bulge.tolist()
    return [_bulge(verts[i], ends[i], bulges[i], f"{where}, vertex {i}") for i in range(last)]


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
