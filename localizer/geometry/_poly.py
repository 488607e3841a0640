"""Vectorized polynomial helpers: Horner evaluation and Bernstein range bounds.

Polynomials are stored with *ascending* power coefficients in the last axis,
``p(u) = c[..., 0] + c[..., 1] u + ... + c[..., n] u**n``.
"""

from math import comb

import numpy as np

from .._types import FloatArray

__all__ = ["horner", "poly_mul", "poly_der", "bernstein_bounds"]


def horner(coef: FloatArray, u: FloatArray | float) -> FloatArray:
    """Evaluate polynomials ``coef`` (shape (..., n+1), ascending) at ``u`` (broadcast with ``coef[..., 0]``)."""
    out = coef[..., -1]
    for k in range(coef.shape[-1] - 2, -1, -1):
        out = out * u + coef[..., k]
    return out


def poly_mul(a: FloatArray, b: FloatArray) -> FloatArray:
    """Product of two stacks of ascending polynomials (shapes (M, p+1), (M, q+1))."""
    p, q = a.shape[-1], b.shape[-1]
    out = np.zeros(a.shape[:-1] + (p + q - 1,))
    for i in range(p):
        out[..., i : i + q] += a[..., i : i + 1] * b
    return out


def poly_der(a: FloatArray) -> FloatArray:
    """Derivative of a stack of ascending polynomials."""
    n = a.shape[-1]
    if n == 1:
        return np.zeros_like(a)
    return a[..., 1:] * np.arange(1, n)


def bernstein_bounds(coef: FloatArray, u0: FloatArray, u1: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Guaranteed lower and upper bounds of polynomials over intervals.

    Parameters
    ----------
    coef : ndarray, shape (M, n+1)
        Ascending power coefficients, one polynomial per row.
    u0, u1 : ndarray, shape (M,)
        Interval ends, ``u0 <= u1``.

    Returns
    -------
    lo, hi : ndarray, shape (M,)
        ``lo <= p(u) <= hi`` for every ``u`` in ``[u0, u1]`` (the range of the
        Bernstein coefficients on that interval, widened by a few ulps of
        the coefficients' magnitude to absorb rounding).
    """
    coef = np.asarray(coef, dtype=float)
    u0 = np.asarray(u0, dtype=float)
    w = np.asarray(u1, dtype=float) - u0
    n = coef.shape[-1] - 1
    # Taylor shift to u0, then scale by w: q(v) = p(u0 + w v) = sum b_k v^k.
    b = coef.copy()
    for k in range(n):
        for i in range(n - 1, k - 1, -1):
            b[..., i] += u0 * b[..., i + 1]
    scale = np.ones_like(w)
    for k in range(1, n + 1):
        scale = scale * w
        b[..., k] *= scale
    # Power basis on [0, 1] -> Bernstein coefficients.
    beta = np.empty_like(b)
    for j in range(n + 1):
        acc = np.zeros(b.shape[:-1])
        for k in range(j + 1):
            acc = acc + (comb(j, k) / comb(n, k)) * b[..., k]
        beta[..., j] = acc
    slack = 1e-13 * np.abs(beta).max(axis=-1) + 1e-300
    return beta.min(axis=-1) - slack, beta.max(axis=-1) + slack
