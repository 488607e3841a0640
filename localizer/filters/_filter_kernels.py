"""The grid filter's running sums, compiled (numba): one reading added in one loop.

:meth:`localizer.ContactFilter.update` adds a reading's basis row to the sums UᵀU, Uᵀz, Uᵀp, pᵀp and
zᵀp over the live hypotheses. Mid-localization a hundred or so hypotheses are live and a row has ten
columns, so in numpy the add was a dozen calls on small arrays (about 80 µs of a 150 µs update on
the 100-knot benchmark part), the arithmetic a few microseconds. The loop does the same additions
in the same order on each element, so the sums are the same to the bit. With ``sign`` -1 it takes a
reading out again (a stretch of readings the filter no longer trusts: :meth:`ContactFilter.quarantine`).

:func:`weigh_scales` weighs the unknown noise scale out of every start's likelihood on the grid of scales:
in numpy a (scales × starts) array of exponentials and four temporaries per call, which with ten thousand
starts live early in a rolling, and a stretch envelope asking for a dozen such solves, was most of a belief.

:func:`gather` takes the sums of the live starts over the touched basis columns, element by element: numpy's
row gather copied every start's sums before it took the live ones (three times the time with a thousand of
ten thousand starts live). A copy, so the same numbers.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._types import BoolArray, FloatArray, IntArray

__all__ = ["add_row", "gather", "weigh_scales"]

#: Terms this many nats below the largest are left out of a sum of exponentials (e⁻⁵⁰ ≈ 2·10⁻²²).
UNDERFLOW = 50.0


@numba.njit(cache=True)
def add_row(
    up: FloatArray,
    uu: FloatArray,
    uz: FloatArray,
    spp: FloatArray,
    szp: FloatArray,
    touched: BoolArray,
    cols: IntArray,
    vals: FloatArray,
    idx: IntArray,
    p: FloatArray,
    z: float,
    sign: float = 1.0,
) -> None:
    """Add one weighted reading to the sums, in place (``sign`` -1: take it out again).

    Parameters
    ----------
    up, uu, uz : ndarray (m, n), (m, m), (m,)
        Uᵀp per hypothesis, UᵀU and Uᵀz.
    spp, szp : ndarray (n,)
        pᵀp and zᵀp per hypothesis.
    touched : ndarray of bool (m,)
        The basis columns any reading has used.
    cols, vals : ndarray (r,)
        The row's basis columns (distinct) and values (weighted).
    idx, p : ndarray (k,)
        The live hypotheses and their weighted predictions (mm).
    z : float
        The weighted reading (mm).
    sign : float
        1 to add the reading, -1 to remove one added before (the sums then are as if it never had been,
        up to rounding).
    """
    for a in range(cols.size):
        ca = cols[a]
        va = vals[a]
        for k in range(idx.size):
            up[ca, idx[k]] += sign * (va * p[k])
        touched[ca] = True
    for k in range(idx.size):
        i = idx[k]
        spp[i] += sign * (p[k] * p[k])
        szp[i] += sign * (z * p[k])
    for a in range(cols.size):
        ca = cols[a]
        uz[ca] += sign * (vals[a] * z)
        for b in range(cols.size):
            uu[ca, cols[b]] += sign * (vals[a] * vals[b])


@numba.njit(cache=True)
def weigh_scales(quad: FloatArray, k: FloatArray, lam: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The likelihood of each start with the noise scale λ weighed out over a uniform grid of scales.

    With every standard deviation times λ, a start whose readings' quadratic form is q (in units of the
    told variance) over k readings not absorbed by a flat offset has log-likelihood −q/(2λ²) − k·log λ
    (up to a constant).

    Parameters
    ----------
    quad : ndarray (r, n)
        The quadratic form of each of n starts, in each of r sets of readings.
    k : ndarray (r,)
        The readings counted in each set.
    lam : ndarray (s,)
        The grid of scales (factors on the told noise).

    Returns
    -------
    log_mean, lam2 : ndarray (r, n)
        The log of the mean over the grid of exp(−q/(2λ²) − k·log λ), and the posterior mean of λ².
    """
    rows, n = quad.shape
    inv = 1.0 / lam**2
    log_lam = np.log(lam)
    log_mean = np.empty((rows, n))
    lam2 = np.empty((rows, n))
    for i in range(rows):
        for j in range(n):
            q = quad[i, j]
            top = -math.inf
            for m in range(lam.size):
                top = max(top, -0.5 * q * inv[m] - k[i] * log_lam[m])
            total = 0.0
            second = 0.0
            for m in range(lam.size):
                t = -0.5 * q * inv[m] - k[i] * log_lam[m] - top
                if t > -UNDERFLOW:  # the rest add less than a rounding of the total, which is at least 1
                    e = math.exp(t)
                    total += e
                    second += e * lam[m] ** 2
            log_mean[i, j] = top + math.log(total / lam.size)
            lam2[i, j] = second / total
    return log_mean, lam2


@numba.njit(cache=True)
def gather(a: FloatArray, rows: IntArray, cols: IntArray) -> FloatArray:
    """``a[rows][:, cols]``, without the rows' copy.

    Parameters
    ----------
    a : ndarray (m, n)
    rows, cols : ndarray of int (r,), (c,)
        Indices into a's rows and columns.

    Returns
    -------
    ndarray (r, c)
    """
    out = np.empty((rows.size, cols.size))
    for i in range(rows.size):
        row = a[rows[i]]
        for j in range(cols.size):
            out[i, j] = row[cols[j]]
    return out
