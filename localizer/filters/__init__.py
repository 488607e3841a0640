"""Sequential localization while rolling: the belief a filter reports, the straight jaw's grid
filter, the wheel's filter, the particle filter (the conventional peer), and the stretches of
readings a belief must not rest on when the part is not its model.
"""

from ._belief import Belief, Mode, mass_within, most_probable
from ._contact_filter import ContactFilter
from ._contact_settings import (
    BRIDGE_MISS,
    CONTRADICTION,
    ENCODER_SD,
    LOOKALIKE_RADIUS,
    LOOKALIKE_SLOPE,
    NOISE_SCALES,
    SCALE_SD,
    SLOPE_ENVELOPE,
    STRETCH_WEIGHT,
    TEMPER,
)
from ._particle_filter import ParticleFilter
from ._stretches import DEFECT_WINDOW, NOISE_FIT_LIMIT, UNEXPLAINED, Misfit
from ._wheel_filter import (
    WHEEL_FIT_SCALE,
    WHEEL_NOISE_SCALES,
    WHEEL_SD_SLOPE,
    WHEEL_SD_TURN,
    WHEEL_SLOPE_LENGTH,
    WheelFilter,
)
from ._wheel_scale import OFF_SCALE, OFF_SCALE_DOUBT, PartScale, Spread

__all__ = [
    "OFF_SCALE",
    "OFF_SCALE_DOUBT",
    "Spread",
    "PartScale",
    "Belief",
    "Mode",
    "most_probable",
    "mass_within",
    "BRIDGE_MISS",
    "CONTRADICTION",
    "ENCODER_SD",
    "LOOKALIKE_RADIUS",
    "LOOKALIKE_SLOPE",
    "STRETCH_WEIGHT",
    "NOISE_SCALES",
    "SCALE_SD",
    "SLOPE_ENVELOPE",
    "TEMPER",
    "ContactFilter",
    "ParticleFilter",
    "DEFECT_WINDOW",
    "UNEXPLAINED",
    "NOISE_FIT_LIMIT",
    "Misfit",
    "WHEEL_FIT_SCALE",
    "WHEEL_NOISE_SCALES",
    "WHEEL_SD_SLOPE",
    "WHEEL_SD_TURN",
    "WHEEL_SLOPE_LENGTH",
    "WheelFilter",
]
