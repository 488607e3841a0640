"""Numerics every part of the package shares: the full turn, angle wrapping, the curvature of a
parametric curve and Gauss–Legendre nodes on [0, 1], each defined once."""

from __future__ import annotations

from typing import TypeVar

import numpy as np

from .._types import FloatArray

_Angle = TypeVar("_Angle", float, FloatArray)

__all__ = ["TWO_PI", "wrap_angle", "mod_period", "curvature", "gauss_legendre"]

#: One full turn, rad.
TWO_PI = 2.0 * np.pi


def wrap_angle(angle: _Angle) -> _Angle:
    """Angles mapped to [−π, π), rad (arrays or scalars)."""
    wrapped: _Angle = (angle + np.pi) % TWO_PI - np.pi
    return wrapped


def mod_period(x: FloatArray, period: float) -> FloatArray:
    """``np.mod(x, period)`` to the bit, for ``period`` > 0, in a third of its time where every ``x`` is
    within a period of [0, period), as the filters' arc positions are.

    There numpy's remainder (``fmod``, then the period added to a negative remainder, and −0 made +0) is
    the value itself, the value less the period (exact: the two are within a factor of two) or the value
    plus the period; elsewhere, and for short arrays, NaN or infinities, ``np.mod`` is asked."""
    a = np.asarray(x, dtype=float)
    if a.size < 64:
        out: FloatArray = np.mod(a, period)
        return out
    if not (-period <= a.min() and a.max() < 2.0 * period):  # also false for NaN
        out = np.mod(a, period)
        return out
    out = np.where(a < 0.0, a + period, np.where(a >= period, a - period, a)) + 0.0
    return out


def curvature(dx: FloatArray, dy: FloatArray, ddx: FloatArray, ddy: FloatArray) -> FloatArray:
    """Signed curvature, 1/mm, of a curve from its first and second derivatives in any parameter."""
    v2 = dx * dx + dy * dy
    return (dx * ddy - dy * ddx) / (v2 * np.sqrt(v2))


def gauss_legendre(n: int) -> tuple[FloatArray, FloatArray]:
    """The ``n`` Gauss–Legendre nodes and weights on [0, 1] (the weights sum to 1)."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w
