"""What the filter, the jaw's reach and the rolling need of a part's boundary, whatever it is made of.

Two kinds of boundary exist: the C2 spline through a point file (:class:`localizer.Part`) and the
chain of exact pieces read from CAD (:class:`localizer.Outline`). Both are functions of the arc
position σ (mm, from the first point, counter-clockwise); the tangent angle θ(σ) is unwrapped (it
grows by 2π a lap) and, on an outline, jumps at a corner. :class:`Boundary` names that common
interface, and :class:`ArcPositions` holds the arithmetic of arc positions they share.
"""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any, Protocol

import numpy as np

from .._types import ArrayLike, FloatArray
from ._numerics import mod_period

__all__ = ["Boundary", "ArcPositions"]


class Boundary(Protocol):
    """A closed counter-clockwise boundary by arc position (a :class:`Part` or an :class:`Outline`).

    Attributes
    ----------
    name : str
    perimeter : float, mm
    """

    @property
    def name(self) -> str: ...

    @property
    def perimeter(self) -> float: ...

    @property
    def _tables(self) -> dict[tuple[str, Hashable], Any]:
        """The tables built from the boundary (:func:`localizer.geometry._cache.per_part`)."""
        ...

    @property
    def corners(self) -> tuple[Any, ...]:
        """Where the tangent jumps: :class:`localizer.Corner` (arc mm, exterior angle rad), by arc."""
        ...

    def point_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """Points at arc positions ``sigma`` (mm), shape (..., 2), mm."""
        ...

    def tangent_angle_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """Unwrapped tangent angle at ``sigma`` (mm), rad; after the jump at a corner."""
        ...

    def curvature_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """Signed curvature at ``sigma`` (mm), 1/mm."""
        ...

    def wrap_arc(self, sigma: ArrayLike) -> FloatArray:
        """Arc positions ``sigma`` (mm) reduced to [0, perimeter)."""
        ...

    def arc_offset(self, a: ArrayLike, b: ArrayLike) -> FloatArray:
        """Signed shortest offset from ``b`` to ``a`` around the boundary, mm."""
        ...

    def forget_tables(self) -> None:
        """Drop the tables built from this boundary."""
        ...


class ArcPositions:
    """Arithmetic of arc positions on a closed boundary of length ``perimeter`` (mm)."""

    perimeter: float
    _tables: dict[tuple[str, Hashable], Any]

    def wrap_arc(self, sigma: ArrayLike) -> FloatArray:
        """Arc positions ``sigma`` (mm) reduced to ``[0, perimeter)``."""
        w = mod_period(np.asarray(sigma, dtype=float), self.perimeter)
        wrapped: FloatArray = np.where(w >= self.perimeter, 0.0, w)
        return wrapped

    def arc_offset(self, a: ArrayLike, b: ArrayLike) -> FloatArray:
        """Signed shortest offset from arc position ``b`` to ``a`` around the boundary, mm.

        In ``[-perimeter/2, perimeter/2)``; its absolute value is the distance
        along the boundary.
        """
        half = 0.5 * self.perimeter
        offset: FloatArray = (
            mod_period(np.asarray(a, dtype=float) - np.asarray(b, dtype=float) + half, self.perimeter) - half
        )
        return offset

    def forget_tables(self) -> None:
        """Drop the tables built for this boundary by the solvers and filters (the march's grid takes
        72 MB per million cells); they are built again when next needed."""
        self._tables.clear()
