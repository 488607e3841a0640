"""The straight jaw, written once against :class:`driver.rig.Rig`: its hand (moving, pressing to the
force), the wrist's calibration and its file, rolling with bridge detection and the two-roll
pipeline (paper §III), and reactive localization (roll, update, stop when sure).
"""

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
from .reactive import localize_reactively
from .reactive_policy import (
    BOXED_ROTATION,
    CONFIRM,
    MAX_LEAVES,
    MAX_MOVES,
    MAX_RESTARTS,
    MAX_ROTATION,
    MOVE_BUDGET,
    REACTIVE_POLICY,
    SEEK_HYPOTHESES,
    ReactivePolicy,
    ReactiveRun,
    clear_ahead,
    information_by_direction,
    spread_by_direction,
)
from .reactive_sensing import JawReadings
from .reactive_verdict import PLACE_RADIUS, holds_place
from .roll_result import RollingRun, RollResult, step_sequence
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
    "PLACE_RADIUS",
    "holds_place",
    "step_sequence",
    "Calibration",
    "calibrate",
    "ANGLE_SLACK",
    "Hand",
    "PRESS",
    "PressSettings",
    "ServoSettings",
    "delta_voltages",
    "edge_offset",
    "establish_contact",
    "hold_force",
    "press",
    "zero",
    "localize_reactively",
    "CONFIRM",
    "REACTIVE_POLICY",
    "MAX_LEAVES",
    "MAX_RESTARTS",
    "BOXED_ROTATION",
    "MAX_MOVES",
    "MOVE_BUDGET",
    "MAX_ROTATION",
    "ReactivePolicy",
    "ReactiveRun",
    "clear_ahead",
    "spread_by_direction",
    "information_by_direction",
    "SEEK_HYPOTHESES",
    "JawReadings",
    "RollResult",
    "RollingRun",
    "FACE_ANGLE_TOL",
    "FACE_JUMP_TOL",
    "MAX_ROLL_STEPS",
    "STEP_RANGE_DEG",
    "crossed_face",
    "laid_off",
    "localize_by_rolling",
    "read_location",
    "roll",
    "roll_sequence",
    "run_from_here",
    "calibrate_simulated",
]
