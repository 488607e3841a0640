"""The straight jaw's filter: its constants and the defaults of its settings, each defined once.

Why each has its value: docs/filter.md."""

from __future__ import annotations

import math

from .._defaults import CALIBRATION_SCALE_SD, PART_SCALE_SD

__all__ = [
    "NOISE_SCALES",
    "TEMPER",
    "SLOPE_ENVELOPE",
    "CONTRADICTION",
    "BRIDGE_MISS",
    "ENCODER_SD",
    "RHO_MAX",
    "FACE_SLOPES",
    "SLOPE_RHO_MAX",
    "LOOKALIKE_SLOPE",
    "LOOKALIKE_RADIUS",
    "TURN_MARGIN",
    "SCALE_SD",
    "STRETCH_BATCH",
    "STRETCH_WEIGHT",
]

#: Factors on the filter's noise settings it weighs when it is not sure of them (docs/filter.md): a
#: log-uniform prior in steps of 2^(1/4) from a quarter to sixteen times what it was told. The
#: steps are fine because with hundreds of readings the scale's posterior is sharp (a few per cent):
#: a coarse grid would round it, and an underestimated scale overstates the evidence.
NOISE_SCALES = tuple(float(2.0 ** (k / 4)) for k in range(-8, 17))
#: The power on the readings' likelihood: the evidence counts half (docs/filter.md, "Trust").
TEMPER = 0.5
#: Other factors on ``sd_slope`` under which the stated mass must hold as well (docs/filter.md, "Trust"):
#: the belief's mass is the least over the slope priors (1, then these).
SLOPE_ENVELOPE = (0.25, 2.0)
#: Probability that one reading puts the contact where the jaw cannot touch under the true start
#: (a jaw position misread by more than ``jaw_margin``, a model error in the part's reach).
CONTRADICTION = 1e-3
#: Probability that the rig reports a bridge where the jaw surely clears (a press refused for
#: another reason).
BRIDGE_MISS = 0.05
#: Standard deviation of one reading of the arm's rotation, rad: its encoder's 0.03° step (the
#: Adept Cobra 600, paper §IV), a uniform error.
ENCODER_SD = math.radians(0.03) / math.sqrt(12.0)
#: The largest radius of curvature, mm, the error model takes: the slope error's and the rotation
#: reading's effects on the contact grow with ρ, and on a straight stroke of a glyph or a flat side
#: (ρ of metres) the readings cannot place the contact along it, which the model must say.
RHO_MAX = 5000.0
#: How many of the machined slope's standard deviations (``sd_slope``) past a face's angle the jaw must have
#: turned before its contact is taken to have left the face: a face machined wavy by microns over
#: millimetres is locally tilted by several (docs/filter.md, "A face just crossed").
FACE_SLOPES = 5.0
#: The largest radius, mm, the slope term's prior takes: beyond it the offset's prior is so wide
#: (metres times mrad) that it makes the marginalisation ill-conditioned, and it is already wide
#: enough to leave the contact's place on such a stretch to the other readings.
SLOPE_RHO_MAX = 1000.0
#: The factor on ``sd_slope`` under which a look-alike place must be ruled out too (docs/filter.md, "A part
#: that is not its model"): a part a few hundredths of a millimetre off its drawing, where that error
#: changes over a few millimetres, has slopes several mrad off, which at ρ = 30 mm moves the contact
#: 0.3 mm along a roll: more than what can tell a feature from its look-alike elsewhere on the part.
LOOKALIKE_SLOPE = 8.0
#: How near, mm, a start's nominal present contact must be to the most probable one to count as the same
#: place in the look-alike check: farther is another feature of the part; nearer, the envelope's
#: radius judges the spread.
LOOKALIKE_RADIUS = 3.0
#: How far, rad, a rotation may run past the model's end of a convex stretch and keep the contact
#: at that end: the machined part's slope differs from the model's by 0.6 mrad RMS at the `paper`
#: preset, peaks of 10 mrad at five times that.
TURN_MARGIN = 0.02
#: The prior standard deviation of the scale of every measured arc against the model's: the
#: calibration's and the part's own (docs/filter.md, "A part that is not its model").
SCALE_SD = math.hypot(CALIBRATION_SCALE_SD, PART_SCALE_SD)

#: How many stretches of readings are left out at once (one batched solve; its arrays are this many
#: times the filter's own, so early in a rolling, with every start live, a few tens of MB at most).
STRETCH_BATCH = 8

#: The prior probability that a short stretch of the readings comes from a defect the model does not have
#: (a burr, a dent, debris): the weight of the stretch check in the stated mass (docs/filter.md, "A stretch
#: check that weighs"). 1: the least of the stretch check's mass and the rest, a veto. At 0.06 the tuning
#: family against its model resampled was sure and wrong on 18 of 184 sure stops, up to 293 mm off (4 of 160,
#: under 0.8 mm, at 1).
STRETCH_WEIGHT = 1.0
