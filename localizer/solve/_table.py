"""Arc-position tables: θ(σ) and t(σ) as piecewise quintic Hermite polynomials.

The exact solver screens and subdivides on these tables, which cost one
polynomial evaluation per point (no integration, no inverse of the arc
length); roots found on them are then polished on the exact spline
(:func:`polish`). The tables' worst interpolation error is measured when
they are built, on every cell, and the solver widens its certificates by it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._types import ArrayLike, FloatArray, IntArray
from ..geometry import TWO_PI, Part, bernstein_bounds, check_grid, curvature, horner, per_part, wrap_angle

__all__ = ["ArcTable", "arc_table"]

# Quintic Hermite basis on [0, 1] (ascending coefficients) for
# (f0, f0', f0'', f1, f1', f1'').
_H5 = np.array(
    [
        [1, 0, 0, -10, 15, -6],
        [0, 1, 0, -6, 8, -3],
        [0, 0, 0.5, -1.5, 1.5, -0.5],
        [0, 0, 0, 10, -15, 6],
        [0, 0, 0, -4, 7, -3],
        [0, 0, 0, 0.5, -1, 0.5],
    ]
)


@dataclass(frozen=True, eq=False)
class ArcTable:
    """Tables of a part in arc position (see module notes).

    Attributes
    ----------
    sig : ndarray, shape (J+1,), mm
        Cell boundaries in arc position; ``sig[-1]`` is the perimeter.
    h : ndarray, shape (J,), mm
        Cell widths.
    theta : ndarray, shape (J, 6)
        θ on cell j as a quintic in x = (σ - sig[j]) / h[j], rad.
    dtheta : ndarray, shape (J, 5)
        dθ/dσ = κ on the cell, 1/mm (the derivative of ``theta`` divided by h).
    param : ndarray, shape (J, 6)
        Spline parameter t on the cell as a quintic in x.
    kappa_slope : ndarray, shape (J,)
        Bound of |d²θ/dσ²| = |dκ/dσ| of the tabulated θ on each cell, 1/mm².
    theta_error, param_error : float
        Worst measured interpolation error of θ (rad) and of t.
    theta_cols, kappa_cols, param_cols : ndarray, shapes (6, J), (5, J), (6, J)
        ``theta``, ``dtheta`` and ``param`` column by column (gathering 1-D columns is several
        times faster), for the exact solver's breakpoints and the evaluations here.
    inv_h : ndarray, shape (J,), 1/mm
        1 / ``h``.
    """

    perimeter: float
    sig: FloatArray
    h: FloatArray
    theta: FloatArray
    dtheta: FloatArray
    param: FloatArray
    kappa_slope: FloatArray
    theta_error: float
    param_error: float
    theta_cols: FloatArray = field(init=False, repr=False)
    kappa_cols: FloatArray = field(init=False, repr=False)
    param_cols: FloatArray = field(init=False, repr=False)
    inv_h: FloatArray = field(init=False, repr=False)
    _last: int = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "theta_cols", np.ascontiguousarray(self.theta.T))
        object.__setattr__(self, "kappa_cols", np.ascontiguousarray(self.dtheta.T))
        object.__setattr__(self, "param_cols", np.ascontiguousarray(self.param.T))
        object.__setattr__(self, "inv_h", 1.0 / self.h)
        object.__setattr__(self, "_last", len(self.h) - 1)

    def locate(self, sigma: ArrayLike) -> tuple[FloatArray, IntArray, FloatArray]:
        """(lap, cell, x) for unrolled arc positions."""
        sigma = np.asarray(sigma, dtype=float)
        lap = np.floor(sigma * (1.0 / self.perimeter))
        ss = sigma - lap * self.perimeter
        cell = np.searchsorted(self.sig, ss, side="right") - 1
        np.minimum(cell, self._last, out=cell)
        x = (ss - self.sig[cell]) * self.inv_h[cell]
        return lap, cell, x

    def theta_kappa(self, sigma: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Tabulated unwrapped tangent angle (rad) and curvature (1/mm) at ``sigma``."""
        return self.theta_kappa_cell(sigma)[:2]

    def theta_kappa_cell(self, sigma: ArrayLike) -> tuple[FloatArray, FloatArray, IntArray]:
        """As :meth:`theta_kappa`, plus the table cell of each point."""
        lap, cell, x = self.locate(sigma)
        c = self.theta_cols
        th = c[5][cell]
        for k in (4, 3, 2, 1, 0):
            th = th * x + c[k][cell]
        c = self.kappa_cols
        ka = c[4][cell]
        for k in (3, 2, 1, 0):
            ka = ka * x + c[k][cell]
        return th + TWO_PI * lap, ka, cell

    def param_at(self, sigma: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Tabulated unrolled spline parameter at ``sigma`` (add ``lap * N`` outside)."""
        lap, cell, x = self.locate(sigma)
        c = self.param_cols
        t = c[5][cell]
        for k in (4, 3, 2, 1, 0):
            t = t * x + c[k][cell]
        return t, lap


def _node_state(
    part: Part, piece: IntArray, u: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """θ, κ, dκ/dσ, t, dt/dσ, d²t/dσ² from one spline piece at u (one-sided at knots)."""
    dx, dy, ddx, ddy = part.derivatives(piece, u)
    v2 = dx * dx + dy * dy
    v = np.sqrt(v2)
    kappa = curvature(dx, dy, ddx, ddy)
    dkds = part.curvature_slope(piece, u)
    dtds = 1.0 / v
    vt = (dx * ddx + dy * ddy) / v
    d2tds2 = -vt / (v2 * v)
    return np.arctan2(dy, dx), kappa, dkds, dtds, d2tds2


def arc_table(part: Part, *, max_theta_error: float = 1e-9) -> ArcTable:
    """Build (and cache on the part) the arc-position tables of ``part``.

    Cells are the part's table cells, split further until the measured
    interpolation error of θ is below ``max_theta_error`` rad.
    """
    return per_part("arc_table", part, (float(max_theta_error),), lambda: _build(part, max_theta_error))


def _build(part: Part, max_theta_error: float) -> ArcTable:
    n = part.n_knots
    sub = 1
    while True:
        m = part.cells_per_piece * sub
        J = n * m
        # a few dozen numbers a cell, and the cells grow with the knots, not the perimeter
        check_grid(
            part, "arc table", part.perimeter / J, J, unit="cells", advice=f"it has {n} knots; are they all needed?"
        )
        j = np.arange(J)
        piece = j // m
        u0 = (j % m) / m
        u1 = u0 + 1.0 / m
        t0 = piece + u0
        t1 = piece + u1
        sig0 = part.arc_at_param(t0)
        sig1 = np.where(j == J - 1, part.perimeter, part.arc_at_param(np.minimum(t1, n - 1e-300)))
        sig1[:-1] = sig0[1:]
        h = sig1 - sig0
        a0, k0, dk0, dt0, ddt0 = _node_state(part, piece, u0)
        a1, k1, dk1, dt1, ddt1 = _node_state(part, piece, u1)
        th0 = part.tangent_angle(t0)
        th1 = th0 + wrap_angle(a1 - th0)  # a cell turns by less than 1 rad
        hh = h * h
        vals_th = np.stack([th0, k0 * h, dk0 * hh, th1, k1 * h, dk1 * hh], axis=1)
        vals_t = np.stack([t0, dt0 * h, ddt0 * hh, t1, dt1 * h, ddt1 * hh], axis=1)
        theta = vals_th @ _H5
        param = vals_t @ _H5
        # measured interpolation error at interior points (exact σ, θ, t at known t)
        q = np.array([0.17, 0.5, 0.83])
        tq = (piece[:, None] + u0[:, None] + q / m).ravel()
        sq = part.arc_at_param(tq)
        cq = np.repeat(j, len(q))
        xq = (sq - sig0[cq]) / h[cq]
        err_th = np.abs(horner(theta[cq], xq) - part.tangent_angle(tq)).max()
        err_t = np.abs(horner(param[cq], xq) - tq).max()
        if err_th <= max_theta_error or sub >= 64:
            break
        sub *= 2
    dtheta = (theta[:, 1:] * np.arange(1, 6)) / h[:, None]
    d2 = (dtheta[:, 1:] * np.arange(1, 5)) / h[:, None]
    lo, hi = bernstein_bounds(d2, np.zeros(J), np.ones(J))
    slope = np.maximum(np.abs(lo), np.abs(hi))
    table = ArcTable(
        perimeter=part.perimeter,
        sig=np.append(sig0, part.perimeter),
        h=h,
        theta=theta,
        dtheta=dtheta,
        param=param,
        kappa_slope=slope * (1 + 1e-9),
        theta_error=float(err_th),
        param_error=float(err_t),
    )
    return table
