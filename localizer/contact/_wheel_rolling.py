"""What the model says of a wheel rolling from each start of a grid: the tangent angle it follows, the
turn it reads at a drawing's corners, and how far it can roll on either way.

On a convex corner the disc pivots: Ω runs through the corner's jump while L stands still, so a reading
near one fits any turn within the jump (:func:`pivot_turn`). A disc cannot reach into a concave corner of
jump j: it touches both faces r·tan(|j|/2) before it and cannot roll on (the rolling takes the drop for
a jump); the reach, with its clearance kept generous for a machined part, calls a shallow corner
touchable throughout, a jump's evidence must not (:func:`jump_runs`).
"""

from __future__ import annotations

import math

import numpy as np

from .._types import FloatArray
from ..geometry import Boundary, Outline, nearest_corner
from ._wheel import WheelJaw

__all__ = ["ShiftedGrid", "unwrapped_angle", "pivot_turn", "free_runs", "jump_runs"]


def unwrapped_angle(part: Boundary, sigma: FloatArray) -> FloatArray:
    """Unwrapped tangent angle Θ at unrolled arc positions ``sigma`` (mm), rad, Θ(σ + P) = Θ(σ) + 2π:
    continuous on a spline part; on a drawing it steps at corners, taking the value after the jump there."""
    sigma = np.asarray(sigma, dtype=float)
    if isinstance(part, Outline):
        unwrapped: FloatArray = part.tangent_angle_at_arc(sigma)
        return unwrapped
    laps = np.floor(sigma / part.perimeter)
    t = part.param_at_arc(sigma - laps * part.perimeter)  # type: ignore[attr-defined]
    out: FloatArray = part.tangent_angle(t) + 2 * math.pi * laps  # type: ignore[attr-defined]
    return out


class ShiftedGrid:
    """Θ and κ of a ``part`` at a uniform grid of starts ``k·h`` (``n`` of them round the perimeter), and at
    that grid shifted by any arc L: what a wheel's filter asks at every reading it uses.

    On a spline part the shifted values come from the grid's own, with one fraction L/h for every start:
    a cubic Hermite interpolation of Θ (its derivative κ known at every node) and a linear one of κ. At the
    wheel filter's 0.02 mm grid this is within 2e-8 rad of the spline's own evaluation on the shipped
    parts and 2.5e-5 rad on the tightest held-out glyph (κ up to 5.8 mm⁻¹), under 6% of one reading's
    angle error, where the spline's evaluation (arc to parameter by Newton at every start) costs ~10 ms a
    reading on the kidney. On a drawing Θ steps at corners and κ at the ends of arcs, which no interpolation crosses:
    there the drawing's own exact and cheap evaluation is used.

    Parameters
    ----------
    part : Part or Outline
    n : int
        Starts round the perimeter (the grid step h = P/n, mm).
    exact : bool
        Evaluate the part at every shift instead (the reference the interpolation is measured against).
    """

    def __init__(self, part: Boundary, n: int, *, exact: bool = False) -> None:
        self.part = part
        self.h = float(part.perimeter) / n
        self.grid: FloatArray = np.arange(n, dtype=float) * self.h
        self.theta: FloatArray = unwrapped_angle(part, self.grid)
        self.kappa: FloatArray = np.asarray(part.curvature_at_arc(self.grid), dtype=float)
        self._exact = exact or isinstance(part, Outline)
        # two laps and a node of Θ, κ and the lap, so that the grid shifted by whole steps is a slice of them
        self._theta2 = np.concatenate([self.theta, self.theta, self.theta[:1]])
        self._kappa2 = np.concatenate([self.kappa, self.kappa, self.kappa[:1]])
        self._lap2 = np.repeat(np.arange(3), [n, n, 1])

    def at(self, length: float) -> tuple[FloatArray, FloatArray]:
        """Θ (rad, unwrapped: Θ(σ + P) = Θ(σ) + 2π) and κ (1/mm) at every start plus ``length`` mm."""
        x = self.grid + float(length)
        if self._exact:
            kappa = np.asarray(self.part.curvature_at_arc(self.part.wrap_arc(x)), dtype=float)
            return unwrapped_angle(self.part, x), kappa
        n = self.grid.size
        q = float(length) / self.h
        m = math.floor(q)
        f = q - m
        laps, m0 = divmod(m, n)
        t0 = self._theta2[m0 : m0 + n] + 2 * math.pi * (self._lap2[m0 : m0 + n] + laps)
        t1 = self._theta2[m0 + 1 : m0 + n + 1] + 2 * math.pi * (self._lap2[m0 + 1 : m0 + n + 1] + laps)
        k0, k1 = self._kappa2[m0 : m0 + n], self._kappa2[m0 + 1 : m0 + n + 1]
        d0, d1 = k0 * self.h, k1 * self.h
        f2, f3 = f * f, f * f * f
        theta = (2 * f3 - 3 * f2 + 1) * t0 + (f3 - 2 * f2 + f) * d0 + (3 * f2 - 2 * f3) * t1 + (f3 - f2) * d1
        kappa = (1 - f) * k0 + f * k1
        return theta, kappa


