"""The part's scale against its model, weighed out per start by the wheel's filter: the prior (a spike at the
model's size and a slab off it), u's posterior given a start, and each start's present contact at both sizes
(the model: :mod:`localizer.filters._wheel_filter`; docs/robustness.md, "The wheel on a part off its model's
size").
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.special import log_ndtr

from .._types import FloatArray
from ..geometry import Outline, Part
from ._belief import within

__all__ = [
    "Spread",
    "PartScale",
    "OFF_SCALE",
    "OFF_SCALE_DOUBT",
    "NEGLIGIBLE",
    "LOG_NEGLIGIBLE",
    "weigh_scale",
    "relative_weights",
    "log_add_exp",
]

#: The prior probability that a part is off its model's size by more than its machining (made to another
#: revision's drawing, scaled on export): its scale is then N(1, ``sd_part_scale``²); else its model's
#: (docs/robustness.md, "The wheel on a part off its model's size"). The filter's default: it costs rolling
#: where only the size is left to tell (a wheel enclosed in the bracket's notch is not sure; noise-free rolls
#: on the kidney's concave stretches are sure some 15 mm later); ``off_scale`` 0 takes the part for its
#: model's size.
OFF_SCALE = 0.05
#: The stated probability holds also if the part were off its size with this prior probability (the least
#: under the two is stated, as under the noise scales): where the readings cannot tell the part's size (a
#: face, a near-circular stretch, a short roll) it is the prior's odds that would make the belief sure, and
#: a part that is off its size is sure and wrong there (docs/robustness.md).
OFF_SCALE_DOUBT = 0.5
#: A start weighing less than this times the most probable one adds nothing a stated mass could show (11724
#: starts on the kidney: 1.2e-8 at most, all told).
NEGLIGIBLE = 1e-12


class Spread(NamedTuple):
    """Each start's present contact (mm along the part): at the model's size, and off it.

    Attributes
    ----------
    nominal : ndarray, mm
        The present contact if the part is its model's size.
    off : ndarray, mm
        Its mean if the part is off its model's size (u's posterior mean given the start).
    sd : ndarray, mm
        Its standard deviation then.
    p_off : ndarray
        The posterior probability, given the start, that the part is off its model's size.
    """

    nominal: FloatArray
    off: FloatArray
    sd: FloatArray
    p_off: FloatArray

    def mass(self, part: Part | Outline, w: FloatArray, at: float, radius: float) -> float:
        """The probability, the starts weighed by ``w``, that the present contact is within ``radius`` mm of
        arc ``at``. Starts weighing less than :data:`NEGLIGIBLE` times the most probable one are left out: the
        mass is then low by no more than their number times that."""
        top = float(w.max()) if w.size else 0.0
        if not (math.isfinite(top) and top > 0):
            return 0.0
        k = np.flatnonzero(w > NEGLIGIBLE * top)
        zero = np.zeros(k.size)
        inside = (1.0 - self.p_off[k]) * within(part, self.nominal[k], zero, at, radius)
        inside += self.p_off[k] * within(part, self.off[k], self.sd[k], at, radius)
        return float(np.sum(w[k] * inside))

    @property
    def mean(self) -> FloatArray:
        """The present contact's posterior mean given each start, mm (unwrapped about the nominal one)."""
        out: FloatArray = self.nominal + self.p_off * (self.off - self.nominal)
        return out


class PartScale(NamedTuple):
    """What the wheel's readings say of the part's size against its model's (:meth:`WheelFilter.part_scale`).

    Attributes
    ----------
    probability : float
        The posterior probability that the part is off its model's size (0 where the scale is not carried).
    scale : float
        The part's size over its model's, if it is off it (posterior mean; 1.02: 2% larger).
    sd : float
        Its posterior standard deviation.
    """

    probability: float
    scale: float
    sd: float


def weigh_scale(
    zg: FloatArray, gg: FloatArray, sd_part_scale: float, u_max: FloatArray, penalty_run: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Per start, from the sums Σ z·g and Σ g² of its whitened residuals z and their slopes g in the scale u
    (already tempered and scaled by the noise factor): u's posterior mean and standard deviation given that the
    part is off its model's size (prior N(0, ``sd_part_scale``²)), and the log of the readings' factor off the
    model's size against at it, before the prior's odds.

    The arc rolled either way is a reading of u too: a part off its size by u puts the roll on L(1 + u) of the
    model, which runs over no point the wheel cannot pass for u ≤ ``u_max`` (per start). With probability
    Φ((u_max − û)/σ_u) under u's posterior the start's roll is clear, and the model's size's contradictions
    (``penalty_run``, a log ≤ 0, what the model's size counts for the roll running over such points) are
    taken back; else they stand. A part a little large explains a roll a little past a free run, a part far
    off its size (in the prior's tail) hardly more than the model's size does."""
    prec = 1.0 / sd_part_scale**2 + gg
    mean: FloatArray = zg / prec
    sd: FloatArray = 1.0 / np.sqrt(prec)
    evidence: FloatArray = 0.5 * zg * mean - 0.5 * np.log1p(gg * sd_part_scale**2)
    k = np.flatnonzero(penalty_run < 0)  # elsewhere the roll is clear at the model's size: nothing to take back
    if k.size:
        clear = log_ndtr((u_max[k] - mean[k]) / sd[k])
        evidence[k] += log_add_exp(clear - penalty_run[k], log_ndtr((mean[k] - u_max[k]) / sd[k]))
    return mean, sd, evidence


#: Below this log-weight against the best, a start's weight is taken as 0: e^−700 ≈ 1e-304, nothing a sum or
#: a stated mass could show, where numpy's exp takes its slow path for subnormal results (ten times the
#: cost on a belief of the kidney's 11724 starts).
LOG_NEGLIGIBLE = -700.0


def relative_weights(log_w: FloatArray, top: float | FloatArray) -> FloatArray:
    """e^(log_w − top) elementwise (``top`` at least ``log_w``), 0 below :data:`LOG_NEGLIGIBLE`."""
    x = np.subtract(log_w, top)
    out: FloatArray = np.zeros(x.shape)
    np.exp(x, out=out, where=x > LOG_NEGLIGIBLE)
    return out


def log_add_exp(a: FloatArray | float, b: FloatArray) -> FloatArray:
    """log(eᵃ + eᵇ) elementwise, one of ``a`` and ``b`` finite: :func:`numpy.logaddexp` at a third of its cost
    on this machine."""
    out: FloatArray = np.maximum(a, b) + np.log1p(relative_weights(-np.abs(np.subtract(a, b)), 0.0))
    return out
