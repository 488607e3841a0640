"""One roll, solved: every stretch of a part's boundary where a roll of contact travel L and
rotation Ω can have been (the exact solvers on splines and outlines with their certificates and
tables, and Jia's marching algorithm as the reference), and the Cramér–Rao bound of one roll.
"""

from ._bound import TrialNoise, roll_bound, trial_bound
from ._march import PAPER_MARCH, MarchOptions, MarchResult, march
from ._march_grid import MarchGrid, march_grid
from ._outline_solver import outline_segments
from ._segment import DIRECTIONS, Segment
from ._solver import EXACT, METHODS, ExactOptions, feasible_segments

__all__ = [
    "TrialNoise",
    "roll_bound",
    "trial_bound",
    "PAPER_MARCH",
    "MarchGrid",
    "MarchOptions",
    "MarchResult",
    "march",
    "march_grid",
    "outline_segments",
    "DIRECTIONS",
    "Segment",
    "EXACT",
    "METHODS",
    "ExactOptions",
    "feasible_segments",
]
