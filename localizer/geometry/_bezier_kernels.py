"""A cubic Bézier's arc length inverted, compiled (numba): one Newton iteration per point in one loop.

:meth:`localizer.geometry.CubicBezier.param` finds the parameter u at arc lengths s by Newton on the
16-point Gauss-Legendre arc length from the start of u's table cell, and after a short step on the last
arc length plus the 4-point rule's over the step (a fifth of the speeds). In numpy each step built arrays of
(points × 16 nodes × 3) for the homogeneous polynomial and its derivative: most of a drawing's segment
solver on Béziers, ellipses and NURBS. Here each point is iterated on its own with the same arithmetic in
the same order (the polynomial by Horner, the speed by ``hypot``, the 16 products summed as numpy sums
them: eight running sums, then pairwise; the four in order), so the results are numpy's to the bit (tested).
"""

from __future__ import annotations

import math

import numba

from .._types import FloatArray, IntArray

__all__ = ["arc_to_param", "SHORT_STEP"]


@numba.njit(cache=True)
def _speed(coef: FloatArray, diff: FloatArray, rational: bool, u: float) -> float:
    """|C'(u)| of the Bézier: rational from the homogeneous power basis ``coef`` (4, 3), polynomial from the
    control points' differences ``diff`` (3, 2) (Bernstein form, as CubicBezier._d1)."""
    if rational:
        # the homogeneous point (x, y, w) and its derivative, by Horner, each coordinate as numpy does
        ax = ((coef[3, 0] * u + coef[2, 0]) * u + coef[1, 0]) * u + coef[0, 0]
        ay = ((coef[3, 1] * u + coef[2, 1]) * u + coef[1, 1]) * u + coef[0, 1]
        w = ((coef[3, 2] * u + coef[2, 2]) * u + coef[1, 2]) * u + coef[0, 2]
        bx = (3 * coef[3, 0] * u + 2 * coef[2, 0]) * u + coef[1, 0]
        by = (3 * coef[3, 1] * u + 2 * coef[2, 1]) * u + coef[1, 1]
        w1 = (3 * coef[3, 2] * u + 2 * coef[2, 2]) * u + coef[1, 2]
        cx, cy = ax / w, ay / w
        return math.hypot((bx - w1 * cx) / w, (by - w1 * cy) / w)
    v = 1.0 - u
    dx = 3 * v * v * diff[0, 0] + 6 * v * u * diff[1, 0] + 3 * u * u * diff[2, 0]
    dy = 3 * v * v * diff[0, 1] + 6 * v * u * diff[1, 1] + 3 * u * u * diff[2, 1]
    return math.hypot(dx, dy)


@numba.njit(cache=True)
def _gauss_to(
    coef: FloatArray, diff: FloatArray, rational: bool, gl_x: FloatArray, gl_w: FloatArray, a: float, b: float
) -> float:
    """The 16-point rule for the arc length from u = ``a`` to ``b``, summed as numpy's pairwise sum does."""
    d = b - a
    r0 = _speed(coef, diff, rational, a + d * gl_x[0]) * gl_w[0]
    r1 = _speed(coef, diff, rational, a + d * gl_x[1]) * gl_w[1]
    r2 = _speed(coef, diff, rational, a + d * gl_x[2]) * gl_w[2]
    r3 = _speed(coef, diff, rational, a + d * gl_x[3]) * gl_w[3]
    r4 = _speed(coef, diff, rational, a + d * gl_x[4]) * gl_w[4]
    r5 = _speed(coef, diff, rational, a + d * gl_x[5]) * gl_w[5]
    r6 = _speed(coef, diff, rational, a + d * gl_x[6]) * gl_w[6]
    r7 = _speed(coef, diff, rational, a + d * gl_x[7]) * gl_w[7]
    r0 += _speed(coef, diff, rational, a + d * gl_x[8]) * gl_w[8]
    r1 += _speed(coef, diff, rational, a + d * gl_x[9]) * gl_w[9]
    r2 += _speed(coef, diff, rational, a + d * gl_x[10]) * gl_w[10]
    r3 += _speed(coef, diff, rational, a + d * gl_x[11]) * gl_w[11]
    r4 += _speed(coef, diff, rational, a + d * gl_x[12]) * gl_w[12]
    r5 += _speed(coef, diff, rational, a + d * gl_x[13]) * gl_w[13]
    r6 += _speed(coef, diff, rational, a + d * gl_x[14]) * gl_w[14]
    r7 += _speed(coef, diff, rational, a + d * gl_x[15]) * gl_w[15]
    total: float = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    return total * (b - a)


@numba.njit(cache=True)
def _gauss4(
    coef: FloatArray, diff: FloatArray, rational: bool, g4_x: FloatArray, g4_w: FloatArray, a: float, b: float
) -> float:
    """The 4-point rule for the arc length from u = ``a`` to ``b`` (signed), its terms summed in order."""
    d = b - a
    total: float = _speed(coef, diff, rational, a + d * g4_x[0]) * g4_w[0]
    total += _speed(coef, diff, rational, a + d * g4_x[1]) * g4_w[1]
    total += _speed(coef, diff, rational, a + d * g4_x[2]) * g4_w[2]
    total += _speed(coef, diff, rational, a + d * g4_x[3]) * g4_w[3]
    return total * d


#: A Newton step at most this long (in u) is integrated from the last iterate by the 4-point rule, its
#: error there of the order of the step to the ninth power times the speed's eighth derivative: far below
#: 1e-12 mm. A longer one is integrated again from its cell's start by the 16-point rule.
SHORT_STEP = 1e-3


@numba.njit(cache=True)
def arc_to_param(
    coef: FloatArray,
    diff: FloatArray,
    rational: bool,
    gl_x: FloatArray,
    gl_w: FloatArray,
    g4_x: FloatArray,
    g4_w: FloatArray,
    cum: FloatArray,
    k: IntArray,
    lo: FloatArray,
    hi: FloatArray,
    arc: FloatArray,
    u: FloatArray,
) -> None:
    """Newton from the guesses ``u`` (in place) to the parameters at arc lengths ``arc`` (mm), each within
    its table cell ``k`` (``lo``..``hi``, arc ``cum[k]`` at ``lo``), until within 1e-12 mm (at most 50 steps).
    The first arc length is the 16-point rule's from the cell's start; after a short step (:data:`SHORT_STEP`)
    the last one plus the 4-point rule's over the step."""
    for i in range(arc.size):
        x = u[i]
        f = cum[k[i]] + _gauss_to(coef, diff, rational, gl_x, gl_w, lo[i], x) - arc[i]
        for _ in range(50):
            if abs(f) <= 1e-12:
                break
            step = f / max(_speed(coef, diff, rational, x), 1e-300)
            nxt = min(max(x - step, lo[i]), hi[i])
            if abs(nxt - x) <= SHORT_STEP:
                f = f + _gauss4(coef, diff, rational, g4_x, g4_w, x, nxt)
            else:
                f = cum[k[i]] + _gauss_to(coef, diff, rational, gl_x, gl_w, lo[i], nxt) - arc[i]
            x = nxt
        u[i] = x
