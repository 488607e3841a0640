"""The rolling tracks' step, compiled (numba): every hypothesis moved along its convex stretch in one loop.

:meth:`localizer.Tracks.step` moves each live hypothesis' contact by the jaw's net turn: the target
angle on its stretch's banded angle table, a binary search there, and a linear interpolation of the
arc. Mid-localization about a hundred hypotheses are live, and in numpy the step was two dozen
calls on arrays that small (about 40 µs of a grid filter update). The loop does the same arithmetic,
element by element, in the same order, so the results are the same to the bit.
"""

from __future__ import annotations

import numba
import numpy as np

from .._types import BoolArray, FloatArray, IntArray

__all__ = ["step_along"]


@numba.njit(cache=True)
def _leftmost(banded: FloatArray, target: float, lo: int, hi: int, hint: int) -> int:
    """The first entry of ``banded[lo:hi + 1]`` (sorted) at or above ``target`` (``banded[hi]`` is), found by
    galloping from ``hint`` and halving the bracket: the entry ``np.searchsorted(..., side="left")`` gives."""
    h = min(max(hint, lo), hi)
    step = 1
    if banded[h] >= target:  # at or before h: gallop back to an entry below the target
        right = h
        left = h
        while True:
            left = right - step
            if left <= lo:
                left = lo
                break
            if banded[left] < target:
                break
            right = left
            step *= 2
        if banded[left] >= target:  # only at lo: nothing before it is searched
            return left
    else:  # after h: gallop on to an entry at or above it
        left = h
        right = h
        while True:
            right = left + step
            if right >= hi:
                right = hi
                break
            if banded[right] >= target:
                break
            left = right
            step *= 2
    # banded[left] < target <= banded[right]
    while right - left > 1:
        mid = (left + right) // 2
        if banded[mid] >= target:
            right = mid
        else:
            left = mid
    return right


@numba.njit(cache=True)
def step_along(
    idx: IntArray,
    turn: FloatArray,
    turn_margin: float,
    theta: FloatArray,
    run_of: IntArray,
    span: float,
    first_of: IntArray,
    last_of: IntArray,
    banded: FloatArray,
    convex: BoolArray,
    s: FloatArray,
    node_of: IntArray,
    entry: IntArray,
) -> tuple[FloatArray, IntArray, BoolArray, IntArray, FloatArray]:
    """The raw step of :meth:`localizer.Tracks.step` (before a face's centre of pressure and the
    no-turn and out-of-stretch masks).

    Parameters
    ----------
    idx : ndarray of int (n,)
        Grid points the rotation starts from.
    turn : ndarray (1,) or (n,), rad
        Net rotation, one for all or one per point.
    turn_margin : float, rad
        How far past its stretch's end a rotation may go and still keep the point.
    theta, run_of, span, first_of, last_of, banded, convex, s, node_of, entry
        The tracks' tables: each grid point's angle and run, the runs' angle offset, each run's
        first and last entry in the banded table, the banded angles, convexity, arcs and nodes, and
        each grid point's own entry (where the search for its landing starts: a roll moves the
        contact a few entries, and a search from there is a few steps where one over the whole
        table was many, each to a far-off place in memory).

    Returns
    -------
    arc, node, ok, j, target
        The landing's arc (mm, unwrapped) and nearest node, whether it is on the stretch, the
        banded entry above it and the clipped target angle (rad).
    """
    n = idx.size
    arc = np.empty(n)
    node = np.empty(n, np.int64)
    ok = np.empty(n, np.bool_)
    jj = np.empty(n, np.int64)
    target_out = np.empty(n)
    for k in range(n):
        i = idx[k]
        run = run_of[i]
        t = turn[0] if turn.size == 1 else turn[k]
        target = theta[i] + t + run * span
        first, last = first_of[run], last_of[run]
        lo_b, hi_b = banded[first], banded[last]
        ok[k] = convex[i] and (target >= lo_b - turn_margin) and (target <= hi_b + turn_margin)
        target = min(max(target, lo_b), hi_b)
        j = max(_leftmost(banded, target, first, last, entry[i]), first + 1)
        b0, b1 = banded[j - 1], banded[j]
        w = (target - b0) / (b1 - b0 if b1 > b0 else 1.0)
        arc[k] = s[j - 1] + w * (s[j] - s[j - 1])
        node[k] = node_of[j - 1] if w < 0.5 else node_of[j]
        jj[k] = j
        target_out[k] = target
    return arc, node, ok, jj, target_out
