"""Numerics every part of the package shares: the full turn, angle wrapping, the curvature of a
parametric curve and Gauss–Legendre nodes on [0, 1], each defined once."""

from __future__ import annotations

from typing import TypeVar

import numpy as np

from .._types import FloatArray

_Angle = TypeVar("_Angle", float, FloatArray)

__all__ = ["TWO_PI", "wrap_angle", "curvature", "gauss_legendre"]

#: One full turn, rad.
TWO_PI = 2.0 * np.pi


def wrap_angle(angle: _Angle) -> _Angle:
    """Angles mapped to [−π, π), rad (arrays or scalars)."""
    wrapped: _Angle = (angle + np.pi) % TWO_PI - np.pi
    return wrapped


def curvature(dx: FloatArray, dy: FloatArray, ddx: FloatArray, ddy: FloatArray) -> FloatArray:
    """Signed curvature, 1/mm, of a curve from its first and second derivatives in any parameter."""
    v2 = dx * dx + dy * dy
    return (dx * ddy - dy * ddx) / (v2 * np.sqrt(v2))


def gauss_legendre(n: int) -> tuple[FloatArray, FloatArray]:
    """The ``n`` Gauss–Legendre nodes and weights on [0, 1] (the weights sum to 1)."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w
