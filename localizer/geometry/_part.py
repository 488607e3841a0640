"""The part model: a closed C2 cubic spline through the part's points.

Knot ``i`` sits at parameter ``i``; the domain is ``[0, N)`` and the curve is
periodic, so every function here accepts *unrolled* parameters (any real
``t``; ``t + N`` is the same point one lap further on). Along the unrolled
curve, arc length and tangent angle grow by the perimeter and by ``2*pi``
per lap, which makes arc length ℓ(s, t) and total curvature Φ(s, t) plain
differences, for segments that wrap past the first point too.

Lengths are in millimetres, angles in radians, arc positions are measured
counter-clockwise from the first point.
"""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.interpolate import CubicSpline

from .._errors import PartError, QueryError
from .._types import ArrayLike, FloatArray, IntArray
from ._boundary import ArcPositions
from ._numerics import TWO_PI, curvature, gauss_legendre, wrap_angle
from ._poly import bernstein_bounds, horner, poly_der, poly_mul

__all__ = ["Part", "part_from_points", "polygon_crossing", "UNITS_TO_MM"]

#: Length units a part file may declare, and their size in millimetres.
UNITS_TO_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "um": 1e-3}

# Gauss-Legendre nodes on [0, 1]: 16 for whole table cells, 8 for partial ones.
_GL16_X, _GL16_W = gauss_legendre(16)
_GL8_X, _GL8_W = gauss_legendre(8)


