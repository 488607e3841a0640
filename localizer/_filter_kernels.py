"""The grid filter's running sums, compiled (numba): one reading added in one loop.

:meth:`localizer.ContactFilter.update` adds a reading's basis row to the sums UᵀU, Uᵀz, Uᵀp, pᵀp and
zᵀp over the live hypotheses. Mid-localization a hundred or so hypotheses are live and a row has ten
columns, so in numpy the add was a dozen calls on small arrays (about 80 µs of a 150 µs update on
the 100-knot benchmark part), the arithmetic a few microseconds. The loop does the same additions
in the same order on each element, so the sums are the same to the bit. With ``sign`` -1 it takes a
reading out again (a stretch of readings the filter no longer trusts: :meth:`ContactFilter.quarantine`).
"""

from __future__ import annotations

import numba

from ._types import BoolArray, FloatArray, IntArray

__all__ = ["add_row"]


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
