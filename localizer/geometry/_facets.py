"""A faceted drawing read as the curve it traces: small turns between straight segments made smooth.

CAD exports, scanners and slicers write a curve as a dense polyline: thousands of short straight
segments, each turning a little from the last. Taken literally, every vertex is a corner where a
straight jaw pivots, and a turn too small to count as a corner (:data:`localizer.geometry._outline.SMOOTH_TOL`)
is a jump in the tangent that the outline does not record. The rule here (docs/cad.md, "Faceted
drawings"):

* A vertex between two straight segments is **smooth** when its direction turns by at most
  :attr:`FacetRule.corner_angle` and the arc that replaces it stays within
  :attr:`FacetRule.chord_tolerance` of the drawn vertex. It is replaced by the circular arc tangent
  to both segments that reaches halfway along the shorter of them (the fillet): on a regular
  polygon these arcs join into its inscribed circle; a long straight edge keeps all but its ends.
* Any other vertex is a **corner**, kept as drawn.
* A vertex whose arc would be flatter than :data:`MAX_FILLET_RADIUS` (two collinear segments up to
  rounding) is left as a smooth join.

The fillets move the outline by at most the chord tolerance (at a vertex, inward at a convex one);
each turns exactly by its vertex's turn, so the total turning stays one turn.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._errors import PartError
from ._pieces import (
    CircularArc,
    Line,
    Piece,
    arcs_are_valid,
    as_points,
    lines_are_valid,
    trusted_arcs,
    trusted_lines,
)

__all__ = ["FacetRule", "FACETS", "read_facets"]

#: A fillet flatter than this, mm, is not made: its centre would be so far off that its end points
#: lose a nanometre to rounding; the vertex then turns by less than 2·(half segment)/radius, under
#: 1e-6 rad for segments under 10 mm.
MAX_FILLET_RADIUS = 1e7
#: A straight segment shortened by the fillets at both ends to less than this, mm, is dropped (its
#: direction, from its end points, would be lost to rounding); the fillets then meet within it.
MIN_SEGMENT = 1e-9


@dataclass(frozen=True)
class FacetRule:
    """When a vertex between two straight segments of a drawing is smooth rather than a corner.

    Attributes
    ----------
    corner_angle : float, rad
        A vertex that turns by more is a corner. Default 15°: a 24-gon's vertices are corners, a
        100-gon's (3.6°) and an ellipse of axes 3:1 drawn with 100 points (10.8° at its ends) smooth.
    chord_tolerance : float, mm
        A vertex whose fillet would pass farther from it is a corner. Default 0.05 mm: about the
        sagitta of a 100-gon on a 100 mm circle (0.025 mm); a 3° bend between two 20 mm edges
        (0.13 mm) stays a corner.
    """

    corner_angle: float = math.radians(15.0)
    chord_tolerance: float = 0.05

    def __post_init__(self) -> None:
        if not (math.isfinite(self.corner_angle) and 0.0 <= self.corner_angle < math.pi):
            raise PartError(f"corner_angle={self.corner_angle!r} rad must be in [0, π)")
        if not (math.isfinite(self.chord_tolerance) and self.chord_tolerance >= 0.0):
            raise PartError(f"chord_tolerance={self.chord_tolerance!r} mm must be a number ≥ 0")


#: The rule CAD files are read with (:func:`localizer.load_outline`).
FACETS = FacetRule()


def read_facets(pieces: list[Piece] | tuple[Piece, ...], rule: FacetRule = FACETS) -> list[Piece]:
    """The closed chain ``pieces`` with every smooth vertex between two lines replaced by its fillet.

    Parameters
    ----------
    pieces : sequence of Line, CircularArc, CubicBezier
        A closed chain, each piece starting where the previous one ends, the last where the first
        starts (either winding).
    rule : FacetRule
        Which vertices are smooth.

    Returns
    -------
    list of Piece
        The same chain with fillets: the first point is the middle of the first vertex's fillet
        when that vertex is smooth (the curve's nearest point to it), else the first vertex.

    Examples
    --------
    A square whose bottom side is drawn as two segments with a 0.46° bend (0.1 mm deep in 50 mm):
    the bend becomes an arc of radius 3.1 m, the square's corners stay corners.

    >>> from localizer import Line, outline_from_pieces
    >>> square = [Line((0, 0), (25, -0.1)), Line((25, -0.1), (50, 0)), Line((50, 0), (50, 50)),
    ...           Line((50, 50), (0, 50)), Line((0, 50), (0, 0))]
    >>> pieces = read_facets(square)
    >>> [type(p).__name__ for p in pieces], round(pieces[1].radius)
    (['Line', 'CircularArc', 'Line', 'Line', 'Line', 'Line'], 3125)
    >>> len(outline_from_pieces(pieces).corners)
    4
    """
    pieces = list(pieces)
    n = len(pieces)
    if n < 3:
        return pieces
    line = np.array([isinstance(p, Line) for p in pieces])
    both = line & np.roll(line, 1)  # vertex j: the end of piece j - 1, the start of piece j
    if not both.any():
        return pieces
    start = np.array([p.start for p in pieces])
    end = np.array([p.end for p in pieces])
    length = np.array([p.length for p in pieces])
    heading = np.arctan2(end[:, 1] - start[:, 1], end[:, 0] - start[:, 0])
    turn = (heading - np.roll(heading, 1) + np.pi) % (2.0 * np.pi) - np.pi
    reach = 0.5 * np.minimum(length, np.roll(length, 1))  # tangent length of each vertex's fillet
    half = 0.5 * np.abs(turn)
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = reach / np.tan(half)
        gap = radius * (1.0 / np.cos(half) - 1.0)  # the vertex to the fillet's middle
    smooth = both & (half > 0) & (np.abs(turn) <= rule.corner_angle) & (gap <= rule.chord_tolerance)
    smooth &= radius <= MAX_FILLET_RADIUS
    if not smooth.any():
        return pieces
    direction = (end - start) / length[:, None]
    cut = np.where(smooth, reach, 0.0)  # how much of each line its start's fillet takes
    # each fillet from its tangent point on the incoming line, the centre to the left when it turns left
    incoming = np.roll(direction, 1, axis=0)
    tangent_point = start - reach[:, None] * incoming
    side = np.sign(turn)[:, None] * np.c_[-incoming[:, 1], incoming[:, 0]]
    centre = tangent_point + np.where(smooth, radius, 0.0)[:, None] * side
    a0 = np.arctan2(tangent_point[:, 1] - centre[:, 1], tangent_point[:, 0] - centre[:, 0])
    trimmed = smooth | np.roll(smooth, -1)
    s0, s1 = cut, length - np.roll(cut, -1)
    a, b = start + s0[:, None] * direction, start + s1[:, None] * direction

    # each vertex's fillet, then its piece or what the fillets leave of it, in the chain's order
    arcs = np.flatnonzero(smooth)
    cuts = np.flatnonzero(line & trimmed & (s1 - s0 >= MIN_SEGMENT))
    kept = np.flatnonzero(~(line & trimmed))
    slots = np.empty(2 * n, dtype=object)
    if arcs_are_valid(centre[arcs], radius[arcs], a0[arcs], turn[arcs]) and lines_are_valid(a[cuts], b[cuts]):
        slots[2 * arcs] = trusted_arcs(as_points(centre[arcs]), radius[arcs], a0[arcs], turn[arcs])
        slots[2 * cuts + 1] = trusted_lines(as_points(a[cuts]), as_points(b[cuts]))
    else:  # the constructors say what is wrong, at the first piece it is wrong in
        for i in np.sort(np.r_[2 * arcs, 2 * cuts + 1]):
            j = i // 2
            slots[i] = (
                Line((a[j, 0], a[j, 1]), (b[j, 0], b[j, 1]))
                if i % 2
                else CircularArc((centre[j, 0], centre[j, 1]), radius[j], a0[j], turn[j])
            )
    slots[2 * kept + 1] = [pieces[j] for j in kept]
    out: list[Piece] = [p for p in slots.tolist() if p is not None]
    if smooth[0]:  # the first vertex's fillet: its second half first, its first half last
        arc = out[0]
        assert isinstance(arc, CircularArc)
        mid = arc.start_angle + 0.5 * arc.sweep
        out[0] = CircularArc(arc.center, arc.radius, mid, 0.5 * arc.sweep)
        out.append(CircularArc(arc.center, arc.radius, arc.start_angle, 0.5 * arc.sweep))
    return out