@dataclass(frozen=True, eq=False)
class Part(ArcPositions):
    """A part's boundary: the closed, counter-clockwise C2 cubic spline through its points.

    Build one with :func:`load_part` or :func:`part_from_points`, which
    validate their input; the constructor trusts it.

    Parameters
    ----------
    points : ndarray, shape (N, 2), mm
        Knots in counter-clockwise order, first point first.
    name : str
        A name for messages and plots.
    cells_per_piece : int
        Table resolution: each spline piece is split into this many cells
        for the arc-length table and the solver's grid.

    Attributes
    ----------
    n_knots : int
        N, the number of knots; parameters run over ``[0, N)``.
    perimeter : float, mm
        Arc length of the whole boundary.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    >>> part = part_from_points(np.c_[30 * np.cos(a), 20 * np.sin(a)], name="ellipse")
    >>> round(part.perimeter, 3)  # Ramanujan: 158.654 for the true ellipse
    158.654
    >>> float(part.total_curvature(0.0, 64.0))  # one lap turns by 2 pi
    6.283185307179586
    """

    points: FloatArray
    name: str = "part"
    cells_per_piece: int = 4
    n_knots: int = field(init=False)
    perimeter: float = field(init=False)
    # the spline's polynomial coefficients per piece and its cell tables, built once here
    _cx: FloatArray = field(init=False, repr=False)  # x(u), ascending powers, (N, 4)
    _cy: FloatArray = field(init=False, repr=False)
    _num: FloatArray = field(init=False, repr=False)  # x'y'' − y'x''
    _den: FloatArray = field(init=False, repr=False)  # |α'|²
    _dkappa: FloatArray = field(init=False, repr=False)  # numerator of dκ/dt·den^2.5
    _dcols: FloatArray = field(init=False, repr=False)  # x', y' coefficients as rows (6, N)
    _t_nodes: FloatArray = field(init=False, repr=False)  # cell boundaries: parameter
    _sig_nodes: FloatArray = field(init=False, repr=False)  # ... arc position, mm
    _theta_nodes: FloatArray = field(init=False, repr=False)  # ... unwrapped tangent angle, rad
    _dtds_nodes: FloatArray = field(init=False, repr=False)  # ... dt/dσ, 1/mm
    _kappa_abs: FloatArray = field(init=False, repr=False)  # bound on |κ| per cell, 1/mm
    _turning: float = field(init=False, repr=False)  # total turning, rad (2π for a simple outline)
    # tables the solvers and filters build per part (localizer.geometry._cache.per_part); freed with the part
    _tables: dict[tuple[str, Hashable], Any] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_tables", {})
        pts = np.array(self.points, dtype=float)
        pts.setflags(write=False)
        object.__setattr__(self, "points", pts)
        n = len(pts)
        object.__setattr__(self, "n_knots", n)
        closed = np.vstack([pts, pts[:1]])
        spline = CubicSpline(np.arange(n + 1, dtype=float), closed, bc_type="periodic")
        # Ascending coefficients per piece: (N, 4) for x and for y.
        cx = spline.c[::-1, :, 0].T.copy()
        cy = spline.c[::-1, :, 1].T.copy()
        dx, dy = poly_der(cx), poly_der(cy)
        ddx, ddy = poly_der(dx), poly_der(dy)
        num = poly_mul(dx, ddy) - poly_mul(dy, ddx)  # x'y'' - y'x''
        den = poly_mul(dx, dx) + poly_mul(dy, dy)  # |alpha'|^2
        dkappa = poly_mul(poly_der(num), den) - 1.5 * poly_mul(num, poly_der(den))
        object.__setattr__(self, "_cx", cx)
        object.__setattr__(self, "_cy", cy)
        object.__setattr__(self, "_num", num)
        object.__setattr__(self, "_den", den)
        object.__setattr__(self, "_dkappa", dkappa)
        # x', y' coefficients as rows (6, N): gathering 1-D rows is the fast path
        object.__setattr__(self, "_dcols", np.ascontiguousarray(np.hstack([dx, dy]).T))
        self._build_table(int(self.cells_per_piece))

    # ------------------------------------------------------------------ tables
    def _build_table(self, m: int) -> None:
        """Cumulative arc length and unwrapped tangent angle on a cell grid (each cell turns < 1 rad)."""
        n = self.n_knots
        while True:
            j = np.arange(n * m)
            piece = j // m
            u0 = (j % m) / m
            u1 = u0 + 1.0 / m
            dlo, _ = bernstein_bounds(self._den[piece], u0, u1)
            if np.any(dlo <= 0.0):
                # The Bernstein bound is loose or the speed really vanishes.
                bad = int(np.argmin(dlo))
                fine = self._speed_piece(piece[bad], np.linspace(u0[bad], u1[bad], 257))
                if fine.min() < 1e-9 * max(1.0, np.ptp(self.points)):
                    raise PartError(
                        f"part {self.name!r}: the spline stops (zero speed, a cusp) near "
                        f"parameter {piece[bad] + fine.argmin() / 256 / m + u0[bad] - piece[bad]:.3f}; "
                        "space the points more evenly"
                    )
                if m >= 256:
                    raise PartError(f"part {self.name!r}: speed bound failed near parameter {j[bad] / m:.3f}")
                m *= 2
                continue
            nlo, nhi = bernstein_bounds(self._num[piece], u0, u1)
            kappa_abs = np.maximum(np.abs(nlo), np.abs(nhi)) / dlo**1.5
            # cell arc lengths
            uu = u0[:, None] + (u1 - u0)[:, None] * _GL16_X
            sp = self._speed_piece(piece[:, None], uu)
            dsig = (sp * _GL16_W).sum(axis=1) * (u1 - u0)
            if np.all(kappa_abs * dsig < 1.0) or m >= 256:
                break
            m *= 2
        object.__setattr__(self, "cells_per_piece", m)
        sig = np.concatenate([[0.0], np.cumsum(dsig)])
        perimeter = float(sig[-1])
        object.__setattr__(self, "perimeter", perimeter)
        t_nodes = np.arange(n * m + 1) / m
        node_piece = np.minimum(t_nodes.astype(int), n - 1)
        dxn, dyn, _, _ = self.derivatives(node_piece, t_nodes - node_piece)
        raw = np.arctan2(dyn, dxn)
        theta = raw[0] + np.concatenate([[0.0], np.cumsum(wrap_angle(np.diff(raw)))])
        turning = theta[-1] - theta[0]
        object.__setattr__(self, "_t_nodes", t_nodes)
        object.__setattr__(self, "_sig_nodes", sig)
        object.__setattr__(self, "_theta_nodes", theta)
        object.__setattr__(self, "_turning", float(turning))
        object.__setattr__(self, "_kappa_abs", kappa_abs)
        v_nodes = np.hypot(dxn, dyn)
        object.__setattr__(self, "_dtds_nodes", 1.0 / v_nodes)

    # ---------------------------------------------- evaluation for the solvers
    # The exact solver, the march, the arc tables and the disambiguation evaluate the spline
    # piece by piece through these four, and through nothing else of its inside.
    def derivatives(
        self, piece: IntArray | int, u: FloatArray | float
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """x', y', x'', y'' of spline pieces ``piece`` (int) at local parameters ``u`` in [0, 1]
        (broadcast), mm per unit parameter and per unit parameter squared."""
        c = self._dcols[:, piece]
        dx = (c[2] * u + c[1]) * u + c[0]
        dy = (c[5] * u + c[4]) * u + c[3]
        return dx, dy, 2.0 * c[2] * u + c[1], 2.0 * c[5] * u + c[4]

    def curvature_slope(self, piece: IntArray | int, u: FloatArray | float) -> FloatArray:
        """dκ/dσ, 1/mm², of spline pieces ``piece`` at local parameters ``u`` (broadcast)."""
        den = horner(self._den[piece], u)
        return horner(self._dkappa[piece], u) / (den * den * den)

    @property
    def corners(self) -> tuple[()]:
        """A C2 spline has no corners (the interface it shares with :class:`localizer.Outline`)."""
        return ()

    @property
    def curvature_bound(self) -> float:
        """An upper bound on |κ| over the whole boundary, 1/mm (from the cells' Bernstein bounds)."""
        return float(np.abs(self._kappa_abs).max())

    def _speed_piece(self, piece: IntArray | int, u: FloatArray | float) -> FloatArray:
        c = self._dcols[:, piece]
        speed: FloatArray = np.hypot((c[2] * u + c[1]) * u + c[0], (c[5] * u + c[4]) * u + c[3])
        return speed

    # --------------------------------------------------------------- locating
    def _split(self, t: ArrayLike) -> tuple[FloatArray, IntArray, FloatArray, IntArray]:
        """Unrolled parameter -> (lap, piece, u in [0, 1), cell index)."""
        t = np.asarray(t, dtype=float)
        n = self.n_knots
        lap = np.floor(t / n)
        tt = t - lap * n
        piece = np.minimum(tt.astype(np.int64), n - 1)
        u = tt - piece
        cell = np.minimum((tt * self.cells_per_piece).astype(np.int64), n * self.cells_per_piece - 1)
        return lap, piece, u, cell

    # -------------------------------------------------------- functions of t
    def point(self, t: ArrayLike) -> FloatArray:
        """Boundary point at parameter ``t``; shape ``t.shape + (2,)``, mm."""
        _, piece, u, _ = self._split(t)
        return np.stack([horner(self._cx[piece], u), horner(self._cy[piece], u)], axis=-1)

    def derivative(self, t: ArrayLike) -> FloatArray:
        """Curve derivative dα/dt at ``t``; shape ``t.shape + (2,)``, mm per unit parameter."""
        _, piece, u, _ = self._split(t)
        dx, dy, _, _ = self.derivatives(piece, u)
        return np.stack([dx, dy], axis=-1)

    def speed(self, t: ArrayLike) -> FloatArray:
        """Curve speed ``|dα/dt|`` at ``t``, mm per unit parameter."""
        _, piece, u, _ = self._split(t)
        return self._speed_piece(piece, u)

    def tangent(self, t: ArrayLike) -> FloatArray:
        """Unit tangent (counter-clockwise direction) at ``t``; shape ``t.shape + (2,)``."""
        d = self.derivative(t)
        unit: FloatArray = d / np.linalg.norm(d, axis=-1, keepdims=True)
        return unit

    def normal(self, t: ArrayLike) -> FloatArray:
        """Unit outward normal at ``t`` (the tangent turned clockwise)."""
        tg = self.tangent(t)
        return np.stack([tg[..., 1], -tg[..., 0]], axis=-1)

    def tangent_angle(self, t: ArrayLike) -> FloatArray:
        """Unwrapped tangent angle θ(t), rad, at unrolled parameters ``t``: continuous, θ(t + N) = θ(t) + 2π."""
        lap, piece, u, cell = self._split(t)
        dx, dy, _, _ = self.derivatives(piece, u)
        return self._unwrap(np.arctan2(dy, dx), cell, lap)

    def _unwrap(self, raw: FloatArray, cell: IntArray, lap: FloatArray) -> FloatArray:
        """Unwrapped angle from atan2 ``raw``: the cell's start angle turns < 1 rad across the cell."""
        base = self._theta_nodes[cell]
        return base + wrap_angle(raw - base) + TWO_PI * lap

    def curvature(self, t: ArrayLike) -> FloatArray:
        """Signed curvature κ(t), 1/mm, at unrolled parameters ``t``: positive where the boundary is convex."""
        _, piece, u, _ = self._split(t)
        return curvature(*self.derivatives(piece, u))

    def arc_at_param(self, t: ArrayLike) -> FloatArray:
        """Unrolled arc position Λ(t) = ℓ(0, t), mm, at unrolled parameters ``t`` (grows by the perimeter per lap)."""
        lap, piece, u, cell = self._split(t)
        return self._sig_nodes[cell] + self._partial_arc(piece, cell, u) + self.perimeter * lap

    def _partial_arc(self, piece: IntArray, cell: IntArray, u: FloatArray) -> FloatArray:
        """Arc length from the start of ``cell`` to ``u`` within ``piece``."""
        u0 = (cell - piece * self.cells_per_piece) / self.cells_per_piece
        w = u - u0
        uu = u0[..., None] + w[..., None] * _GL8_X
        arc: FloatArray = (self._speed_piece(piece[..., None], uu) * _GL8_W).sum(axis=-1) * w
        return arc

    def arc_length(self, s: ArrayLike, t: ArrayLike) -> FloatArray:
        """Arc length ℓ(s, t) of the counter-clockwise stretch from ``s`` to ``t``, mm.

        Parameters are unrolled; when ``t < s`` the stretch wraps past the
        first point (``t`` is taken one lap further on).
        """
        s = np.asarray(s, dtype=float)
        t = np.asarray(t, dtype=float)
        laps = np.where(t < s, np.ceil((s - t) / self.n_knots), 0.0)
        return self.arc_at_param(t + laps * self.n_knots) - self.arc_at_param(s)

    def total_curvature(self, s: ArrayLike, t: ArrayLike) -> FloatArray:
        """Total curvature Φ(s, t) = ∫ κ dℓ of the stretch from ``s`` to ``t``, rad.

        Exact: the difference of unwrapped tangent angles. ``t < s`` wraps as
        in :meth:`arc_length`.
        """
        s = np.asarray(s, dtype=float)
        t = np.asarray(t, dtype=float)
        laps = np.where(t < s, np.ceil((s - t) / self.n_knots), 0.0)
        return self.tangent_angle(t + laps * self.n_knots) - self.tangent_angle(s)

    def state(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Exact (unrolled arc position mm, unwrapped tangent angle rad, curvature 1/mm, speed mm per
        unit parameter) at unrolled parameters ``t``, in one pass."""
        lap, piece, u, cell = self._split(t)
        dx, dy, ddx, ddy = self.derivatives(piece, u)
        theta = self._unwrap(np.arctan2(dy, dx), cell, lap)
        sigma = self._sig_nodes[cell] + self._partial_arc(piece, cell, u) + self.perimeter * lap
        return sigma, theta, curvature(dx, dy, ddx, ddy), np.hypot(dx, dy)

    # ---------------------------------------------------- functions of arc
    def param_at_arc(self, sigma: ArrayLike, *, newton_steps: int = 2) -> FloatArray:
        """Unrolled parameter at unrolled arc position ``sigma`` (mm): the inverse of ℓ(0, ·), refined by
        ``newton_steps`` Newton steps.

        A cubic Hermite guess inside the table cell, then safeguarded Newton
        steps on the Gauss-Legendre arc length (two steps give ~1e-13 mm).
        """
        sigma = np.asarray(sigma, dtype=float)
        P = self.perimeter
        lap: FloatArray = np.floor(sigma / P)
        ss = sigma - lap * P
        nodes = self._sig_nodes
        ncell = len(nodes) - 1
        cell = np.clip(np.searchsorted(nodes, ss, side="right") - 1, 0, ncell - 1)
        s0, s1 = nodes[cell], nodes[cell + 1]
        h = s1 - s0
        x = (ss - s0) / h
        m = self.cells_per_piece
        t0 = cell / m
        dt = 1.0 / m
        d0 = self._dtds_nodes[cell] * h
        d1 = self._dtds_nodes[cell + 1] * h
        # cubic Hermite in x on [0, 1] for t(sigma)
        x2, x3 = x * x, x * x * x
        t: FloatArray = t0 + dt * (3 * x2 - 2 * x3) + d0 * (x3 - 2 * x2 + x) + d1 * (x3 - x2)
        piece = cell // m
        lo, hi = t0, t0 + dt
        target = ss - s0
        for _ in range(newton_steps):
            u = t - piece
            f = self._partial_arc(piece, cell, u) - target
            t = np.clip(t - f / self._speed_piece(piece, u), lo, hi)
        return t + lap * self.n_knots

    def point_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """Boundary point at arc position ``sigma`` (mm); shape ``sigma.shape + (2,)``."""
        return self.point(self.param_at_arc(sigma))

    def tangent_angle_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """Unwrapped tangent angle at arc position ``sigma``, rad (grows 2π per lap)."""
        return self.tangent_angle(self.param_at_arc(sigma))

    def curvature_at_arc(self, sigma: ArrayLike) -> FloatArray:
        """Signed curvature at arc position ``sigma``, 1/mm."""
        return self.curvature(self.param_at_arc(sigma))

    def sample(self, per_piece: int = 16) -> FloatArray:
        """Dense closed polyline of the boundary, ``per_piece`` points per spline piece, mm.

        Returns an array of shape (N*per_piece + 1, 2), its last point the first."""
        t = np.arange(self.n_knots * per_piece + 1) / per_piece
        return self.point(t)


# ------------------------------------------------------------------ loading
def _check_points(points: ArrayLike, source: str) -> FloatArray:
    try:
        pts = np.array(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise PartError(f"{source}: points must be a list of [x, y] numbers ({exc})") from None
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise PartError(f"{source}: points must have shape (N, 2), got {pts.shape}")
    if len(pts) < 4:
        raise PartError(f"{source}: a part needs at least 4 points, got {len(pts)}")
    bad = np.flatnonzero(~np.isfinite(pts).all(axis=1))
    if bad.size:
        raise PartError(f"{source}: point {bad[0]} is {pts[bad[0]].tolist()}: NaN or inf is not a coordinate")
    step = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)
    scale = np.ptp(pts, axis=0).max()
    if scale <= 0:
        raise PartError(f"{source}: all points coincide")
    dup = np.flatnonzero(step <= 1e-9 * scale)
    if dup.size:
        i = int(dup[0])
        raise PartError(
            f"{source}: points {i} and {(i + 1) % len(pts)} coincide at {pts[i].tolist()}; "
            "remove the repeated point (do not close the list by repeating the first point)"
        )
    return pts


def _segments_cross(poly: FloatArray) -> tuple[int, int] | None:
    """First pair of non-adjacent crossing edges of a closed polyline, or None.

    Sweep and prune: edges in order of their lowest x; each is paired with the later ones whose
    lowest x is within its own x range (all pairs at once, in that order), the pairs whose y ranges
    overlap are tested exactly, and the first crossing pair is returned.
    """
    a = poly[:-1]
    b = poly[1:]
    n = len(a)
    order = np.argsort(np.minimum(a[:, 0], b[:, 0]), kind="stable")
    a, b = a[order], b[order]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    end = np.searchsorted(lo[:, 0], hi[:, 0], side="right")
    count = np.maximum(end - np.arange(n) - 1, 0)
    ii = np.repeat(np.arange(n), count)
    jj = ii + 1 + np.arange(ii.size) - np.repeat(np.cumsum(count) - count, count)
    gap = np.abs(order[jj] - order[ii])
    keep = (lo[jj, 1] <= hi[ii, 1]) & (hi[jj, 1] >= lo[ii, 1]) & (gap > 1) & (gap < n - 1)
    ii, jj = ii[keep], jj[keep]
    r, sv, qp = b[ii] - a[ii], b[jj] - a[jj], a[jj] - a[ii]
    rxs = r[:, 0] * sv[:, 1] - r[:, 1] * sv[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        tt = (qp[:, 0] * sv[:, 1] - qp[:, 1] * sv[:, 0]) / rxs
        uu = (qp[:, 0] * r[:, 1] - qp[:, 1] * r[:, 0]) / rxs
    hit = np.flatnonzero((rxs != 0) & (tt >= 0) & (tt <= 1) & (uu >= 0) & (uu <= 1))
    if hit.size == 0:
        return None
    return int(order[ii[hit[0]]]), int(order[jj[hit[0]]])


def polygon_crossing(points: ArrayLike) -> tuple[int, int] | None:
    """The first pair of non-adjacent edges of a closed polyline that cross, or None when it is simple.

    Parameters
    ----------
    points : array_like, shape (n + 1, 2), mm
        The polyline, its last point equal to its first.

    Returns
    -------
    (i, j) or None
        Edge i runs from point i to point i + 1.

    Examples
    --------
    >>> polygon_crossing([[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]) is None
    True
    >>> sorted(polygon_crossing([[0, 0], [1, 1], [1, 0], [0, 1], [0, 0]]))
    [0, 2]
    """
    poly = np.asarray(points, dtype=float)
    if poly.ndim != 2 or poly.shape[1] != 2 or poly.shape[0] < 4:
        raise QueryError(f"points of shape {poly.shape}: give a closed polyline of at least 3 edges, shape (n + 1, 2)")
    return _segments_cross(poly)


def part_from_points(points: ArrayLike, *, name: str = "part", units: str = "mm", source: str | None = None) -> Part:
    """Validate a point list and build its :class:`Part`.

    Parameters
    ----------
    points : array_like, shape (N, 2)
        Boundary points in ``units``, in either winding; the first point stays first.
    name : str
        Name of the part.
    units : {"mm", "cm", "m", "in", "um"}
        Units of ``points``; the part is stored in mm.
    source : str, optional
        What to call the input in error messages (a file name).

    Returns
    -------
    Part

    Raises
    ------
    PartError
        Fewer than 4 points, a NaN or inf, coincident consecutive points, unknown
        units, a spline that stops (cusp) or crosses itself.

    Examples
    --------
    >>> part_from_points([[0, 0], [1, 0], [1, 1]])
    Traceback (most recent call last):
    ...
    localizer._errors.PartError: points: a part needs at least 4 points, got 3
    """
    source = source or "points"
    if units not in UNITS_TO_MM:
        raise PartError(f"{source}: unknown units {units!r}; use one of {sorted(UNITS_TO_MM)}")
    pts = _check_points(points, source) * UNITS_TO_MM[units]
    part = Part(pts, name=name)
    turning = part._turning
    if abs(abs(turning) - 2 * np.pi) > 1e-6:
        raise PartError(
            f"{source}: the spline through the points crosses itself (its tangent turns "
            f"{turning / (2 * np.pi):.2f} times, a simple closed curve turns once); check the point order"
        )
    if turning < 0:  # clockwise: reverse, keeping the first point first
        pts = np.vstack([pts[:1], pts[:0:-1]])
        part = Part(pts, name=name)
    crossing = _segments_cross(part.sample(16))
    if crossing is not None:
        i, j = sorted(crossing)
        raise PartError(
            f"{source}: the spline through the points crosses itself between parameters "
            f"{i / 16:.2f} and {j / 16:.2f} (near points {i // 16} and {j // 16}); check the point order"
        )
    return part
