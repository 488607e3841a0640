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

__all__ = ["unwrapped_angle", "pivot_turn", "free_runs", "jump_runs"]


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
