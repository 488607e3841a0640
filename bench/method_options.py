"""A study's settings of its methods: the reactive method's ([reactive]: confidence, budget, the filter's
noise settings and rules) and the particle filter's ([particle]), each defaulting to the method's own."""

from __future__ import annotations

import math
from dataclasses import dataclass

from driver.jaw import MAX_ROTATION
from localizer import (
    CONFIDENCE,
    OFF_SCALE,
)

__all__ = ["ReactiveOptions", "ParticleOptions"]


@dataclass(frozen=True)
class ReactiveOptions:
    """[reactive] of a study file (see :func:`driver.jaw.reactive.localize_reactively`)."""

    confidence: float = CONFIDENCE
    max_rotation_deg: float = round(math.degrees(MAX_ROTATION), 9)
    check_every: int = 5
    confirm: int | None = None  # None: driver.jaw.CONFIRM (checks in a row at the confidence)
    sd_position: float | None = None  # None: the filter's default
    sd_scale: float | None = None
    sd_slope: float | str | None = None  # "auto": from the study's noise model
    min_spread: float = 0.05
    seek: bool | None = None  # None: driver.jaw.ReactivePolicy's (seeking information); false: the baseline
    noise_scales: tuple[float, ...] | None = None  # None: localizer.NOISE_SCALES
    temper: float | None = None  # None: the filter's default
    shape_spacing: float | None = None  # None: the filter's default (mm between the slope basis' knots)
    slope_envelope: tuple[float, ...] | None = None  # None: localizer.SLOPE_ENVELOPE; []: the slope prior alone
    defect_window: float | None = None  # None: localizer.DEFECT_WINDOW (mm); 0: trust every stretch, test none
    lookalike_slope: float | None = None  # None: localizer.LOOKALIKE_SLOPE; 0: no look-alike check
    corner_ends: bool | None = None  # None: the filter's default (True); false: the uniform prior over a corner
    stretch_weight: float | None = None  # None: localizer.STRETCH_WEIGHT; 1: the least of the checks
    off_scale: float = OFF_SCALE  # the wheel: prior probability the part is off its model's size; 0: its model's


@dataclass(frozen=True)
class ParticleOptions:
    """[particle] of a study file (see :class:`localizer.ParticleFilter`)."""

    particles: int = 2000
    sd_position: float = 0.04
    process: float = 0.005
