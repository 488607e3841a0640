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

A whole trial (:func:`trial_bound`) reads the contact's travel z_j and the arm's angle Ω_j at every
step j = 0 … k of its rolls, with the nuisances the filters carry: an offset c_s per contact segment
(flat prior) and the calibration's scale b ~ N(1, sd_scale²), and the jaw's angle offset φ:

    z_j = c_s + b·(σ_j − σ_0) + e_j,   Ω_j = θ(σ_j) + φ + ε_j,   e_j ~ N(0, sd_position²), ε_j ~ N(0, sd_turn²).

The unknowns are the path σ_0 … σ_k and g = (φ, c_1 … c_S, b). Reading j's information over (σ_j, g)
is [[a_j, u_jᵀ], [u_j, M_j]] with a_j = 1/sd_position² + κ_j²/sd_turn²; σ_j appears in no other
reading, so eliminating it leaves M_j − u_j u_jᵀ / a_j on g. Summing those over j < k, adding reading
k's block (σ_k kept) and the prior 1/sd_scale² on b, and inverting gives the bound of the contact's
final place σ_k. For two readings without a scale this is the roll bound above with
sd_length = √2·sd_position and sd_turn = √2 times the arm's (a roll's L and Ω are differences of
two readings). docs/robustness.md gives the derivation in full.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._errors import QueryError
from .._types import ArrayLike, FloatArray
from ..geometry import Boundary

__all__ = ["roll_bound", "trial_bound", "TrialNoise"]


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


