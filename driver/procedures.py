"""The straight jaw's procedures, written once against :class:`driver.rig.Rig`: its face.

Paper §III-B (calibration without weights) and §III-C (rolling: rotate the jaw by a small angle about
the tool axis, then press back along the jaw normal until Δv1 is back at about 0.4 V). The rooms:
:mod:`driver.hand` (moving and pressing the hand, the wrist's voltages), :mod:`driver.calibration` (the
wrist's calibration and its file), :mod:`driver.rolling` (rolls, bridges, the pipeline),
:mod:`driver.roll_result` (what they return) and :mod:`driver.simulated` (a simulated rig calibrated
as a real one is).

Angles are radians, lengths mm, voltages V. Poses are (x, y, φ) as in :class:`driver.rig.Rig`: pressing
means moving along m = (-sin φ, cos φ).
"""

from __future__ import annotations

from .calibration import Calibration, calibrate
from .hand import (
    ANGLE_SLACK,
    PRESS,
    Hand,
    PressSettings,
    ServoSettings,
    delta_voltages,
    edge_offset,
    establish_contact,
    hold_force,
    press,
    zero,
)
from .roll_result import RollingRun, RollResult
from .rolling import (
    FACE_ANGLE_TOL,
    FACE_JUMP_TOL,
    MAX_ROLL_STEPS,
    STEP_RANGE_DEG,
    crossed_face,
    laid_off,
    localize_by_rolling,
    read_location,
    roll,
    roll_sequence,
    run_from_here,
)
from .simulated import calibrate_simulated

__all__ = [
    "ANGLE_SLACK",
    "Hand",
    "ServoSettings",
    "PressSettings",
    "PRESS",
    "zero",
    "delta_voltages",
    "press",
    "hold_force",
    "establish_contact",
    "edge_offset",
    "Calibration",
    "calibrate",
    "MAX_ROLL_STEPS",
    "STEP_RANGE_DEG",
    "laid_off",
    "RollResult",
    "read_location",
    "roll",
    "RollingRun",
    "FACE_ANGLE_TOL",
    "FACE_JUMP_TOL",
    "crossed_face",
    "roll_sequence",
    "localize_by_rolling",
    "run_from_here",
    "calibrate_simulated",
]
