"""The simulated instruments: the two-axis strain-gauge wrist (paper eqs. 8–13) and the encoder.

A contact force F (N) normal to the jaw at distance d (mm) from the wrist's
axis of symmetry and height p (mm) below the robot's open end gives the
bending moment M_b = F·p on chip sensor S1 and the twisting moment M_t = F·d
on S2. With the wrist's dimensions W1, W2, δ (mm):

    σ1 = -6 M_b / (W1 δ²)        (eq. 10)
    σ2 =  3 M_t / (W2² δ)        (eq. 12)
    σ2/σ1 = -d / (32 p)          (eq. 13, for W2 = 2 W1 = 8 δ)

and each channel's voltage change is proportional to its stress.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .noise import NoiseModel

__all__ = ["Wrist", "encoder_angle"]


@dataclass(frozen=True)
class Wrist:
    """Geometry and sensitivity of the aluminium wrist.

    Attributes
    ----------
    w1, w2, delta : float, mm
        Section widths and thickness (paper Fig. 4: 3.175, 6.35, 0.794 mm).
    height : float, mm
        p, the height of the contact below the open end, held constant.
    volts_per_newton : float, V/N
        Δv1 for a 1 N contact force; the paper rolls at Δv1 ≈ 0.4 V.
    """

    w1: float = 3.175
    w2: float = 6.35
    delta: float = 0.794
    height: float = 25.0
    volts_per_newton: float = 0.4

    def stresses(self, force, d):
        """(σ1, σ2) in MPa for ``force`` F (N) at jaw position ``d`` (mm), eqs. (10) and (12)."""
        force = np.asarray(force, dtype=float)
        mb = force * self.height
        mt = force * np.asarray(d, dtype=float)
        return -6.0 * mb / (self.w1 * self.delta**2), 3.0 * mt / (self.w2**2 * self.delta)

    def ideal_voltages(self, force, d):
        """Noise-free (Δv1, Δv2), V, for ``force`` (N) at jaw position ``d`` (mm): both channels have the same
        volts per MPa."""
        s1, s2 = self.stresses(force, d)
        k = self.volts_per_newton / self.stresses(1.0, 0.0)[0]  # V per MPa (< 0), so that Δv1 > 0 when pressed
        return k * s1, k * s2

    def voltages(self, force, d, time, noise: NoiseModel, rng: np.random.Generator):
        """One raw sample of (v1, v2), V, for ``force`` (N) at jaw position ``d`` (mm), under ``noise`` at
        ``time`` (s), its random parts drawn from ``rng``."""
        dv1, dv2 = self.ideal_voltages(force, d)
        dv2 = dv2 * (1.0 + noise.gain_error) * (1.0 + noise.nonlinearity * (np.asarray(d) / 50.0) ** 2)
        v1 = noise.v1_offset + dv1 + noise.crosstalk * dv2 + noise.v1_drift * time
        v2 = noise.v2_offset + dv2 + noise.crosstalk * dv1 + noise.v2_drift * time
        if noise.v1_noise:
            v1 = v1 + rng.normal(0.0, noise.v1_noise, np.shape(v1))
        if noise.v2_noise:
            v2 = v2 + rng.normal(0.0, noise.v2_noise, np.shape(v2))
        if noise.adc_step:
            v1 = np.round(v1 / noise.adc_step) * noise.adc_step
            v2 = np.round(v2 / noise.adc_step) * noise.adc_step
        return v1, v2


def encoder_angle(phi, noise: NoiseModel):
    """The arm's reading of the jaw angle ``phi`` (rad), quantized to the ``noise`` model's encoder step.

    Examples
    --------
    >>> import math
    >>> from sim2d import load_noise
    >>> paper = load_noise("paper")                        # a 0.03° encoder
    >>> round(math.degrees(encoder_angle(math.radians(10.01), paper)), 4)
    10.02
    """
    if not noise.encoder_step:
        return phi
    return np.round(np.asarray(phi) / noise.encoder_step) * noise.encoder_step
