"""A proved bound of how fast a Bézier's curvature changes along it, from Bernstein coefficients.

The outline solver's certificate needs, on each cell, a bound of |g''| = |κ'(σ + L) − κ'(σ)|, κ' the
curvature's derivative by arc length. For a cubic Bézier with weights (rational, or all equal) in
homogeneous form (X, Y, W)(u), polynomials of degree three in the parameter u:

    r' × r'' = D / W³,   D = det[(X, Y, W); (X', Y', W'); (X'', Y'', W'')],
    |r'|     = √Q / W²,  Q = A² + B²,  A = X'W − XW',  B = Y'W − YW',
    κ        = D·W³ / Q^(3/2),
    dκ/ds    = (dκ/du) / |r'| = W²·((D·W³)'·Q − 3/2·D·W³·Q') / Q³.

Numerator N = W²·((DW³)'Q − 3/2·DW³Q') and Q are polynomials in u; over an interval of u each is
between its least and greatest Bernstein coefficient on that interval (the Bernstein basis is a
partition of unity with non-negative terms). So |dκ/ds| ≤ max|b(N)| / (min b(Q))³ wherever min b(Q)
> 0, which holds on short enough intervals of a piece that never stops (Q > 0 on it). Nothing is
sampled: the bound holds over the whole interval, up to the rounding of the coefficients, which a
relative cushion of :data:`ROUNDING` covers. The coordinates are first moved to the first control
point and divided by the piece's size, so that the coefficients are of order one.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import polynomial as poly
from scipy.special import comb

from .._types import FloatArray
from ..geometry import CubicBezier

__all__ = ["kappa_slope_bound", "ROUNDING"]

#: Relative cushion on the bound for the rounding of the polynomials' coefficients (their Bernstein
#: conversion sums terms of up to C(n, n/2) times the result's size at degree n ≤ 30: 1.6e8 × 2e-16).
ROUNDING = 1e-6

# the cubic Bernstein basis in powers of u (rows: B0..B3; columns: 1, u, u², u³)
_CUBIC = np.array(
    [
        [1.0, -3.0, 3.0, -1.0],
        [0.0, 3.0, -6.0, 3.0],
        [0.0, 0.0, 3.0, -3.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
)


def _polynomials(piece: CubicBezier) -> tuple[FloatArray, FloatArray, float]:
    """(N, Q, size): the numerator and Q of dκ/ds = N/Q³ in powers of u, for the piece moved to its first
    control point and divided by ``size`` (mm); dκ/ds of the piece itself is that over size²."""
    pts = np.array([piece.p0, piece.p1, piece.p2, piece.p3], dtype=float)
    pts = pts - pts[0]
    size = float(np.abs(pts).max()) or 1.0
    pts = pts / size
    w = np.asarray(piece.weights, dtype=float)
    w = w / w.max()
    X = (w * pts[:, 0]) @ _CUBIC
    Y = (w * pts[:, 1]) @ _CUBIC
    W = w @ _CUBIC
    X1, Y1, W1 = poly.polyder(X), poly.polyder(Y), poly.polyder(W)
    X2, Y2, W2 = poly.polyder(X, 2), poly.polyder(Y, 2), poly.polyder(W, 2)
    mul, sub, add = poly.polymul, poly.polysub, poly.polyadd
    D = add(
        sub(mul(X, sub(mul(Y1, W2), mul(W1, Y2))), mul(Y, sub(mul(X1, W2), mul(W1, X2)))),
        mul(W, sub(mul(X1, Y2), mul(Y1, X2))),
    )
    A = sub(mul(X1, W), mul(X, W1))
    B = sub(mul(Y1, W), mul(Y, W1))
    Q = add(mul(A, A), mul(B, B))
    DW3 = mul(D, mul(W, mul(W, W)))
    M = sub(mul(poly.polyder(DW3), Q), 1.5 * mul(DW3, poly.polyder(Q)))
    N = mul(mul(W, W), M)
    return poly.polytrim(N, 0.0), poly.polytrim(Q, 0.0), size


def _bernstein(coef: FloatArray, u0: FloatArray, u1: FloatArray) -> FloatArray:
    """Bernstein coefficients (rows: intervals) of the polynomial ``coef`` (powers of u) on [u0, u1]."""
    n = coef.size - 1
    h = u1 - u0
    # Taylor shift to the interval's start, scaled to its length: c_j = h^j Σ_k C(k, j) a_k u0^(k−j)
    powers = u0[:, None] ** np.arange(n + 1)
    c = np.empty((u0.size, n + 1))
    for j in range(n + 1):
        k = np.arange(j, n + 1)
        c[:, j] = (powers[:, : n + 1 - j] @ (comb(k, j) * coef[j:])) * h**j
    # powers of the local variable to Bernstein: b_k = Σ_{j ≤ k} C(k, j) / C(n, j) c_j
    rows, cols = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    to_bernstein = np.where(rows <= cols, comb(cols, rows) / comb(n, rows), 0.0)
    result: FloatArray = c @ to_bernstein
    return result


def kappa_slope_bound(piece: CubicBezier, u0: FloatArray, u1: FloatArray, depth: int = 6) -> FloatArray:
    """A bound of |dκ/ds| (1/mm²) over each parameter interval [u0_i, u1_i] of ``piece``.

    Parameters
    ----------
    piece : CubicBezier
    u0, u1 : ndarray
        The intervals' ends in the piece's parameter, 0 ≤ u0 ≤ u1 ≤ 1.
    depth : int
        Halvings allowed where an interval is too long for its Bernstein coefficients of Q to be
        positive (each halving takes the larger of the two halves' bounds).

    Returns
    -------
    ndarray
        One bound per interval, ≥ the largest |dκ/ds| on it.
    """
    N, Q, size = _polynomials(piece)
    bound = _bound(N, Q, np.asarray(u0, dtype=float), np.asarray(u1, dtype=float), depth)
    result: FloatArray = bound * (1.0 + ROUNDING) / size**2
    return result


def _bound(N: FloatArray, Q: FloatArray, u0: FloatArray, u1: FloatArray, depth: int) -> FloatArray:
    """max|b(N)| / (min b(Q))³ per interval, halving where min b(Q) ≤ 0 (inf when ``depth`` runs out)."""
    bn = np.abs(_bernstein(N, u0, u1)).max(axis=1)
    bq = _bernstein(Q, u0, u1).min(axis=1)
    out = np.full(u0.shape, np.inf)
    ok = bq > 0
    out[ok] = bn[ok] / bq[ok] ** 3
    bad = np.flatnonzero(~ok)
    if bad.size and depth > 0:
        mid = 0.5 * (u0[bad] + u1[bad])
        out[bad] = np.maximum(_bound(N, Q, u0[bad], mid, depth - 1), _bound(N, Q, mid, u1[bad], depth - 1))
    return out
