"""Where a finger touches the part and where the contact goes as it rolls: the straight jaw's
reach and tracks, the wheel finger and what the model says of its rolling, and the arc rolled
from what the jaw measured.
"""

from ._reach import DEFAULT_JAW, Reach, StraightJaw, calibration_arc, reach_for
from ._rolling import arc_from_jaw_positions
from ._tracks import BRIDGE_EXCESS, PIVOT_KAPPA, ModeTracks, grid_size, tracks_for
from ._wheel import Finger, WheelJaw, WheelReach, parse_jaw, wheel_reach_for
from ._wheel_rolling import ShiftedGrid, free_runs, jump_runs, pivot_turn, unwrapped_angle

__all__ = [
    "DEFAULT_JAW",
    "Reach",
    "StraightJaw",
    "calibration_arc",
    "reach_for",
    "arc_from_jaw_positions",
    "BRIDGE_EXCESS",
    "PIVOT_KAPPA",
    "ModeTracks",
    "grid_size",
    "tracks_for",
    "Finger",
    "WheelJaw",
    "WheelReach",
    "parse_jaw",
    "wheel_reach_for",
    "ShiftedGrid",
    "free_runs",
    "jump_runs",
    "pivot_turn",
    "unwrapped_angle",
]
