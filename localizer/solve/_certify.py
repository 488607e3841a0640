"""Certified root enumeration on cells: the exact solvers' completeness, shared by splines and outlines.

g(σ) = θ(σ + L) − θ(σ) − Ω is known exactly, with its derivative g' = κ(σ + L) − κ(σ), at the ends
of each cell [a, b], and K bounds |g''| on the cell. Then:

* ``g'(a) + g'(b) > K w`` (or ``< -K w``) certifies g strictly monotone on the cell: exactly one
  root if g changes sign there, none otherwise;
* otherwise the quadratic envelopes ``g(a) + g'(a) s - K s²/2`` and ``g(b) - g'(b) s - K s²/2``
  certify that a cell whose ends have the same sign holds no root when their zero crossings overlap;
* a cell that passes neither is bisected. Near a double root the bisection stops at a width of
  ``double_width`` mm and reports the point as a root of kind ``"double"``; a cell where |g| stays
  below ``flat_tol`` everywhere is flat, and flat cells merge into ``"continuum"`` stretches.

``margin`` (rad) and ``dmargin`` (1/mm) widen the certificates by the evaluation's own error (a
table's interpolation error on a spline, the arc-length inversion on a Bézier).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._errors import QueryError

__all__ = ["certify_cells", "merge_flats"]

Evaluate = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def certify_cells(
    cells: tuple[np.ndarray, ...],
    evaluate: Evaluate,
    perimeter: float,
    *,
    margin: float,
    dmargin: float,
    flat_tol: float,
    double_width: float,
    max_cells: int,
    degenerate: str,
) -> tuple[np.ndarray, tuple[np.ndarray, ...] | None, np.ndarray, list[tuple[float, float]]]:
    """Sort every cell into certified single-root brackets, root-free, double roots and flat stretches.

    Parameters
    ----------
    cells : (a, b, ga, gb, da, db, K)
        Cell ends (mm), g (rad) and g' (1/mm) at them, and the bound K of |g''| (1/mm²) per cell.
    evaluate : callable
        ``evaluate(m) -> (g, g')`` at arc positions ``m`` (mm).
    perimeter : float, mm
        For merging flat cells across σ = 0.
    margin, dmargin : float
        The evaluation's error bounds on g (rad) and g' (1/mm).
    flat_tol, double_width, max_cells : float, float, int
        A cell flat below ``flat_tol`` rad; the width (mm) at which a cell that cannot be certified
        is a double root; the most cells processed before the query is called degenerate
        (:class:`localizer.ExactOptions`).
    degenerate : str
        What the query is, for the error when g stays near zero on more than ``max_cells`` cells.

    Returns
    -------
    zeros, brackets, doubles, continua
        Cell ends where g is exactly 0; the single-root brackets (lo, hi, glo, ghi, g'lo, g'hi,
        near_double) or None; double-root positions; (start, span) pairs of flat stretches.
    """
    a, b, ga, gb, da, db, K = cells
    brackets = []  # (lo, hi, glo, ghi, g'lo, g'hi, near_double)
    exact_zero = [a[ga == 0.0]]
    doubles = []
    flats = []
    processed = 0
    while a.size:
        processed += a.size
        if processed > max_cells:
            raise QueryError(
                f"{degenerate}: g stays near zero on too many cells ({processed}); the part is "
                "nearly a circular arc there. Raise flat_tol or max_cells"
            )
        w = b - a
        s = da + db
        mono = (s > K * w + dmargin) | (s < -(K * w + dmargin))
        change = ga * gb < 0.0
        take = mono & change
        if take.any():
            brackets.append((a[take], b[take], ga[take], gb[take], da[take], db[take], np.zeros(int(take.sum()), bool)))
        rest = ~mono
        # same-sign cells: no root if the quadratic envelopes' zero crossings overlap
        sg = np.where(ga != 0.0, np.sign(ga), np.sign(gb))
        Ga, Gb, Da, Db = sg * ga - margin, sg * gb - margin, sg * da, sg * db
        with np.errstate(invalid="ignore", divide="ignore"):
            ra = (Da + np.sqrt(np.maximum(Da * Da + 2 * K * Ga, 0.0))) / K
            rb = (-Db + np.sqrt(np.maximum(Db * Db + 2 * K * Gb, 0.0))) / K
        excluded = (~change) & (Ga > 0) & (Gb > 0) & (ra + rb > w)
        M = 0.5 * (np.abs(s) + K * w)
        flat = np.maximum(np.abs(ga), np.abs(gb)) + 0.5 * M * w + margin <= flat_tol
        rest &= ~excluded
        fl = rest & flat
        if fl.any():
            flats.append(np.c_[a[fl], b[fl]])
        rest &= ~flat
        bottom = rest & (w <= double_width)
        if bottom.any():
            bc = bottom & change
            if bc.any():
                brackets.append((a[bc], b[bc], ga[bc], gb[bc], da[bc], db[bc], np.ones(int(bc.sum()), bool)))
            bn = bottom & ~change
            if bn.any():
                pick = np.abs(ga[bn]) <= np.abs(gb[bn])
                doubles.append(np.where(pick, a[bn], b[bn]))
        split = rest & ~bottom
        if not split.any():
            break
        a, b, ga, gb, da, db, K = (x[split] for x in (a, b, ga, gb, da, db, K))
        m = 0.5 * (a + b)
        gm, dm = evaluate(m)
        a = np.concatenate([a, m])
        b = np.concatenate([m, b])
        ga, gb = np.concatenate([ga, gm]), np.concatenate([gm, gb])
        da, db = np.concatenate([da, dm]), np.concatenate([dm, db])
        K = np.concatenate([K, K])

    zeros = np.concatenate(exact_zero)
    joined = tuple(np.concatenate([x[i] for x in brackets]) for i in range(7)) if brackets else None
    double_roots = np.concatenate(doubles) if doubles else np.empty(0)
    continua = merge_flats(np.concatenate(flats) if flats else np.empty((0, 2)), perimeter)
    return zeros, joined, double_roots, continua


def merge_flats(cells: np.ndarray, P: float) -> list[tuple[float, float]]:
    """Overlapping flat cells (start, end) merged, across σ = 0 too: (start, span) pairs, mm."""
    if len(cells) == 0:
        return []
    cells = cells[np.argsort(cells[:, 0])]
    out = [list(cells[0])]
    for a, b in cells[1:]:
        if a <= out[-1][1] + 1e-9:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    if len(out) > 1 and out[0][0] <= 1e-9 and out[-1][1] >= P - 1e-9:  # joins across σ = 0
        first = out.pop(0)
        out[-1][1] = P + first[1]
    return [(a, b - a) for a, b in out]
