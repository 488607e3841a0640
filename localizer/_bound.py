"""The Cramér–Rao bound of one roll: how well a start can be known from one (L, Ω) at best.

A roll from start s measures its contact travel L and rotation Ω = θ(s + L) − θ(s), each with an
independent Gaussian error (sd σ_L mm and σ_Ω rad). The unknowns are s and the true L: two readings,
two unknowns, so the Fisher information is HᵀΣ⁻¹H with

    H = ∂(L_m, Ω_m)/∂(s, L) = [[0, 1], [κ(s+L) − κ(s), κ(s+L)]],   Σ = diag(σ_L², σ_Ω²),

and inverting it (H is square) gives the variance of any unbiased estimate of the start:

    σ_s² ≥ (σ_Ω² + κ(s+L)²·σ_L²) / (κ(s+L) − κ(s))².

Where the curvature is the same at both ends (a circle, a stretch of constant curvature) the roll
says nothing about the start and the bound is infinite. Of the contact's place at the roll's end,
s + L, the bound is the same expression with κ(s) in the numerator's place of κ(s+L) (the roll
read backwards). docs/wheel.md uses it for the wheel finger with its own σ_L and σ_Ω.
"""

from __future__ import annotations

import math

import numpy as np

from ._boundary import Boundary
from ._errors import QueryError
from ._types import ArrayLike, FloatArray

__all__ = ["roll_bound"]


def roll_bound(
    part: Boundary, start: ArrayLike, length: float, *, sd_length: ArrayLike, sd_turn: ArrayLike, at: str = "start"
) -> FloatArray:
    """The Cramér–Rao bound, mm, of the start (or the end) of a roll of ``length`` mm from ``start``.

    Parameters
    ----------
    part : Part or Outline
    start : float or array, mm
        Arc positions where the roll starts (counter-clockwise travel).
    length : float, mm
        The roll's contact travel L (> 0).
    sd_length, sd_turn : float or array, mm and rad
        Standard deviations of the measured L and Ω (independent); arrays go with ``start``.
    at : {"start", "end"}
        Bound the start s, or the contact's place at the roll's end, s + L.

    Returns
    -------
    ndarray, mm
        One bound per start; ``inf`` where κ(s + L) = κ(s).

    Examples
    --------
    On a circle a roll says next to nothing of where it started (a spline through 40 points of it
    varies its curvature by a hundred-thousandth), on an egg it says more.

    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    >>> circle = part_from_points(np.c_[30 * np.cos(a), 30 * np.sin(a)])
    >>> egg = part_from_points(np.c_[30 * np.cos(a) + 4 * np.cos(2 * a), 22 * np.sin(a)])
    >>> [round(float(roll_bound(p, 10.0, 5.0, sd_length=0.05, sd_turn=1e-3)), 1) for p in (circle, egg)]
    [110.9, 0.1]
    """
    if not (math.isfinite(length) and length > 0):
        raise QueryError(f"length={length!r} mm must be a positive number")
    sd_l, sd_o = np.asarray(sd_length, dtype=float), np.asarray(sd_turn, dtype=float)
    for name, value in (("sd_length", sd_l), ("sd_turn", sd_o)):
        if not (np.all(np.isfinite(value)) and np.all(value >= 0)):
            raise QueryError(f"{name}={value!r} must be finite and ≥ 0")
    if at not in ("start", "end"):
        raise QueryError(f"at={at!r}: use 'start' or 'end'")
    s = np.asarray(start, dtype=float)
    k0 = np.asarray(part.curvature_at_arc(s), dtype=float)
    k1 = np.asarray(part.curvature_at_arc(s + length), dtype=float)
    lever = k1 if at == "start" else k0
    spread = np.sqrt(sd_o**2 + (lever * sd_l) ** 2)
    gap = np.abs(k1 - k0)
    with np.errstate(divide="ignore"):
        out: FloatArray = np.where(gap > 1e-12, spread / np.maximum(gap, 1e-300), np.inf)
    return out