@dataclass(frozen=True)
class TrialNoise:
    """What :func:`trial_bound` takes the readings' errors and the nuisances to be.

    Attributes
    ----------
    sd_position : float, mm
        Standard deviation of one reading of the contact's travel (> 0).
    sd_turn : float, rad
        Standard deviation of one reading of the arm's angle (> 0).
    sd_scale : float
        Prior standard deviation of the calibration's relative scale (0: the scale is known).
    machining_error : float, mm
        RMS of the real boundary's normal deviation from the model (0: none), as harmonics of the
        perimeter with 1/k amplitudes down to ``machining_wavelength`` (the simulator's model):
        its slope turns the arm's angle and its curvature's share lengthens the travel.
    machining_wavelength : float, mm
        The deviation's shortest wavelength.
    """

    sd_position: float
    sd_turn: float
    sd_scale: float = 0.0
    machining_error: float = 0.0
    machining_wavelength: float = 20.0

    def __post_init__(self) -> None:
        for name in ("sd_position", "sd_turn", "machining_wavelength"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} must be a positive number")
        for name in ("sd_scale", "machining_error"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise QueryError(f"{name}={value!r} must be a number ≥ 0")


def _harmonics(noise: TrialNoise, perimeter: float) -> FloatArray:
    """The machining deviation's harmonic numbers k (empty without one)."""
    if noise.machining_error <= 0:
        return np.empty(0)
    return np.arange(1, max(1, int(perimeter / noise.machining_wavelength)) + 1, dtype=float)


def trial_bound(part: Boundary, path: ArrayLike, noise: TrialNoise, *, segments: ArrayLike | None = None) -> float:
    """The Cramér–Rao bound, mm, of the contact's final place after the readings along ``path``.

    Parameters
    ----------
    part : Part or Outline
    path : array_like (k+1,), mm
        The true contact's arc position at every reading of the trial, in order (the first where
        the jaw was laid); wrapped or unrolled, each step shorter than half the perimeter.
    noise : TrialNoise
        The readings' errors and the nuisances' priors.
    segments : array_like of int (k+1,), optional
        The contact segment of each reading (a regrasp or a bridge starts one with its own offset);
        default one segment.

    Returns
    -------
    float, mm
        ``inf`` where the readings do not fix the place (a circle, or a single reading).

    Examples
    --------
    Two readings are one roll (its L and Ω each the difference of two readings):

    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    >>> egg = part_from_points(np.c_[30 * np.cos(a) + 4 * np.cos(2 * a), 22 * np.sin(a)])
    >>> two = trial_bound(egg, [10.0, 22.0], TrialNoise(sd_position=0.01, sd_turn=2e-4))
    >>> one = float(roll_bound(egg, 10.0, 12.0, sd_length=0.01 * 2**0.5, sd_turn=2e-4 * 2**0.5, at="end"))
    >>> round(two, 4), abs(two - one) < 1e-9 * one
    (0.0278, True)

    Rolling on adds readings and the bound falls; an unknown scale and a machined part raise it:

    >>> path = np.linspace(10.0, 40.0, 151)
    >>> [round(trial_bound(egg, path, TrialNoise(0.01, 2e-4, **kw)), 4)
    ...  for kw in ({}, {"sd_scale": 0.01}, {"sd_scale": 0.01, "machining_error": 0.009})]
    [0.0085, 0.0165, 0.1341]
    """
    sigma = np.asarray(path, dtype=float).ravel()
    if sigma.size == 0 or not np.all(np.isfinite(sigma)):
        raise QueryError(f"path: {sigma.size} readings; a trial's path must be finite arc positions, at least one")
    seg = np.zeros(sigma.size, dtype=int) if segments is None else np.asarray(segments).ravel()
    if seg.shape != sigma.shape:
        raise QueryError(f"segments has {seg.size} entries for {sigma.size} readings")
    if sigma.size < 2:
        return math.inf
    P = part.perimeter
    steps = np.diff(sigma)
    steps = steps - P * np.round(steps / P)
    travel = np.concatenate([[0.0], np.cumsum(steps)])
    kappa = np.asarray(part.curvature_at_arc(np.mod(sigma, P)), dtype=float)
    labels, seg_index = np.unique(seg, return_inverse=True)
    harm = _harmonics(noise, P)
    # columns of g: φ, one offset per segment, b (when its scale is not known), the deviation's
    # cosine and sine coefficients
    n_c = 1 + labels.size
    n_b = 1 if noise.sd_scale > 0 else 0
    n_g = n_c + n_b + 2 * harm.size
    k = sigma.size
    e_z = np.zeros((k, n_g))
    e_z[np.arange(k), 1 + seg_index] = 1.0
    e_o = np.zeros((k, n_g))
    e_o[:, 0] = 1.0
    prior = np.zeros(n_g)
    if n_b:
        e_z[:, n_c] = travel
        prior[n_c] = 1.0 / noise.sd_scale**2
    if harm.size:
        # d(σ) = Σ α_k cos(ω_k σ) + β_k sin(ω_k σ), var α_k = var β_k = rms² / (k² Σ 1/j²); the arm reads
        # the real tangent, θ + d', and the travel on the real boundary grows by ∫ κ d dσ
        w = 2 * np.pi * harm / P
        cos, sin = np.cos(np.outer(sigma, w)), np.sin(np.outer(sigma, w))
        e_o[:, n_c + n_b :] = np.hstack([-sin * w, cos * w])
        mid = 0.5 * (kappa[1:] + kappa[:-1])[:, None] * steps[:, None]
        grow = np.vstack(
            [
                np.zeros((1, 2 * harm.size)),
                np.cumsum(mid * 0.5 * np.hstack([cos[1:] + cos[:-1], sin[1:] + sin[:-1]]), axis=0),
            ]
        )
        e_z[:, n_c + n_b :] = grow
        var = noise.machining_error**2 / (harm**2 * np.sum(1.0 / harm**2))
        prior[n_c + n_b :] = np.tile(1.0 / var, 2)
    w_z, w_o = 1.0 / noise.sd_position**2, 1.0 / noise.sd_turn**2
    a = w_z + kappa**2 * w_o
    u = w_z * e_z + (kappa * w_o)[:, None] * e_o
    info = w_z * e_z.T @ e_z + w_o * e_o.T @ e_o - (u[:-1].T / a[:-1]) @ u[:-1] + np.diag(prior)
    # σ_k's share: a_k − u_kᵀ info⁻¹ u_k, the information left on it once g is unknown
    if np.linalg.cond(info) > 1e14:  # a nuisance the readings do not fix: nor is the place
        return math.inf
    solved = np.linalg.solve(info, u[-1])
    left = float(a[-1] - u[-1] @ solved)
    return math.inf if left <= a[-1] * 1e-12 else 1.0 / math.sqrt(left)
