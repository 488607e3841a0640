"""A closed outline made of exact pieces, with corners: the geometry of a part drawn in CAD.

The pieces (:mod:`localizer.geometry._pieces`) are chained end to start; the outline is counter-clockwise
(a clockwise chain is reversed, its first point kept first) and its arc position σ runs from the
first piece's start over [0, perimeter). The unwrapped tangent angle θ(σ) is continuous along a
piece and jumps at a **corner** by the exterior angle (positive: a convex corner, where a straight
jaw pivots; negative: a concave one, which a straight jaw cannot touch). At a corner's arc position
θ is the value after the corner; :meth:`Outline.tangent_angle_at_arc` with ``side="before"`` gives
the value before it. Over one lap θ grows by 2π, jumps included.

This is the geometry only; the solver, the filter and the rigs take it from here.
"""

from __future__ import annotations

import math
from collections.abc import Hashable
from dataclasses import dataclass, field
from typing import Any, NamedTuple, cast

import numpy as np

from .._errors import PartError
from .._types import ArrayLike, FloatArray
from ._boundary import ArcPositions
from ._numerics import wrap_angle
from ._part import _segments_cross
from ._pieces import CircularArc, CubicBezier, Line, Piece

__all__ = ["Outline", "Corner", "outline_from_pieces", "nearest_corner"]

#: Two pieces meet when the end of one is this close to the start of the next, mm.
JOIN_TOL = 1e-6
#: A tangent that turns by less than this across a meeting point, rad, is smooth there (no corner).
#: A drawing written with coordinates rounded to 1 µm (SVG text, DXF exports) breaks a smooth join by
#: about 1e-7 rad over a 10 mm control arm, and by 1e-4 at 1e-3 mm; such a "corner" would be a pivot
#: (or, turned the other way, a concave corner the jaw cannot touch) in the middle of a smooth
#: stretch. 1e-3 rad is half of two steps of the arm's 0.03° encoder: a jump the jaw cannot sense.
SMOOTH_TOL = 1e-3
#: An arc position this close to a corner, relative to the perimeter (or 1 mm), is at the corner
#: (:meth:`Outline.corner_at`): a start plus a length that should land on a corner misses it by rounding,
#: about 1e-15 of the perimeter. Far below any place the jaw can tell (0.3 nm on a 300 mm part), and
#: below the solver's own margin inside its intervals (1e-9), so that a limit taken beside a corner
#: stays on its side.
AT_CORNER = 1e-12
#: A corner whose direction turns by more than π less this, rad, is a fold: the outline goes back along
#: itself (a line drawn twice, a zero-width slot), which no part has.
FOLD_TOL = 1e-6
#: An outline enclosing less than this times its perimeter squared has no inside (a sliver; a square
#: has 1/16, a 1 mm strip 1 m long 2.5e-4).
AREA_RTOL = 1e-6


_LINE, _ARC, _BEZIER = 0, 1, 2


class Corner(NamedTuple):
    """Where the tangent jumps: the arc position (mm) and the exterior angle (rad; > 0 convex)."""

    arc: float
    angle: float


