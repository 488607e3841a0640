"""The paper's grid of a part: ℓ and Φ accumulated once by the trapezoid rule on an h-grid of the
parameter (Jia 2005, §II-A), interpolated linearly between its points, and where κ changes sign
(the modes' ends). :func:`localizer.march` marches on it."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._errors import QueryError
from .._types import FloatArray
from ..geometry import Part, check_grid, curvature, per_part

__all__ = ["MarchGrid", "march_grid"]


@dataclass(frozen=True, eq=False)
class MarchGrid:
    """ℓ(0, ih) and Φ(0, ih) by the trapezoid rule on the h-grid of one period.

    Attributes
    ----------
    h : float
        Step in the parameter domain.
    cells : int
        Grid cells per period, τ/h.
    length : ndarray, shape (cells+1,), mm
        Cumulative arc length at the grid points.
    turn : ndarray, shape (cells+1,), rad
        Cumulative total curvature at the grid points.
    kappa : ndarray, shape (cells+1,), 1/mm
        Curvature at the grid points.
    """

    h: float
    cells: int
    length: FloatArray
    turn: FloatArray
    kappa: FloatArray

    # ---- per-part quantities, computed once per grid --------------------
    @cached_property
    def max_speed(self) -> float:
        """Largest |α'| on the grid (trapezoid cell lengths / h), mm per unit parameter."""
        return float(np.max(np.diff(self.length))) / self.h

    @cached_property
    def inflections(self) -> tuple[FloatArray, FloatArray]:
        """(z, sign after z): the inflections of :func:`_sign_regions`."""
        return _sign_regions(self.kappa, self.h)

    @cached_property
    def negated_turn(self) -> FloatArray:
        """-Φ(0, ih): nondecreasing over concave stretches, for concave-concave modes."""
        return -self.turn

    # ---- unrolled evaluation (parameter x may exceed the period) ----------
    def _value(self, cum: FloatArray, x: float) -> float:
        """The unrolled cumulative ``cum`` at parameter ``x``, interpolated linearly in the cell."""
        i = x / self.h
        lap, i = divmod(i, self.cells)
        k = min(int(i), self.cells - 1)
        f = i - k
        return float(cum[k] + f * (cum[k + 1] - cum[k]) + lap * cum[-1])

    def ell(self, s: float, t: float) -> float:
        """ℓ(s, t) by the trapezoid rule, mm, between unrolled parameters ``s`` <= ``t``."""
        return self._value(self.length, t) - self._value(self.length, s)

    def phi(self, s: float, t: float) -> float:
        """Φ(s, t) by the trapezoid rule, rad, between unrolled parameters ``s`` <= ``t``."""
        return self._value(self.turn, t) - self._value(self.turn, s)

    def _search(self, cum: FloatArray, target: float, x_lo: float, x_hi: float) -> float | None:
        """First x in [x_lo, x_hi] with C(x) = target, C nondecreasing there, or None.

        C is the unrolled cumulative ``cum``; the search is a binary search on
        views of ``cum`` (no copies), then linear interpolation in the cell.
        """
        M, h = self.cells, self.h
        if self._value(cum, x_lo) >= target:
            return x_lo
        i = int(np.floor(x_lo / h))
        i_hi = int(np.ceil(x_hi / h))
        while i < i_hi:
            lap, k0 = divmod(i, M)
            k1 = min(M, k0 + (i_hi - i))
            v = target - lap * cum[-1]
            seg = cum[k0 : k1 + 1]
            j = int(np.searchsorted(seg, v, side="left"))
            if j <= k1 - k0:
                k = max(j - 1, 0)
                a = seg[k]
                b = seg[k + 1] if k + 1 <= k1 - k0 else a
                f = 0.0 if b == a else min(max((v - a) / (b - a), 0.0), 1.0)
                x = (lap * M + k0 + k + f) * h
                return max(x, x_lo) if x <= x_hi else None
            i += k1 - k0
        return None


def march_grid(part: Part, h: float) -> MarchGrid:
    """The integrals of ``part`` on a grid of step ``h`` in the parameter, built by the trapezoid rule (kept
    with the part for the last ``h``)."""
    return per_part("march_grid", part, float(h), lambda: _build(part, h), latest_only=True)


def _build(part: Part, h: float) -> MarchGrid:
    n = part.n_knots
    M = int(round(n / h))
    if 4 * n > M or abs(M * h - n) > 1e-9 * n:
        raise QueryError(f"step={h!r} must divide the parameter period {n} into at least {4 * n} cells")
    # three numbers a cell, the cells a step of the parameter apart: the paper's grid is as large as the knots
    # are many (not as the part is long), and meant to be fine
    check_grid(
        part,
        "march",
        h,
        M + 1,
        limit=None,
        point_bytes=24,
        unit="cells",
        per="of a knot",
        advice=f"it has {n} knots; take a coarser step (MarchOptions.step)",
    )
    length = np.empty(M + 1)
    turn = np.empty(M + 1)
    kappa = np.empty(M + 1)
    acc_l = acc_t = 0.0
    chunk = 1 << 20
    prev_v = prev_w = None
    for start in range(0, M + 1, chunk):
        idx = np.arange(start, min(start + chunk, M + 1))
        t = (idx * h).astype(np.float64, copy=False)
        piece = np.minimum(t.astype(np.int64), n - 1)
        u = (t - piece).astype(np.float64, copy=False)
        dx, dy, ddx, ddy = part.derivatives(piece, u)
        v = np.hypot(dx, dy)
        k = curvature(dx, dy, ddx, ddy)
        w = k * v
        kappa[idx] = k
        if prev_v is None:
            inc_v = 0.5 * h * (v[1:] + v[:-1])
            inc_w = 0.5 * h * (w[1:] + w[:-1])
            length[idx[0]] = 0.0
            turn[idx[0]] = 0.0
            length[idx[1:]] = np.cumsum(inc_v)
            turn[idx[1:]] = np.cumsum(inc_w)
        else:
            vv = np.concatenate([[prev_v], v])
            ww = np.concatenate([[prev_w], w])
            length[idx] = acc_l + np.cumsum(0.5 * h * (vv[1:] + vv[:-1]))
            turn[idx] = acc_t + np.cumsum(0.5 * h * (ww[1:] + ww[:-1]))
        acc_l, acc_t = length[idx[-1]], turn[idx[-1]]
        prev_v, prev_w = v[-1], w[-1]
    grid = MarchGrid(h=h, cells=M, length=length, turn=turn, kappa=kappa)
    return grid


def _sign_regions(kappa: FloatArray, h: float) -> tuple[FloatArray, FloatArray]:
    """Inflections (parameters in [0, τ), ascending) and the sign of κ after each.

    κ is sampled on the grid (``kappa[-1]`` repeats ``kappa[0]``). A zero of κ
    that does not change its sign is no inflection (footnote 5): grid values
    equal to zero take the sign of the next nonzero value, which is the sign
    of κ' at a simple zero.
    """
    M = kappa.size - 1
    sgn = np.sign(kappa[:-1])
    nz = np.flatnonzero(sgn)
    if nz.size == 0:
        raise QueryError("the part's curvature vanishes everywhere on the grid")
    sgn = sgn[nz[np.searchsorted(nz, np.arange(M)) % nz.size]]
    change = np.flatnonzero(sgn != np.roll(sgn, 1))
    k0 = kappa[(change - 1) % M]
    k1 = kappa[change]
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(k0 != k1, k0 / (k0 - k1), 0.0)
    z = np.mod((change - 1 + np.clip(f, 0.0, 1.0)) * h, M * h)
    order = np.argsort(z)
    return z[order], sgn[change][order]
