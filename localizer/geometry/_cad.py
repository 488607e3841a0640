"""Outlines read from CAD files: DXF (ezdxf) and SVG (svgelements), as exact pieces.

Conventions (docs/cad.md): millimetres; y up (an SVG's y axis points down and is flipped, so the
part is not mirrored); the outline is the outer closed loop, the one of largest area, unless a DXF
layer or an SVG element id is named; the first point is the first vertex of the DXF entity or the
first ``M`` of the SVG path the loop starts with. Everything else in the file (holes, text,
dimensions, other layers) is ignored and listed in :attr:`localizer.Outline.ignored`.

The readers are imported only when a CAD file is read: ``import localizer`` needs neither.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .._errors import PartError
from ._dxf import read_dxf
from ._facets import FACETS, FacetRule, read_facets
from ._limits import MAX_PART_BYTES, check_size
from ._outline import Outline, outline_from_pieces
from ._pieces import Line, Piece
from ._svg import read_svg

__all__ = ["load_outline", "CAD_SUFFIXES"]

#: File suffixes read as CAD outlines.
CAD_SUFFIXES = (".dxf", ".svg")


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
        loops, ignored = read_dxf(path, layer)
    elif suffix == ".svg":
        if layer is not None:
            raise PartError(f"{path}: layer={layer!r} is for DXF files; an SVG names an element id")
        loops, ignored = read_svg(path, element)
    else:
        raise PartError(f"{path}: not a CAD file (use one of {list(CAD_SUFFIXES)})")
    chosen, rest = _outer(loops, str(path))
    if rest:
        ignored.append(f"{rest} other closed loop(s) (holes or other outlines)")
    if facets is not None:
        chosen = read_facets(chosen, facets)
    return outline_from_pieces(chosen, name=path.stem, ignored=tuple(ignored))


# ------------------------------------------------------------------ DXF


# ------------------------------------------------------------------ SVG


# ------------------------------------------------------------------ loops


def _area(loop: list[Piece]) -> float:
    # a line's start, a curve's points every 1/64 of it; a run of lines' starts as one array (a faceted
    # drawing's loop is 10⁵ lines)
    parts: list[Any] = []
    run: list[tuple[float, float]] = []
    for p in loop:
        if isinstance(p, Line):
            run.append(p.start)
            continue
        if run:
            parts.append(np.array(run))
            run = []
        parts.append(p.point(np.linspace(0.0, p.length, 65)[:-1]))
    if run:
        parts.append(np.array(run))
    pts = np.concatenate(parts)
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
