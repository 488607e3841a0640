"""The wheel filter's model of a reading, per start: the errors the readings of a roll share, the model's turn
(with a drawing's convex corners, on which the wheel pivots), its curvature and its slope in the part's
scale, and where a pivot places the contact (the model: :mod:`localizer.filters._wheel_filter`).
"""

from __future__ import annotations

import math

import numpy as np

from .._types import FloatArray
from ..contact import ShiftedGrid, pivot_turn, unwrapped_angle
from ..geometry import Outline, Part, nearest_corner

__all__ = ["WheelModel"]


class WheelModel:
    """The model's side of :class:`~localizer.filters._wheel_state.WheelState`: what a start predicts for a reading
    (its attributes are the state's, set by it)."""

    part: Part | Outline
    grid: FloatArray
    h: float
    sd_turn: float
    sd_slope: float
    slope_length: float
    sd_length: float
    sd_scale: float
    sd_part_scale: float
    noise_scales: tuple[float, ...]
    _angles: ShiftedGrid
    _theta0: FloatArray
    _terms: int
    _steps: tuple[FloatArray, FloatArray]
    _convex: tuple[FloatArray, FloatArray]
    _turn_margin: float

    def _cov(self, a: FloatArray, b: FloatArray) -> FloatArray:
        """Covariance of the shared errors of residuals at arcs ``a`` and ``b`` (mm) rolled from the start."""
        a, b = np.asarray(a, dtype=float)[:, None], np.asarray(b, dtype=float)[None, :]
        ell2 = 2 * self.slope_length**2
        slope = self.sd_slope**2 * (
            np.exp(-((a - b) ** 2) / ell2) - np.exp(-(a**2) / ell2) - np.exp(-(b**2) / ell2) + 1.0
        )
        # the start's independent reading error: in every residual
        out: FloatArray = slope + self.sd_turn**2 * (1.0 + (a == b))
        return out

    def corner_window(self, length: float) -> float:
        """How near a convex corner (mm) a start's contact after rolling ``length`` mm may be for the wheel
        to be pivoting on it: three standard errors of L (the encoder's and the calibrated radius's) under
        the largest of :attr:`noise_scales` (the stated probability holds under it), and one grid step (the
        true start lies between two of the grid's)."""
        return self.h + 3.0 * max(self.noise_scales) * math.hypot(self.sd_length, float(length) * self.sd_scale)

    def predicted_turn(self, length: float, turn: float) -> FloatArray:
        """Each start's model turn (rad) after rolling ``length`` mm, the nearest to the reading ``turn`` (rad)
        the model allows: Θ(s + L) − Θ(s), or, within :meth:`corner_window` of a convex corner, any angle
        between the model's there and across the corner's jump (the wheel pivoting on it)."""
        return self._model_at(length, turn)[0]

    def _model_at(self, length: float, turn: float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """:meth:`predicted_turn`, each start's curvature (1/mm) at its contact after ``length`` mm, the
        predicted turn's slope in the part's scale u (rad): across u's prior ±1σ, [Θ(x + Lσ) − Θ(x − Lσ)]/2σ
        with x = s + L (κ·L where the turn is smooth over it), 0 where the wheel pivots on a corner,
        and where it pivots with the part's scale carried, how far the corner is ahead of its contact (mm; NaN
        elsewhere): a pivot places the contact on the corner, s + L(1 + u) = c, which within the corner window
        widened by the scale's prior is a reading of u (:meth:`update`)."""
        theta, kappa = self._angles.at(length)
        x, window = self.grid + float(length), self.corner_window(length)
        smooth = theta - self._theta0
        corners, jumps = self._convex
        if self._terms > 1 and corners.size:
            window += 3.0 * self.sd_part_scale * abs(float(length))
        model = pivot_turn(self.part, x, self._theta0, smooth, float(turn), window)
        pivoting = model != smooth
        if self._terms > 1:
            # the turn's slope in u across the prior's ±1σ (a secant, not κ·L at u = 0): the readings' u is then
            # judged over the stretch a part off its size puts the contact on, not at a point, which past a
            # face's end at an arc's start (κ stepping) would read a few σ of u as nothing
            step = self.sd_part_scale * float(length)
            ahead_angle, behind_angle = self._angles.at(length + step)[0], self._angles.at(length - step)[0]
            rise = ahead_angle - behind_angle
            arcs, steps = self._steps
            if arcs.size:
                # a corner within the span is the pivot's to read, not a rise of the faces': its jump is taken out
                j, d, _ = nearest_corner(arcs, float(self.part.perimeter), np.mod(x, float(self.part.perimeter)))
                rise = rise - np.where(np.abs(d) < step, steps[j], 0.0)
            secant = rise / (2.0 * self.sd_part_scale)
        else:
            secant = kappa * float(length)
        slope: FloatArray = np.where(pivoting, 0.0, secant)
        ahead = np.full(x.size, math.nan)
        if self._terms > 1 and corners.size and pivoting.any():
            # the place only where the turn is inside the corner's jump beyond its faces' angles over the window
            # (the error of a reading's turn and the faces' machined slope, at the noisiest the stated probability
            # allows): a wheel still on the face before it, or already on the one after, reads a face's angle
            # anywhere, and a face that bends the jump's way towards the corner (a concave arc into it) reads
            # within the jump a few millimetres before it. The faces' angles at the window's ends stand for their
            # extremes over it
            P = float(self.part.perimeter)
            i = np.flatnonzero(pivoting)
            j, d, _ = nearest_corner(corners, P, np.mod(x[i], P))
            after = unwrapped_angle(self.part, x[i] - d) - self._theta0[i]
            before = after - jumps[j]
            before = np.maximum(before, unwrapped_angle(self.part, x[i] - window) - self._theta0[i])
            after = np.minimum(after, unwrapped_angle(self.part, x[i] + window) - self._theta0[i])
            margin = self._turn_margin
            inside = (float(turn) > before + margin) & (float(turn) < after - margin)
            ahead[i[inside]] = -d[inside]
        return model, kappa, slope, ahead