@dataclass(frozen=True, eq=False)
class Outline(ArcPositions):
    """A closed counter-clockwise chain of exact pieces (build one with :func:`outline_from_pieces`).

    Attributes
    ----------
    pieces : tuple of Line, CircularArc, CubicBezier
        In order, each starting where the previous one ends.
    name : str
    perimeter : float, mm
    corners : tuple of Corner
        The points where the tangent jumps, by arc position.
    ignored : tuple of str
        What the file the outline was read from held besides it (other loops, text, layers).
    starts : ndarray, shape (n + 1,), mm
        Arc position of each piece's start, and the perimeter.
    turning : float, rad
        Total turning over one lap, every jump included (2π for a simple counter-clockwise outline).
    """

    pieces: tuple[Piece, ...]
    name: str = "outline"
    ignored: tuple[str, ...] = ()
    perimeter: float = field(init=False)
    corners: tuple[Corner, ...] = field(init=False)
    turning: float = field(init=False, repr=False)
    starts: FloatArray = field(init=False, repr=False)
    _theta0: FloatArray = field(init=False, repr=False)  # unwrapped θ at each piece's start (after its corner)
    _kind: np.ndarray = field(init=False, repr=False)  # _LINE, _ARC or _BEZIER per piece
    _corner_arcs: FloatArray = field(init=False, repr=False)  # the corners' arcs and jumps, as arrays
    _corner_angles: FloatArray = field(init=False, repr=False)
    _exact: tuple[FloatArray, ...] = field(init=False, repr=False)  # the lines' and arcs' arrays
    _tables: dict[tuple[str, Hashable], Any] = field(init=False, repr=False, default_factory=dict)

    def __post_init__(self) -> None:
        pieces = self.pieces
        n = len(pieces)
        # lines and arcs are evaluated for all their arc positions at once, from these arrays, by the
        # same arithmetic as the pieces' own; Béziers one piece at a time
        kind = np.array(
            [_LINE if isinstance(p, Line) else _ARC if isinstance(p, CircularArc) else _BEZIER for p in pieces],
            dtype=np.int8,
        )
        at_line, at_arc, at_bezier = (np.flatnonzero(kind == k) for k in (_LINE, _ARC, _BEZIER))
        lines = cast(list[Line], [pieces[i] for i in at_line.tolist()])
        arcs = cast(list[CircularArc], [pieces[i] for i in at_arc.tolist()])
        origin, delta = np.zeros((n, 2)), np.zeros((n, 2))  # a line's start and end − start
        polar0, sense, radius = np.zeros(n), np.zeros(n), np.ones(n)  # an arc's, origin its centre
        lengths = np.empty(n)
        if lines:
            origin[at_line] = [p.start for p in lines]
            delta[at_line] = np.array([p.end for p in lines]) - origin[at_line]
            lengths[at_line] = list(map(math.hypot, delta[at_line, 0].tolist(), delta[at_line, 1].tolist()))
        if arcs:
            origin[at_arc], radius[at_arc], polar0[at_arc], sweep = _arc_fields(arcs)
            sense[at_arc] = np.copysign(1.0, sweep)
            lengths[at_arc] = radius[at_arc] * np.abs(sweep)
        lengths[at_bezier] = [pieces[i].length for i in at_bezier.tolist()]
        starts = np.concatenate([[0.0], np.cumsum(lengths)])
        object.__setattr__(self, "starts", starts)
        object.__setattr__(self, "perimeter", float(starts[-1]))
        heading = np.arctan2(delta[:, 1], delta[:, 0])
        quarter = sense * (0.5 * math.pi)
        first = np.where(kind == _LINE, heading, polar0 + quarter)
        last = np.where(kind == _LINE, heading, polar0 + sense * lengths / radius + quarter)
        for b in np.flatnonzero(kind == _BEZIER):
            piece = self.pieces[int(b)]
            first[b], last[b] = float(piece.tangent_angle(0.0)), float(piece.tangent_angle(piece.length))
        angles0, angles1, arcs_at = first.tolist(), last.tolist(), starts.tolist()
        theta0: list[float] = []
        corners = []
        theta = angles0[0]
        for i in range(n):
            local0 = angles0[i]
            if i > 0:
                jump = wrap_angle(local0 - theta)
                if abs(jump) > SMOOTH_TOL:
                    corners.append(Corner(arcs_at[i], jump))
                theta += jump
            theta0.append(theta)
            theta += angles1[i] - local0
        jump = wrap_angle(angles0[0] - theta)
        if abs(jump) > SMOOTH_TOL:
            corners.insert(0, Corner(0.0, jump))
        object.__setattr__(self, "_theta0", np.array(theta0, dtype=float))
        object.__setattr__(self, "corners", tuple(corners))
        object.__setattr__(self, "_corner_arcs", np.array([c.arc for c in corners], dtype=float))
        object.__setattr__(self, "_corner_angles", np.array([c.angle for c in corners], dtype=float))
        # every jump counts, the smooth ones too: the total is then exactly that of the pieces' ends
        object.__setattr__(self, "turning", float(theta + jump - theta0[0]))
        object.__setattr__(self, "_kind", kind)
        object.__setattr__(self, "_exact", (origin, delta, lengths, polar0, sense, radius, first))

    def _evaluate(
        self, k: np.ndarray, local: FloatArray, point: bool = False, angle: bool = False, curvature: bool = False
    ) -> tuple[FloatArray | None, FloatArray | None, FloatArray | None]:
        """(points (..., 2) mm, θ rad, κ 1/mm), those asked for, of pieces ``k`` at arcs ``local``
        within them (mm); θ unwrapped from the piece's start θ :attr:`_theta0`."""
        origin, delta, lengths, polar0, sense, radius, first = self._exact
        shape = np.shape(local)
        kind = self._kind[k]
        line, arc = kind == _LINE, kind == _ARC
        kl, ka = k[line], k[arc]
        xy = th = kappa = None
        polar = polar0[ka] + sense[ka] * local[arc] / radius[ka]
        if point:
            xy = np.empty(shape + (2,))
            xy[line] = origin[kl] + (local[line] / lengths[kl])[..., None] * delta[kl]
            xy[arc] = origin[ka] + radius[ka][:, None] * np.stack([np.cos(polar), np.sin(polar)], -1)
        if angle:
            th = np.empty(shape)
            th[line] = self._theta0[kl]
            th[arc] = self._theta0[ka] + (polar + sense[ka] * (0.5 * math.pi)) - first[ka]
        if curvature:
            kappa = np.empty(shape)
            kappa[line] = 0.0
            kappa[arc] = sense[ka] * (1.0 / radius[ka])
        for i in np.unique(k[kind == _BEZIER]):
            sel = k == i
            piece = self.pieces[int(i)]
            assert isinstance(piece, CubicBezier)
            if point:
                xy[sel] = piece.point(local[sel])  # type: ignore[index]
            if angle and curvature:
                t, kappa[sel] = piece.angle_and_curvature(local[sel])  # type: ignore[index]
                th[sel] = self._theta0[i] + t - first[i]  # type: ignore[index]
            elif angle:
                th[sel] = self._theta0[i] + piece.tangent_angle(local[sel]) - first[i]  # type: ignore[index]
            elif curvature:
                kappa[sel] = piece.curvature(local[sel])  # type: ignore[index]
        return xy, th, kappa

    def _locate(self, sigma: ArrayLike) -> tuple[FloatArray, np.ndarray, FloatArray]:
        """(laps, piece index, arc within the piece) of unrolled arc positions ``sigma`` (mm); a position
        at a corner (:meth:`corner_at`) is the start of the piece after it."""
        lap, k, local, _ = self._place(sigma)
        return lap, k, local

    def _place(self, sigma: ArrayLike) -> tuple[FloatArray, np.ndarray, FloatArray, np.ndarray]:
        """:meth:`_locate` and :meth:`corner_at` of ``sigma`` at once."""
        P = self.perimeter
        s = np.asarray(sigma, dtype=float)
        lap = np.floor(s / P)
        ss = s - lap * P
        over = ss >= P  # rounding: just under a whole lap
        lap, ss = np.where(over, lap + 1.0, lap), np.where(over, ss - P, ss)
        corner = np.full(ss.shape, -1, dtype=np.int64)
        if self.corners:
            arcs = self._corner_arcs
            # a sum of arcs that should land on a corner lands within rounding of it on either side, through
            # the seam as well
            index, off, shift = nearest_corner(arcs, P, ss)
            at = np.abs(off) <= AT_CORNER * max(1.0, P)
            corner = np.where(at, index, -1)
            lap = np.where(at, lap + shift, lap)
            ss = np.where(at, arcs[index], ss)
        k = np.clip(np.searchsorted(self.starts, ss, side="right") - 1, 0, len(self.pieces) - 1)
        local: FloatArray = ss - self.starts[k]
        return lap, k, local, corner

    def corner_at(self, sigma: ArrayLike) -> np.ndarray:
        """The index in :attr:`corners` of the corner at each arc position ``sigma`` (mm, any real), −1
        where there is none. Every question "is this arc at a corner?" is answered here: a position
        within :data:`AT_CORNER` of a corner (relative to the perimeter, or 1 mm) is at it, on either
        side, through the seam too, so that an end computed as a start plus a length lands on the
        corner it was meant to, whatever the rounding."""
        return self._place(sigma)[3]

    def point_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """Points at arc positions ``sigma`` (mm, any real: wraps), shape (..., 2), mm."""
        _, k, local = self._locate(sigma)
        out, _, _ = self._evaluate(k, local, point=True)
        assert out is not None
        return out

    def tangent_angle_at_arc(self, sigma: ArrayLike, side: str = "after") -> FloatArray:
        """Unwrapped tangent angle θ at arc positions ``sigma`` (mm), rad: θ(σ + P) = θ(σ) + 2π. At a
        corner ``side`` says which value: ``"after"`` (default) or ``"before"`` the jump."""
        if side not in ("after", "before"):
            raise PartError(f"side={side!r}: use 'after' or 'before'")
        lap, k, local, corner = self._place(sigma)
        _, theta, _ = self._evaluate(k, local, angle=True)
        assert theta is not None
        out = theta + 2.0 * np.pi * lap
        if side == "before" and self.corners:
            out = out - np.where(corner >= 0, self._corner_angles[corner], 0.0)
        result: FloatArray = out
        return result

    @property
    def faces(self) -> tuple[tuple[float, float], ...]:
        """The straight pieces, where a straight jaw lies flush: (tangent angle, rad in [−π, π);
        length, mm) each, in order."""
        return tuple((float(p.tangent_angle(0.0)), float(p.length)) for p in self.pieces if isinstance(p, Line))

    def angle_and_curvature_at_arc(self, sigma: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(:meth:`tangent_angle_at_arc`, :meth:`curvature_at_arc`) at ``sigma`` (mm), the angle after a
        corner's jump; a Bézier's arc length inverted once for both."""
        lap, k, local = self._locate(sigma)
        _, theta, kappa = self._evaluate(k, local, angle=True, curvature=True)
        assert theta is not None and kappa is not None
        return theta + 2.0 * np.pi * lap, kappa

    def on_bezier(self, sigma: ArrayLike) -> np.ndarray:
        """Whether each unrolled arc position ``sigma`` (mm) lies on a Bézier piece (bool array): the
        pieces whose curvature varies along them, where the exact solvers need a certificate."""
        return np.asarray(self._kind[self._locate(sigma)[1]] == _BEZIER)

    def curvature_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """Signed curvature at arc positions ``sigma`` (mm), 1/mm (zero on lines, ±1/r on arcs)."""
        _, k, local = self._locate(sigma)
        _, _, kappa = self._evaluate(k, local, curvature=True)
        assert kappa is not None
        return kappa

    # an outline's parameter is its arc position: the parametric interface of a spline Part, so that
    # what places a jaw by parameter (the simulated rig) takes either
    def param_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """The parameter at arc positions ``sigma`` (mm): the arc itself, wrapped to [0, perimeter)."""
        return self.wrap_arc(sigma)

    def arc_at_param(self, t: ArrayLike) -> FloatArray:
        """The arc position (mm) at parameter ``t``: ``t`` itself."""
        return np.asarray(t, dtype=float)

    def point(self, t: ArrayLike) -> FloatArray:
        """:meth:`point_at_arc` at ``t`` (the parameter is the arc position, mm)."""
        return self.point_at_arc(t)

    def tangent_angle(self, t: ArrayLike) -> FloatArray:
        """:meth:`tangent_angle_at_arc` at ``t`` (the parameter is the arc position, mm)."""
        return self.tangent_angle_at_arc(t)

    def curvature(self, t: ArrayLike) -> FloatArray:
        """:meth:`curvature_at_arc` at ``t`` (the parameter is the arc position, mm), 1/mm."""
        return self.curvature_at_arc(t)

    def sample(self, spacing: float = 0.5) -> FloatArray:
        """A closed polyline through the outline every ``spacing`` mm or less (every piece's ends
        included), shape (M + 1, 2), mm, its last point the first."""
        lengths = np.diff(self.starts)
        n = np.maximum(2, np.ceil(lengths / spacing)).astype(np.int64)
        k = np.repeat(np.arange(len(self.pieces)), n)
        j = np.arange(k.size) - np.repeat(np.cumsum(n) - n, n)
        poly, _, _ = self._evaluate(k, j * (lengths / n)[k], point=True)
        assert poly is not None
        out: FloatArray = np.vstack([poly, poly[:1]])
        return out


def nearest_corner(arcs: FloatArray, period: float, x: FloatArray) -> tuple[np.ndarray, FloatArray, np.ndarray]:
    """For arc positions ``x`` in [0, ``period``) (mm), the nearest of the sorted corner arcs ``arcs`` (mm)
    either way, through the seam: its index, the signed offset ``x`` − it (mm), and the lap it lies in
    relative to ``x`` (−1: the last corner a lap before, +1: the first a lap after, else 0)."""
    near = np.concatenate([[arcs[-1] - period], arcs, [arcs[0] + period]])
    j = np.clip(np.searchsorted(near, x), 1, near.size - 1)
    j = np.where(x - near[j - 1] <= near[j] - x, j - 1, j)
    offset: FloatArray = x - near[j]
    return (j - 1) % arcs.size, offset, np.where(j == 0, -1, np.where(j == near.size - 1, 1, 0))


def _arc_fields(arcs: list[CircularArc]) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The arcs' centres (n, 2), radii, start angles and sweeps, as arrays (mm, mm, rad, rad)."""
    center = np.array([p.center for p in arcs], dtype=float).reshape(-1, 2)
    radius = np.array([p.radius for p in arcs], dtype=float)
    start_angle = np.array([p.start_angle for p in arcs], dtype=float)
    sweep = np.array([p.sweep for p in arcs], dtype=float)
    return center, radius, start_angle, sweep


def _ends(pieces: tuple[Piece, ...]) -> tuple[FloatArray, FloatArray]:
    """Each piece's start and end, shape (n, 2), mm, to the bit as its ``start`` and ``end``: a circular
    arc's by the same arithmetic on arrays, with :mod:`math`'s cosines and sines (numpy's may differ in
    the last bit)."""
    n = len(pieces)
    start, end = np.empty((n, 2)), np.empty((n, 2))
    at_arc = [i for i, p in enumerate(pieces) if isinstance(p, CircularArc)]
    others = [i for i, p in enumerate(pieces) if not isinstance(p, CircularArc)]
    if others:
        start[others] = [pieces[i].start for i in others]
        end[others] = [pieces[i].end for i in others]
    if at_arc:
        center, radius, a0, sweep = _arc_fields(cast(list[CircularArc], [pieces[i] for i in at_arc]))
        a1 = a0 + np.copysign(1.0, sweep) * (radius * np.abs(sweep)) / radius
        for out, a in ((start, a0.tolist()), (end, a1.tolist())):
            out[at_arc, 0] = center[:, 0] + radius * np.fromiter(map(math.cos, a), float, len(a))
            out[at_arc, 1] = center[:, 1] + radius * np.fromiter(map(math.sin, a), float, len(a))
    return start, end


def outline_from_pieces(
    pieces: list[Piece] | tuple[Piece, ...], *, name: str = "outline", ignored: tuple[str, ...] = ()
) -> Outline:
    """The closed outline of ``pieces`` chained in order, made counter-clockwise.

    Parameters
    ----------
    pieces : sequence of Line, CircularArc, CubicBezier
        Each must start where the previous one ends (within :data:`JOIN_TOL` mm), and the last
        end where the first starts.
    name : str
        For messages and plots.
    ignored : tuple of str
        What the file the pieces were read from held besides them (:attr:`Outline.ignored`).

    Raises
    ------
    PartError
        No pieces, a gap between pieces (which, where, how wide), an outline that crosses itself,
        or one that does not turn once.

    Examples
    --------
    A 40 × 20 mm rectangle with 5 mm fillets, drawn clockwise: made counter-clockwise, first point
    kept.

    >>> import math
    >>> from localizer import CircularArc, Line
    >>> r, w, h = 5.0, 40.0, 20.0
    >>> pieces = [Line((r, 0), (w - r, 0)), CircularArc((w - r, r), r, -math.pi / 2, math.pi / 2),
    ...           Line((w, r), (w, h - r)), CircularArc((w - r, h - r), r, 0.0, math.pi / 2),
    ...           Line((w - r, h), (r, h)), CircularArc((r, h - r), r, math.pi / 2, math.pi / 2),
    ...           Line((0, h - r), (0, r)), CircularArc((r, r), r, math.pi, math.pi / 2)]
    >>> o = outline_from_pieces([p.reversed() for p in reversed(pieces)])
    >>> round(o.perimeter, 9) == round(2 * (w + h) - 8 * r + 2 * math.pi * r, 9), o.corners
    (True, ())
    >>> [round(float(v), 6) for v in o.point_at_arc(0.0)], round(o.turning, 12) == round(2 * math.pi, 12)
    ([5.0, 0.0], True)
    """
    pieces = tuple(pieces)
    if not pieces:
        raise PartError(f"outline {name!r}: no pieces")
    start, end = _ends(pieces)
    # numpy's hypot is within an ulp or so of math.dist's: the gaps it finds well under JOIN_TOL are, and
    # the others are measured as before
    near = np.hypot(*(end - np.roll(start, -1, axis=0)).T) <= JOIN_TOL * (1.0 - 1e-9)
    for i in np.flatnonzero(~near).tolist():
        piece, nxt = pieces[i], pieces[(i + 1) % len(pieces)]
        gap = math.dist(piece.end, nxt.start)
        if gap > JOIN_TOL:
            raise PartError(
                f"outline {name!r}: piece {i} ends at {piece.end} but piece {(i + 1) % len(pieces)} starts at "
                f"{nxt.start}, {gap:.3g} mm away (more than {JOIN_TOL} mm): the outline is not closed there"
            )
    outline = Outline(pieces, name, ignored)
    poly = outline.sample(max(outline.perimeter / 4000.0, 1e-3))
    crossing = _segments_cross(poly)
    if crossing is not None:
        where = poly[crossing[0]]
        raise PartError(f"outline {name!r} crosses itself near ({where[0]:.3f}, {where[1]:.3f}) mm")
    for corner in outline.corners:
        if abs(corner.angle) > math.pi - FOLD_TOL:
            x, y = (float(v) for v in outline.point_at_arc(corner.arc))
            raise PartError(
                f"outline {name!r} folds back on itself at ({x:.3f}, {y:.3f}) mm (its direction reverses there): "
                "a part's outline goes round an inside; is a line drawn twice, or the loop not closed?"
            )
    area = 0.5 * float(np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1]))
    if abs(area) < AREA_RTOL * outline.perimeter**2:
        raise PartError(
            f"outline {name!r} encloses {abs(area):.3g} mm² with a perimeter of {outline.perimeter:.3f} mm: it has "
            "no inside to roll on; is a line drawn twice, or the loop not closed?"
        )
    turning = outline.turning
    if abs(abs(turning) - 2.0 * math.pi) > 1e-6:
        raise PartError(f"outline {name!r} turns by {turning:.6f} rad, not one full turn: not a simple closed outline")
    if turning < 0:  # clockwise: travel it the other way, from the same first point
        outline = Outline(tuple(p.reversed() for p in reversed(pieces)), name, ignored)
    return outline
