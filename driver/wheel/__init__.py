"""The wheel finger on a rig: the disc's rolling step by step (jumps, slip, a drawing's corners), its
calibration (radius and mount, from a roll on the part) and localizing with it (docs/wheel.md).
"""

from .calibration import CALIBRATION_LENGTH, calibrate_wheel, check_calibration, load_calibration, wheel_calibration_arc
from .disc import (
    JUMP_FLOOR,
    JUMP_MISMATCH,
    WHEEL_POLICY,
    AxleEncoder,
    WheelCalibration,
    WheelDisc,
    WheelPolicy,
    axle_travel,
    corner_pivot,
    kappa_band,
)
from .rolling import MAX_RESTARTS, UNEXPLAINED_JUMP, WheelRun, WheelSlip, localize_with_wheel

__all__ = [
    "CALIBRATION_LENGTH",
    "calibrate_wheel",
    "check_calibration",
    "load_calibration",
    "wheel_calibration_arc",
    "AxleEncoder",
    "JUMP_FLOOR",
    "JUMP_MISMATCH",
    "WHEEL_POLICY",
    "WheelCalibration",
    "WheelDisc",
    "WheelPolicy",
    "axle_travel",
    "corner_pivot",
    "kappa_band",
    "MAX_RESTARTS",
    "UNEXPLAINED_JUMP",
    "WheelRun",
    "WheelSlip",
    "localize_with_wheel",
]