def pivot_turn(
    part: Boundary, x: FloatArray, theta0: FloatArray, model: FloatArray, turn: float, window: float
) -> FloatArray:
    """The ``model`` turns (rad) of starts whose contacts are at unrolled arcs ``x`` (mm), their start angles
    ``theta0`` (rad), with those within ``window`` mm of a convex corner of a drawing replaced by the angle
    nearest to the reading ``turn`` (rad) between the model's there and across the corner's jump."""
    corners = [c for c in part.corners if c.angle > 0] if isinstance(part, Outline) else []
    if not corners:
        return model
    j, d, _ = nearest_corner(np.array([k.arc for k in corners]), float(part.perimeter), np.mod(x, part.perimeter))
    near = np.abs(d) <= window
    if not near.any():
        return model
    i = np.flatnonzero(near)
    after = unwrapped_angle(part, x[i] - d[i]) - theta0[i]  # Θ just past the corner, on the start's lap
    before = after - np.array([k.angle for k in corners])[j[i]]
    lo, hi = np.minimum(model[i], before), np.maximum(model[i], after)
    out = model.copy()
    out[i] = np.clip(turn, lo, hi)
    return out


def free_runs(touch: np.ndarray, h: float) -> tuple[FloatArray, FloatArray]:
    """For each grid point, the arc (mm) ahead and behind before the first untouchable point (inf when
    the whole boundary is touchable)."""
    n = touch.size
    bad = np.flatnonzero(~touch)
    if bad.size == 0:
        inf = np.full(n, np.inf)
        return inf, inf.copy()
    idx = np.arange(n)
    ext = np.concatenate([bad - n, bad, bad + n])
    nxt = ext[np.searchsorted(ext, idx, side="left")]
    prv = ext[np.searchsorted(ext, idx, side="right") - 1]
    ahead = np.where(touch, (nxt - idx - 1) * h, -1.0)
    behind = np.where(touch, (idx - prv - 1) * h, -1.0)
    return ahead, behind


def jump_runs(
    part: Boundary, wheel: WheelJaw, grid: FloatArray, ahead: FloatArray, behind: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The :func:`free_runs` ``ahead`` and ``behind`` of the starts ``grid`` (arc positions, mm), each ended
    also where the ``wheel`` meets a concave corner of a drawing (module notes); unchanged on a spline part."""
    if not isinstance(part, Outline):
        return ahead, behind
    P = float(part.perimeter)
    for c in part.corners:
        if c.angle >= 0:
            continue
        skip = wheel.radius * math.tan(min(0.5 * abs(c.angle), 0.5 * math.pi - 1e-9))
        ahead = np.minimum(ahead, np.maximum(np.mod(c.arc - grid, P) - skip, 0.0))
        behind = np.minimum(behind, np.maximum(np.mod(grid - c.arc, P) - skip, 0.0))
    return ahead, behind
