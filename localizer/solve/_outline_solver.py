"""Every stretch of an outline with corners where a roll of length L and rotation Ω can have been.

On an :class:`localizer.Outline` the arc position is its own parameter, so a start σ ends at
σ + L and the roll's rotation is g(σ) + Ω = θ(σ + L) − θ(σ), θ the unwrapped tangent angle with its
jumps at corners. g is smooth between the **breakpoints**: the pieces' starts, and the pieces'
starts less L (where the end crosses one). Between two breakpoints both ends stay on one piece
each, so g' = κ(σ + L) − κ(σ) there:

* on lines and arcs κ is constant on a piece: g is linear between breakpoints, and its root is
  exact; g ≡ 0 on a whole interval (two arcs of equal radius, two lines) is a **continuum** of
  feasible starts (``kind="continuum"``, ``span``);
* where an end is on a Bézier, the spline solver's certificate (:mod:`localizer.solve._certify`) runs on
  cells of ``spacing`` mm: g and g' are exact at the cells' ends, and |g''| = |κ'(σ + L) − κ'(σ)| is
  bounded per cell by the sum of |κ'| bounds on its two ends' stretches, each proved from the
  Bézier's Bernstein coefficients over the stretch (:func:`localizer.solve._bezier_bound.kappa_slope_bound`,
  rational pieces included; lines and arcs add nothing), not from a sample. A cell is then certified
  to hold one root (refined by Brent to 1e-12 mm), none, a near-double root or a flat stretch, or it
  is bisected.

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

from .._errors import QueryError
from ..geometry import CubicBezier, Outline, check_grid, per_part
from ._bezier_bound import kappa_slope_bound
from ._certify import certify_cells
from ._segment import DIRECTIONS, Segment

__all__ = ["outline_segments"]

#: The certificate's settings on Bézier cells (the spline solver's defaults, localizer.EXACT).
_FLAT_TOL, _DOUBLE_WIDTH, _MAX_CELLS = 1e-10, 1e-7, 2_000_000
#: How far a table cell's parameter interval is widened past the arc's inversion (which is to 1e-12).
_PARAM_SLACK = 1e-9


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
    # the certified cells cover the lap once
    check_grid(outline, "outline solver", spacing, P / spacing, unit="cells")
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

    def g(s: np.ndarray) -> np.ndarray:
        """g at starts ``s``, each with both ends strictly inside their pieces."""
        return np.asarray(outline.tangent_angle_at_arc(s + L) - outline.tangent_angle_at_arc(s) - omega)

    # on an interval whose ends are on lines and arcs g is linear: its root (or a continuum) in closed
    # form, all such intervals at once; the others are certified cell by cell
    eps = 1e-9 * max(1.0, P)
    a, b = bounds[:-1], bounds[1:]
    lo, hi = a + eps, b - eps
    mid = 0.5 * (lo + hi)
    curved = outline.on_bezier(mid) | outline.on_bezier(mid + L)
    ga, gb = g(lo), g(hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = (gb - ga) / (hi - lo)
        root = np.where(slope != 0, lo - ga / slope, lo)
    continuum = (np.abs(ga) <= 1e-12) & (np.abs(gb) <= 1e-12)
    simple = ~continuum & ((ga * gb < 0) | (np.abs(gb) <= 1e-12))
    residual = np.zeros(a.size)
    if simple.any():
        residual[simple] = np.abs(g(np.minimum(np.maximum(root[simple], lo[simple]), hi[simple])))
    out: list[tuple[float, str, float, float]] = []
    for i in np.flatnonzero((hi > lo) & (curved | continuum | simple)):
        if curved[i]:
            out.extend(_certified(outline, L, omega, float(lo[i]), float(hi[i]), spacing))
        elif continuum[i]:
            out.append((float(a[i]), "continuum", float(b[i] - a[i]), 0.0))
        else:
            out.append((float(root[i]), "simple", 0.0, float(residual[i])))
    # corners: a start at corner c, or an end at a corner, fits a range of rotations
    at_corner = (outline.corner_at(breaks) >= 0) | (outline.corner_at(breaks + L) >= 0)
    for b in breaks[at_corner]:
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


def _certified(
    outline: Outline, L: float, omega: float, lo: float, hi: float, spacing: float
) -> list[tuple[float, str, float, float]]:
    """(start, kind, span, residual) of every root of g in (lo, hi), where an end lies on a Bézier."""
    P = outline.perimeter

    def evaluate(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        th_s, k_s = outline.angle_and_curvature_at_arc(x)
        th_e, k_e = outline.angle_and_curvature_at_arc(x + L)
        return th_e - th_s - omega, k_e - k_s

    n = max(2, int(math.ceil((hi - lo) / spacing)))
    xs = np.linspace(lo, hi, n + 1)
    gs, ds = evaluate(xs)
    K = _slope_bound(outline, xs, spacing) + _slope_bound(outline, xs + L, spacing)
    zeros, brackets, doubles, flats = certify_cells(
        (xs[:-1], xs[1:], gs[:-1], gs[1:], ds[:-1], ds[1:], K),
        evaluate,
        P,
        margin=1e-9,  # θ from the Béziers' arc-length inversion, 1e-9 mm
        dmargin=1e-9,
        flat_tol=_FLAT_TOL,
        double_width=_DOUBLE_WIDTH,
        max_cells=_MAX_CELLS,
        degenerate=f"the query length={L!r} mm, turn={omega!r} rad is degenerate on outline {outline.name!r}",
    )

    def g(x: float) -> float:
        return float(evaluate(np.array([x]))[0][0])

    out: list[tuple[float, str, float, float]] = [(float(x), "simple", 0.0, 0.0) for x in zeros]
    if brackets is not None:
        from scipy.optimize import brentq  # here: scipy.optimize is 0.3 s of every command's start

        for a, b, ga, gb, near_double in zip(brackets[0], brackets[1], brackets[2], brackets[3], brackets[6]):
            x = float(brentq(g, float(a), float(b), xtol=1e-12)) if ga * gb < 0 else float(a if ga == 0 else b)
            out.append((x, "double" if near_double else "simple", 0.0, abs(g(x))))
    out += [(float(x), "double", 0.0, abs(g(float(x)))) for x in doubles]
    # a root on a cell's end is found from both cells, and a near-double one from many at the bottom
    # width: one per place, a simple root before a double one
    merged: list[tuple[float, str, float, float]] = []
    for root in sorted(out, key=lambda r: (r[0], r[1] != "simple")):
        if merged and root[0] - merged[-1][0] <= 10 * _DOUBLE_WIDTH:
            continue
        merged.append(root)
    flat = [(float(a), "continuum", float(span), 0.0) for a, span in flats]
    inside = [r for r in merged if not any(a - 1e-9 <= r[0] <= a + span + 1e-9 for a, _, span, _ in flat)]
    return inside + flat


def _slope_bound(outline: Outline, x: np.ndarray, spacing: float) -> np.ndarray:
    """A bound of |dκ/dσ| (1/mm²) on each cell [x_i, x_i+1] (mm, all on one piece): 0 on lines and arcs."""
    _, k, local = outline._locate(x)
    piece = int(k[len(k) // 2])
    if not isinstance(outline.pieces[piece], CubicBezier):
        return np.zeros(x.size - 1)
    h, bound = _bezier_slopes(outline, spacing)[piece]
    # the piece's arc of each cell end, kept on the piece (an interval's ends are inside it)
    first = np.clip(np.floor(np.minimum(local[:-1], local[1:]) / h).astype(np.int64), 0, bound.size - 1)
    last = np.clip(np.floor(np.maximum(local[:-1], local[1:]) / h).astype(np.int64), 0, bound.size - 1)
    out = bound[first]
    for j in range(1, 4):  # a cell of ``spacing`` spans at most three of the table's cells of spacing/2
        out = np.maximum(out, bound[np.minimum(first + j, last)])
    return np.asarray(out)


def _bezier_slopes(outline: Outline, spacing: float) -> dict[int, tuple[float, np.ndarray]]:
    """Per Bézier piece: (table step h, mm; a proved bound of |dκ/dσ| on each table cell, 1/mm²), built
    once per outline and spacing."""

    def build() -> dict[int, tuple[float, np.ndarray]]:
        cells = sum(
            max(8, int(math.ceil(piece.length / (0.5 * spacing))))
            for piece in outline.pieces
            if isinstance(piece, CubicBezier)
        )
        check_grid(outline, "outline solver's Bézier table", 0.5 * spacing, cells, unit="cells")
        out = {}
        for i, piece in enumerate(outline.pieces):
            if not isinstance(piece, CubicBezier):
                continue
            m = max(8, int(math.ceil(piece.length / (0.5 * spacing))))
            h = piece.length / m
            u = np.asarray(piece.param(np.arange(m + 1) * h), dtype=float)
            # the parameter from the arc by Newton's method, to 1e-12: each cell widened past that
            u0 = np.clip(u[:-1] - _PARAM_SLACK, 0.0, 1.0)
            u1 = np.clip(u[1:] + _PARAM_SLACK, 0.0, 1.0)
            out[i] = (h, kappa_slope_bound(piece, u0, u1))
        return out

    return per_part("bezier_slopes", outline, float(spacing), build)
