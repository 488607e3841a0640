"""Every stretch of an outline with corners where a roll of length L and rotation Ω can have been.

On an :class:`localizer.Outline` the arc position is its own parameter, so a start σ ends at
σ + L and the roll's rotation is g(σ) + Ω = θ(σ + L) − θ(σ), θ the unwrapped tangent angle with its
jumps at corners. g is smooth between the **breakpoints**: the pieces' starts, and the pieces'
starts less L (where the end crosses one). Between two breakpoints both ends stay on one piece
each, so g' = κ(σ + L) − κ(σ) there:

* on lines and arcs κ is constant on a piece: g is linear between breakpoints, and its root is
  exact; g ≡ 0 on a whole interval (two arcs of equal radius, two lines) is a **continuum** of
  feasible starts (``kind="continuum"``, ``span``);
* where an end is on a Bézier, g is sampled every ``spacing`` mm and each sign change refined
  (Brent, to 1e-12 mm); a root pair closer than ``spacing`` can be missed there (not certified,
  unlike the spline solver).

**Corners.** A jaw laid on a convex corner touches it at every angle within the corner's jump, so
a start (or an end) exactly at a corner fits every rotation in a range: with θ⁻, θ⁺ the angles
before and after a corner, a start at corner c and an end at e fit Ω from θ⁻(e) − θ⁺(c) to
θ⁺(e) − θ⁻(c) (an end that is no corner has θ⁻ = θ⁺). Such a segment is reported once, with
``kind="corner"``, when Ω is in its range and no root of the smooth pieces beside it is already
there; its ``residual`` is 0. A straight jaw cannot touch a concave corner; the geometry here does
not ask (the jaw's reach decides, as on spline parts).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ._errors import QueryError
from ._outline import Outline
from ._pieces import CubicBezier
from ._segment import DIRECTIONS, Segment

__all__ = ["outline_segments"]


def _theta(outline: Outline, sigma: float, side: str) -> float:
    return float(outline.tangent_angle_at_arc(sigma, side=side))


def outline_segments(
    outline: Outline, length: float, turn: float, *, direction: str = "ccw", spacing: float = 0.01
) -> list[Segment]:
    """Every segment of ``outline`` with arc length ``length`` (mm) and rotation ``turn`` (rad).

    Parameters
    ----------
    outline : Outline
    length : float, mm
        Contact travel L, ``0 < L < perimeter``.
    turn : float, rad
        Signed jaw rotation Ω (counter-clockwise positive).
    direction : {"ccw", "cw"}
        Direction the contact moved on the outline (as :func:`localizer.feasible_segments`).
    spacing : float, mm
        Sampling step of g where an end is on a Bézier piece.

    Returns
    -------
    list of Segment
        Sorted by ``start_arc``; ``start_param`` and ``end_param`` are arc positions (an outline's
        parameter is its arc length).

    Examples
    --------
    A 40 × 20 mm rectangle: a 10 mm roll that turns a quarter can start anywhere in the 10 mm before
    a corner and pivot on it (a continuum of starts per corner, its far end the corner itself).

    >>> import math
    >>> from localizer import Line, outline_from_pieces
    >>> pts = [(0, 0), (40, 0), (40, 20), (0, 20)]
    >>> box = outline_from_pieces([Line(pts[i], pts[(i + 1) % 4]) for i in range(4)])
    >>> [(round(s.start_arc, 6), s.kind, round(s.span, 6)) for s in outline_segments(box, 10.0, math.pi / 2)]
    [(30.0, 'continuum', 10.0), (50.0, 'continuum', 10.0), (90.0, 'continuum', 10.0), (110.0, 'continuum', 10.0)]

    An eighth of a turn: the jaw pivots half way round a corner, which the roll starts at (0, 40, 60,
    100) or ends at (30, 50, 90, 110).

    >>> [round(s.start_arc, 6) for s in outline_segments(box, 10.0, math.pi / 4) if s.kind == "corner"]
    [0.0, 30.0, 40.0, 50.0, 60.0, 90.0, 100.0, 110.0]
    """
    if not isinstance(outline, Outline):
        raise QueryError(f"outline must be a localizer.Outline, got {type(outline).__name__}")
    if direction not in DIRECTIONS:
        raise QueryError(f"unknown direction {direction!r}; use one of {list(DIRECTIONS)}")
    P = outline.perimeter
    if not (math.isfinite(length) and 0 < length < P and math.isfinite(turn)):
        raise QueryError(f"length={length!r} mm must be in (0, {P:.6g}) and turn={turn!r} rad finite")
    if not (math.isfinite(spacing) and spacing > 0):
        raise QueryError(f"spacing={spacing!r} mm must be positive")
    omega = turn if direction == "ccw" else -turn
    found = _solve_ccw(outline, float(length), float(omega), spacing)
    segs = []
    for s0, kind, span, residual in found:
        if direction == "ccw":
            sa, ea = s0, s0 + length
        else:  # travelled from the far end of the ccw stretch (and of a continuum)
            sa, ea = s0 + length + span, s0 + span
        sa, ea = sa % P, ea % P
        segs.append(
            Segment(
                start_arc=sa,
                end_arc=ea,
                start_param=sa,
                end_param=ea,
                length=float(length),
                turn=float(turn),
                direction=direction,
                kind=kind,
                span=span,
                residual=residual,
            )
        )
    return sorted(segs, key=lambda g: g.start_arc)


def _solve_ccw(outline: Outline, L: float, omega: float, spacing: float) -> list[tuple[float, str, float, float]]:
    """(start arc, kind, span, residual) of every counter-clockwise solution."""
    P = outline.perimeter
    starts = outline.starts[:-1]
    breaks = np.unique(np.mod(np.concatenate([starts, starts - L]), P))
    tol = 1e-9 * max(1.0, P)
    breaks = breaks[np.concatenate([[True], np.diff(breaks) > tol])]
    bounds = np.append(breaks, breaks[0] + P)
    corner_at = {round(c.arc, 9): c for c in outline.corners}

    def g(s: float) -> float:
        """g on the open interval that holds s (both ends strictly inside their pieces)."""
        return _theta(outline, s + L, "after") - _theta(outline, s, "after") - omega

    out: list[tuple[float, str, float, float]] = []
    eps = 1e-9 * max(1.0, P)
    for a, b in zip(bounds[:-1], bounds[1:]):
        lo, hi = a + eps, b - eps
        if hi <= lo:
            continue
        ga, gb = g(lo), g(hi)
        curved = _on_bezier(outline, lo, hi, L)
        if not curved:
            slope = (gb - ga) / (hi - lo)
            if abs(ga) <= 1e-12 and abs(gb) <= 1e-12:
                out.append((float(a), "continuum", float(b - a), 0.0))
            elif ga * gb < 0 or abs(gb) <= 1e-12:
                s = lo - ga / slope if slope != 0 else lo
                out.append((float(s), "simple", 0.0, abs(g(min(max(s, lo), hi)))))
            continue
        n = max(2, int(math.ceil((hi - lo) / spacing)))
        xs = np.linspace(lo, hi, n + 1)
        gs = outline.tangent_angle_at_arc(xs + L) - outline.tangent_angle_at_arc(xs) - omega
        for i in np.flatnonzero(np.sign(gs[:-1]) * np.sign(gs[1:]) < 0):
            s = brentq(g, float(xs[i]), float(xs[i + 1]), xtol=1e-12)
            out.append((float(s), "simple", 0.0, abs(g(s))))
        for i in np.flatnonzero(gs == 0.0):
            out.append((float(xs[i]), "simple", 0.0, 0.0))
    # corners: a start at corner c, or an end at a corner, fits a range of rotations
    for b in breaks:
        c_start = corner_at.get(round(float(b), 9))
        c_end = corner_at.get(round(float((b + L) % P), 9))
        if c_start is None and c_end is None:
            continue
        lo_end, hi_end = sorted((_theta(outline, b + L, "before"), _theta(outline, b + L, "after")))
        lo_start, hi_start = sorted((_theta(outline, b, "before"), _theta(outline, b, "after")))
        lo_turn, hi_turn = lo_end - hi_start, hi_end - lo_start
        if lo_turn - 1e-12 <= omega <= hi_turn + 1e-12 and not any(
            _covers(s0, span, float(b), P) for s0, _, span, _ in out
        ):
            out.append((float(b), "corner", 0.0, 0.0))
    return out


def _covers(s0: float, span: float, b: float, P: float) -> bool:
    """Whether the solution at s0 (a continuum of ``span`` mm) already holds the start b."""
    d = (b - s0) % P
    return d <= span + 1e-6 or d >= P - 1e-6


def _on_bezier(outline: Outline, lo: float, hi: float, L: float) -> bool:
    """Whether an end of the starts in (lo, hi) lies on a Bézier piece."""
    _, k, _ = outline._locate(np.array([0.5 * (lo + hi), 0.5 * (lo + hi) + L]))
    return any(isinstance(outline.pieces[int(i)], CubicBezier) for i in k)
