"""The columns of a study's trials.csv: each trial's, each method's (prefixed with its name), the
finger's and the world's; a contract other tools read (names kept stable). A trial's row is built from
typed parts (:class:`TrialHead`, :class:`RollCells`, :class:`ScoreCells`, :class:`MethodCells`,
:class:`FingerCells`, :class:`WorldCells`), each the cells of one floor of the trial, by :func:`trial_row`."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple, Protocol, TypedDict

if TYPE_CHECKING:
    from sim2d import WorldChange

__all__ = [
    "TRIAL_COLUMNS",
    "METHODS",
    "METHOD_COLUMNS",
    "FINGER_COLUMNS",
    "WORLD_COLUMNS",
    "TrialHead",
    "RollCells",
    "ScoreCells",
    "MethodCells",
    "FingerCells",
    "WorldCells",
    "Rolled",
    "Scored",
    "world_cells",
    "trial_row",
]


#: Columns of trials.csv, in order.
TRIAL_COLUMNS = (
    "level",
    "trial",
    "parameter",
    "value",
    "part",
    "start_arc",
    "true_arc",
    "estimate_arc",
    "error_mm",
    "success",
    "candidates",
    "probability",
    "ambiguous",
    "lengths",
    "turns",
    "restarts",
    "time_s",
    "failure",
)


METHODS = ("paper", "likelihood", "particle", "grid", "reactive")


#: Per-method columns of trials.csv for a study with ``methods``, after TRIAL_COLUMNS.
#: ``stopped``: confident, budget, ambiguous (the reactive method), fixed (the fixed-roll methods) or
#: error; ``mass``: the stated probability within the success radius at the end (empty if the method
#: states none); ``failure``: the method's error text; ``bridges``: bridges the reactive rolling met;
#: ``bound_mm``: the Cramér–Rao bound of the final place from the readings the method took
#: (:func:`bench.methods.method_bound`; empty for a wheel, or without an encoder step);
#: ``mismatch_arc``: where on the model the readings stopped fitting, "A-B" mm (empty when they fit);
#: ``mass_curve``: the stated probability within the success radius at every mark of ``curve``
#: ("5:0.231 10:0.9512 ...", empty if the method states none), for its calibration along the rolling.
METHOD_COLUMNS = (
    "success",
    "error_mm",
    "estimate_arc",
    "rotation_deg",
    "curve",
    "stopped",
    "mass",
    "failure",
    "bridges",
    "bound_mm",
    "mismatch_arc",
    "mass_curve",
)


#: Columns of a study that names its finger: the finger, how many uniform draws over the boundary were
#: redrawn before one the finger can start from, the fraction of the boundary it can start from, and
#: the arc a wheel rolled (mm; empty for the straight jaw).
FINGER_COLUMNS = ("jaw", "redraws", "reachable", "arc_mm")


#: Columns of a study with a ``[world]`` table: the defects' centres (model arc, mm), signed heights and
#: lengths along the arc (mm), space-separated, the world's scale, and the wrist's spikes in the localizing
#: rig's readings.
WORLD_COLUMNS = (
    "world_defect_arc",
    "world_defect_height_mm",
    "world_scale",
    "world_spikes",
    "world_defect_length_mm",
)


class TrialHead(TypedDict):
    """The trial's first cells, drawn before anything else: its level, number, the swept parameter and its
    value, and the part file's name."""

    level: int
    trial: int
    parameter: str
    value: str | float | None
    part: str


class RollCells(TypedDict):
    """What the finger's rolling tells of a trial: where it started (model arc, mm), how often the start
    was redrawn because the rig refused it, and the fixed rolls' lengths (mm) and turns (rad) as
    space-separated text (empty for a wheel, or where they could not run)."""

    start_arc: float
    restarts: int
    lengths: str
    turns: str


class ScoreCells(TypedDict):
    """The trial's own verdict: the true contact at the end, the estimate and its error (mm), success,
    the rule's candidates (empty for a wheel), the best's probability, whether ambiguous, and why the
    trial failed ("" when it did not). With ``methods``, the estimate is the first method's."""

    true_arc: float
    estimate_arc: float
    error_mm: float
    success: int
    candidates: int | str
    probability: float
    ambiguous: int
    failure: str


class MethodCells(TypedDict):
    """One method's :data:`METHOD_COLUMNS` cells, before they are prefixed with its name."""

    success: int
    error_mm: float
    estimate_arc: float
    rotation_deg: float
    curve: str
    stopped: str
    mass: float | str
    failure: str
    bridges: int | str
    bound_mm: float | str
    mismatch_arc: str
    mass_curve: str


class FingerCells(TypedDict):
    """The :data:`FINGER_COLUMNS` cells."""

    jaw: str
    redraws: int
    reachable: float
    arc_mm: float | str


class WorldCells(TypedDict):
    """The :data:`WORLD_COLUMNS` cells (each empty before a world was drawn)."""

    world_defect_arc: str
    world_defect_height_mm: str
    world_scale: float | str
    world_spikes: int | str
    world_defect_length_mm: str


class Rolled(Protocol):
    """A finger's rolling, as the row takes it: its cells, the finger's cells (None where the study does not
    name its finger) and the world it rolled in (None: the model as machined, or none was drawn)."""

    @property
    def cells(self) -> RollCells: ...

    @property
    def finger(self) -> FingerCells | None: ...

    @property
    def change(self) -> WorldChange | None: ...


class Scored(NamedTuple):
    """A trial's scores: its own cells, every method's by name, and the wrist's spiked readings in the
    localizing rig ("" where no rig rolled)."""

    cells: ScoreCells
    methods: dict[str, MethodCells]
    spikes: int | str


def trial_row(head: TrialHead, rolled: Rolled, scored: Scored, seconds: float, *, world: bool) -> dict[str, Any]:
    """The trials.csv row of a trial that took ``seconds``: its typed parts as one flat mapping, each
    method's cells prefixed with its name; ``world``: the study has a ``[world]`` table (its columns)."""
    row: dict[str, Any] = {**head, **rolled.cells, **scored.cells, "time_s": seconds}
    for name, cells in scored.methods.items():
        row.update({f"{name}_{key}": value for key, value in cells.items()})
    if rolled.finger is not None:
        row.update(rolled.finger)
    if world:
        row.update(world_cells(rolled.change, scored.spikes))
    return row


def world_cells(change: WorldChange | None, spikes: int | str = "") -> WorldCells:
    """The :data:`WORLD_COLUMNS` cells of a trial in world ``change`` (empty before one was drawn)."""
    if change is None:
        return {
            "world_defect_arc": "",
            "world_defect_height_mm": "",
            "world_scale": "",
            "world_spikes": "",
            "world_defect_length_mm": "",
        }
    return {
        "world_defect_arc": " ".join(f"{d.arc:.3f}" for d in change.defects),
        "world_defect_height_mm": " ".join(f"{d.height:.4f}" for d in change.defects),
        "world_scale": change.scale,
        "world_spikes": spikes,
        "world_defect_length_mm": " ".join(f"{d.length:.3f}" for d in change.defects),
    }
