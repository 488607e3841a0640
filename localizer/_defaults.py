"""The paper's constants and the package's defaults, each defined once and imported where used.

Jia (2005) states the tolerances of its marching algorithm (§II-C, §IV: "ε-close" in length
and turn), the separation below which two feasible segments are one, the success radius of its
experiments and the rolling step of its arm (0.2°, §IV).
"""

import math

__all__ = [
    "LENGTH_TOL",
    "TURN_TOL",
    "MIN_SEPARATION",
    "SUCCESS_RADIUS",
    "CONFIDENCE",
    "ROLL_STEP",
    "FIT_ALPHA",
    "PART_SCALE_SD",
    "CALIBRATION_SCALE_SD",
    "SD_LENGTH",
    "SD_TURN",
    "BRIDGE_JUMP",
]

#: The paper's tolerance on a segment's contact travel, mm.
LENGTH_TOL = 0.004
#: The paper's tolerance on a segment's rotation, rad.
TURN_TOL = 0.0004
#: Feasible starts closer than this are one segment, mm.
MIN_SEPARATION = 0.5
#: A localization is a success when its estimate is within this of the true contact, mm.
SUCCESS_RADIUS = 0.3
#: A belief is sure when its probability within the success radius reaches this: the sequential filters'
#: and the two-roll rules' default, and the rolling's stop.
CONFIDENCE = 0.95
#: The arm's rolling step, rad (0.2°).
ROLL_STEP = math.radians(0.2)
#: Readings whose best fit is this improbable under the noise model fit no place on the part: the
#: χ² test's level (a real fit fails it once in 10 000 chains; a stuck encoder or a misread turn of
#: degrees as radians fails it by hundreds of standard deviations).
FIT_ALPHA = 1e-4
#: The relative error of the straight jaw's contact-place calibration's scale (measured 0.1–0.5% on the
#: simulated rig), one standard deviation.
CALIBRATION_SCALE_SD = 0.003
#: How much larger or smaller than its model a real part may be, relative, one standard deviation: a
#: uniform scale of the part is a scale of every arc the rolling measures, which the filters carry with
#: the calibration's as one nuisance (a part 2% off its drawing at two standard deviations: a worn
#: die, a part cast to another shrinkage, a drawing at another revision's size).
PART_SCALE_SD = 0.01
#: The standard deviation of a measured contact travel L the two-roll rules are told unless the user
#: says otherwise, mm: wider than a calibrated rig's (0.3 mm at the `paper` preset, which the studies
#: tell them) so that an uncalibrated first run is not over-sure.
SD_LENGTH = 0.5
#: The standard deviation of a measured rotation the two-roll rules are told, rad: the arm encoder's
#: 0.03° step.
SD_TURN = math.radians(0.03)
#: A step in which the contact's place on a straight jaw moves more than this, mm, is a bridge: the jaw
#: left the part and landed on it elsewhere (the rolling stops or undoes it; the filter weighs it).
BRIDGE_JUMP = 3.0
