"""Pure geometry and estimation for localization by rolling (numpy and scipy only)."""

from ._belief import Belief, Mode
from ._bound import TrialNoise, roll_bound, trial_bound
from ._boundary import Boundary
from ._cad import CAD_SUFFIXES, load_outline
from ._contact_filter import (
    BRIDGE_MISS,
    CONTRADICTION,
    ENCODER_SD,
    LOOKALIKE_RADIUS,
    LOOKALIKE_SLOPE,
    NOISE_SCALES,
    SCALE_SD,
    SLOPE_ENVELOPE,
    TEMPER,
    ContactFilter,
)
from ._defaults import (
    CALIBRATION_SCALE_SD,
    CONFIDENCE,
    FIT_ALPHA,
    LENGTH_TOL,
    MIN_SEPARATION,
    PART_SCALE_SD,
    ROLL_STEP,
    SUCCESS_RADIUS,
    TURN_TOL,
)
from ._disambiguate import RULES, Candidate, Localization, localize
from ._errors import LocalizerError, PartError, QueryError, RolltouchError
from ._facets import FACETS, FacetRule, read_facets
from ._files import load_part
from ._fingerprint import QUANTUM_MM, fingerprint
from ._limits import (
    MAX_ARRAY_BYTES,
    MAX_GRID_POINTS,
    MAX_PAIRWISE_POINTS,
    MAX_PART_BYTES,
    MAX_PIECES,
    check_grid,
    check_size,
    read_toml,
)
from ._march import PAPER_MARCH, MarchGrid, MarchOptions, MarchResult, march, march_grid
from ._outline import Corner, Outline, outline_from_pieces
from ._outline_solver import outline_segments
from ._part import UNITS_TO_MM, Part, part_from_points, polygon_crossing
from ._particle_filter import ParticleFilter
from ._pieces import CircularArc, CubicBezier, Line, elliptical_arc
from ._reach import DEFAULT_JAW, Reach, StraightJaw, calibration_arc, reach_for
from ._rolling import arc_from_jaw_positions
from ._segment import DIRECTIONS, Segment
from ._solver import EXACT, METHODS, ExactOptions, feasible_segments
from ._stretches import DEFECT_WINDOW, UNEXPLAINED, Misfit
from ._tracks import BRIDGE_EXCESS, PIVOT_KAPPA, ModeTracks, tracks_for
from ._wheel import Finger, WheelJaw, WheelReach, parse_jaw, wheel_reach_for
from ._wheel_filter import (
    WHEEL_FIT_SCALE,
    WHEEL_NOISE_SCALES,
    WHEEL_SD_SLOPE,
    WHEEL_SD_TURN,
    WHEEL_SLOPE_LENGTH,
    WheelFilter,
)

__all__ = [
    "Boundary",
    "Line",
    "CircularArc",
    "CubicBezier",
    "elliptical_arc",
    "Outline",
    "Corner",
    "outline_from_pieces",
    "FacetRule",
    "FACETS",
    "read_facets",
    "outline_segments",
    "load_outline",
    "CAD_SUFFIXES",
    "LENGTH_TOL",
    "TURN_TOL",
    "MIN_SEPARATION",
    "SUCCESS_RADIUS",
    "CONFIDENCE",
    "ROLL_STEP",
    "FIT_ALPHA",
    "PART_SCALE_SD",
    "CALIBRATION_SCALE_SD",
    "SCALE_SD",
    "DEFECT_WINDOW",
    "UNEXPLAINED",
    "Misfit",
    "MAX_PART_BYTES",
    "MAX_PIECES",
    "MAX_GRID_POINTS",
    "MAX_PAIRWISE_POINTS",
    "MAX_ARRAY_BYTES",
    "check_size",
    "check_grid",
    "read_toml",
    "ContactFilter",
    "ParticleFilter",
    "Belief",
    "Mode",
    "ModeTracks",
    "tracks_for",
    "BRIDGE_EXCESS",
    "PIVOT_KAPPA",
    "NOISE_SCALES",
    "SLOPE_ENVELOPE",
    "LOOKALIKE_SLOPE",
    "LOOKALIKE_RADIUS",
    "TEMPER",
    "CONTRADICTION",
    "BRIDGE_MISS",
    "ENCODER_SD",
    "StraightJaw",
    "WheelJaw",
    "WheelReach",
    "wheel_reach_for",
    "WheelFilter",
    "WHEEL_SD_TURN",
    "WHEEL_SD_SLOPE",
    "WHEEL_SLOPE_LENGTH",
    "WHEEL_NOISE_SCALES",
    "WHEEL_FIT_SCALE",
    "parse_jaw",
    "Finger",
    "DEFAULT_JAW",
    "Reach",
    "reach_for",
    "calibration_arc",
    "RolltouchError",
    "LocalizerError",
    "PartError",
    "QueryError",
    "Part",
    "load_part",
    "fingerprint",
    "QUANTUM_MM",
    "part_from_points",
    "polygon_crossing",
    "UNITS_TO_MM",
    "Segment",
    "feasible_segments",
    "ExactOptions",
    "EXACT",
    "MarchOptions",
    "PAPER_MARCH",
    "METHODS",
    "DIRECTIONS",
    "Candidate",
    "Localization",
    "localize",
    "RULES",
    "march",
    "march_grid",
    "MarchResult",
    "MarchGrid",
    "arc_from_jaw_positions",
    "roll_bound",
    "trial_bound",
    "TrialNoise",
]
