"""From what the jaw measured during a roll to the arc length it rolled over (paper §III-C, refined)."""

from __future__ import annotations

import numpy as np

from .._errors import QueryError
from .._types import ArrayLike

__all__ = ["arc_from_jaw_positions"]


def arc_from_jaw_positions(positions: ArrayLike, step: float, offset: float = 0.0) -> float:
    """Arc length rolled over on the part, from contact locations on the jaw, mm.

    The rolling strategy rotates the jaw by ``step`` about the tool axis, then
    presses it back along its normal. With u the contact's distance from the
    axis along the jaw and δ = ``offset`` the axis's distance from the pressed
    edge, one step moves the contact on the jaw by (to second order in θ)

        Δu = s·(1 - θ²/6) - δ·θ - u·θ²/2

    for an arc s on the part; the paper keeps Δu ≈ s (§III-C). This inverts
    the expansion step by step, so the error over a roll is O(θ²) instead of O(θ).

    Parameters
    ----------
    positions : array_like, shape (k+1,), mm
        Contact location on the jaw before the roll and after each of k steps.
    step : float, rad
        Signed rotation of one step (positive: counter-clockwise, contact
        moving towards +u).
    offset : float, mm
        δ, the tool axis's distance from the pressed edge (0: the paper's case).

    Returns
    -------
    float, mm
        The arc length rolled over, positive in the rolling direction.

    Examples
    --------
    >>> round(arc_from_jaw_positions([-40.0, -39.0, -38.0], 0.0), 12)  # no rotation: plain travel
    2.0
    """
    u = np.asarray(positions, dtype=float)
    if u.ndim != 1 or u.size < 2 or not np.all(np.isfinite(u)):
        raise QueryError(f"positions must be at least two finite jaw positions (mm), got {u!r}")
    if not np.isfinite(step) or not np.isfinite(offset):
        raise QueryError(f"step={step!r} rad and offset={offset!r} mm must be finite")
    sign = -1.0 if step < 0 else 1.0
    theta = abs(float(step))
    mid = 0.5 * (u[1:] + u[:-1])
    arcs = (sign * np.diff(u) + offset * theta + sign * mid * theta**2 / 2) / (1 - theta**2 / 6)
    return float(arcs.sum())
