"""The reach table's intervals, compiled (numba): each point against every other in one loop.

:class:`localizer.Reach` asks, for each grid point P, where along the jaw laid on P's tangent the
other points of the part block it. That is every pair of points, n² of them: in numpy, in blocks of
rows, it took 0.15 s on a shipped part (1 500 points), every time a part was loaded. The loop does
the same arithmetic, element by element, in the same order (a point's place along the tangent and its
depth below the edge from its difference to P), and takes the same minima and maxima, so the
intervals are the same to the bit.
"""

from __future__ import annotations

import numba
import numpy as np

from .._types import FloatArray, IntArray

__all__ = ["reach_intervals"]


@numba.njit(cache=True)
def _blocked_by(wk: float, nearest: tuple[float, float, bool]) -> tuple[float, float, bool]:
    """The nearest blocking points ahead and behind along the tangent (mm), and whether one is at the
    contact itself, with a blocking point ``wk`` mm along it added."""
    ahead, behind, here = nearest
    if wk > 0:
        return min(ahead, wk), behind, here
    if wk < 0:
        return ahead, max(behind, wk), here
    return ahead, behind, True


@numba.njit(cache=True)
def _interval(nearest: tuple[float, float, bool], half: float) -> tuple[float, float]:
    """(lo, hi) jaw positions, mm, from the nearest blocking points (:func:`_blocked_by`); empty where one
    is at the contact."""
    ahead, behind, here = nearest
    if here:
        return np.inf, -np.inf
    return half - ahead, -half - behind


@numba.njit(cache=True)
def reach_intervals(
    pts: FloatArray,
    points: IntArray,
    tangents: FloatArray,
    origins: FloatArray,
    clearance: float,
    half: float,
    tiny: float,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(lo, hi, lo_sure, hi_sure), mm, of :meth:`localizer.Reach._intervals`.

    Parameters
    ----------
    pts : ndarray (n, 2), mm
        The grid's points in arc order round the boundary.
    points : ndarray of int (m,)
        The grid point each row starts its scan from (the point itself is column 0).
    tangents : ndarray (m, 2)
        The jaw's unit direction at each row.
    origins : ndarray (m, 2), mm
        Where the contact is at each row (the grid point, or a place near it).
    clearance, half, tiny : float, mm
        The reach's clearance, half the jaw's length, the rounding of a depth.

    Returns
    -------
    lo, hi, lo_sure, hi_sure : ndarray (m,), mm
        The generous interval (blocked only deeper than the clearance) and the sure one (also within
        it, but for the contact's own cap), the latter not yet intersected with the former.
    """
    n, m = pts.shape[0], points.size
    lo, hi = np.empty(m), np.empty(m)
    lo_sure, hi_sure = np.empty(m), np.empty(m)
    w = np.empty(n)
    dep = np.empty(n)
    for r in range(m):
        i = points[r]
        px, py = origins[r, 0], origins[r, 1]
        ex, ey = tangents[r, 0], tangents[r, 1]
        for k in range(n):
            j = (i + k) % n
            qx, qy = pts[j, 0] - px, pts[j, 1] - py
            w[k] = qx * ex + qy * ey  # along the tangent
            dep[k] = qx * ey - qy * ex  # −(Q−P)·m, m the inner normal
        # the contact's own cap: the stretch round P up to the first point clear below the edge each way
        ahead = n
        for k in range(1, n):
            if dep[k] < -clearance:
                ahead = k
                break
        behind = n
        for k in range(n - 1, 0, -1):
            if dep[k] < -clearance:
                behind = n - k
                break
        generous = (np.inf, -np.inf, False)
        sure = (np.inf, -np.inf, False)
        for k in range(n):
            wk, dk = w[k], dep[k]
            if dk > clearance:  # generous: blocked by a point deeper than the clearance
                generous = _blocked_by(wk, generous)
            cap = (k < ahead or k > n - behind) and dk <= tiny  # rising above the edge blocks
            if dk > -clearance and not cap:  # sure: also within the clearance of the edge
                sure = _blocked_by(wk, sure)
        lo[r], hi[r] = _interval(generous, half)
        lo_sure[r], hi_sure[r] = _interval(sure, half)
    return lo, hi, lo_sure, hi_sure
