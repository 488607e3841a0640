"""The columns of a study's trials.csv: each trial's, each method's (prefixed with its name), the
finger's and the world's; a contract other tools read (names kept stable)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sim2d import WorldChange

__all__ = ["TRIAL_COLUMNS", "METHODS", "METHOD_COLUMNS", "FINGER_COLUMNS", "WORLD_COLUMNS", "world_cells"]


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
#: ``mismatch_arc``: where on the model the readings stopped fitting, "A-B" mm (empty when they fit).
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
)


#: Columns of a study that names its finger: the finger, how many uniform draws over the boundary were
#: redrawn before one the finger can start from, the fraction of the boundary it can start from, and
#: the arc a wheel rolled (mm; empty for the straight jaw).
FINGER_COLUMNS = ("jaw", "redraws", "reachable", "arc_mm")


#: Columns of a study with a ``[world]`` table: the defects' centres (model arc, mm) and signed heights
#: (mm), space-separated, the world's scale, and the wrist's spikes in the localizing rig's readings.
WORLD_COLUMNS = ("world_defect_arc", "world_defect_height_mm", "world_scale", "world_spikes")


def world_cells(change: WorldChange | None, spikes: int | str = "") -> dict[str, Any]:
    """The :data:`WORLD_COLUMNS` cells of a trial in world ``change`` (empty before one was drawn)."""
    if change is None:
        return {"world_defect_arc": "", "world_defect_height_mm": "", "world_scale": "", "world_spikes": ""}
    return {
        "world_defect_arc": " ".join(f"{d.arc:.3f}" for d in change.defects),
        "world_defect_height_mm": " ".join(f"{d.height:.4f}" for d in change.defects),
        "world_scale": change.scale,
        "world_spikes": spikes,
    }
