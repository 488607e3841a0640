"""What every method's score shares: where the jaw is laid, the error of an estimate on the part's
boundary, the rotation curve's marks and their text in trials.csv, and the cells of a method, or of a
whole trial, that could not run."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, TypeAlias, TypedDict

import numpy as np
import numpy.typing as npt

from .columns import MethodCells, ScoreCells, Scored

if TYPE_CHECKING:
    from localizer import Outline, Part


__all__ = [
    "failed_method",
    "broken_trial",
    "RuleResult",
    "MethodResult",
    "FloatArray",
    "MARK_DEG",
    "JAW_START",
    "ENCODER_SLACK_DEG",
    "curve_cell",
    "mass_cell",
    "parse_curve",
    "boundary_error",
]


FloatArray: TypeAlias = npt.NDArray[np.float64]


class RuleResult(TypedDict):
    """A localizer rule on the fixed rolls, as the study's own columns take it: the estimate (mm), its
    error (mm), how many candidates, the best's probability, whether ambiguous, the stated mass within
    the success radius ("" where the rule failed) and why it failed ("" when it did not)."""

    estimate_arc: float
    error_mm: float
    candidates: int
    probability: float
    ambiguous: int
    mass: float | str
    failure: str


class MethodResult(TypedDict, total=False):
    """One method scored on one trial (:data:`bench.methods.SCORERS`), before it becomes the trial's
    ``<method>_*`` cells: the estimate and its error (mm), the rotation it used (degrees), its error at
    every mark of rotation, how it stopped, its stated mass, why it failed; a method that rolls on its own
    also the bridges it met, its true path (for its bound), where the part seemed to differ from its model
    and its rig's spiked readings."""

    estimate_arc: float
    error_mm: float
    rotation_deg: float
    curve: list[tuple[float, float]]
    mass_curve: list[tuple[float, float]]
    stopped: str
    mass: float | str
    failure: str
    bridges: int | str
    path: tuple[tuple[float, ...], tuple[int, ...]]
    mismatch_arc: str
    spikes: int


MARK_DEG = 5.0


#: Where the jaw is laid on the part: the contact this far (mm) from the jaw's centre, behind it in
#: the rolling direction, so that most of the jaw lies ahead.
JAW_START = 40.0


#: How far short of a mark (degrees) a measured turn still reaches it: more than the encoder's step.
ENCODER_SLACK_DEG = 0.05


def curve_cell(pairs: Iterable[tuple[float, float]]) -> str:
    """A ``<method>_curve`` cell: "5:0.4120 10:0.1080 ..." (mark deg, error mm)."""
    return " ".join(f"{r:g}:{e:.4f}" for r, e in pairs)


def mass_cell(pairs: Iterable[tuple[float, float]]) -> str:
    """A ``<method>_mass_curve`` cell: "5:0.231 10:0.9512 ..." (mark deg, stated probability within the
    success radius; six significant digits, enough to tell 0.9999 from 0.99999; "nan" where none)."""
    return " ".join(f"{r:g}:{p:.6g}" for r, p in pairs)


def parse_curve(text: str) -> list[tuple[float, float]]:
    """[(rotation deg, value), ...] of a ``<method>_curve`` (error mm) or ``<method>_mass_curve`` cell."""
    out = []
    for item in str(text or "").split():
        r, e = item.split(":")
        out.append((float(r), float(e)))
    return out


def boundary_error(part: Part | Outline, est: float, truth: float) -> float:
    if not (math.isfinite(est) and math.isfinite(truth)):
        return math.inf
    return abs(float(part.arc_offset(est, truth)))


def failed_method(text: str) -> MethodCells:
    """The cells of a method that could not run on a trial: ``text`` why."""
    return {
        "success": 0,
        "error_mm": math.inf,
        "estimate_arc": math.nan,
        "rotation_deg": math.nan,
        "curve": "",
        "stopped": "error",
        "mass": "",
        "failure": text,
        "bridges": "",
        "bound_mm": "",
        "mismatch_arc": "",
        "mass_curve": "",
    }


def broken_trial(methods: Sequence[str], text: str, candidates: int | str = 0) -> Scored:
    """The scores of a trial that broke before any method could run: every method's failure ``text``
    (``candidates``: the rule's count, a wheel's empty cell)."""
    cells: ScoreCells = {
        "true_arc": math.nan,
        "estimate_arc": math.nan,
        "error_mm": math.inf,
        "success": 0,
        "candidates": candidates,
        "probability": 0.0,
        "ambiguous": 0,
        "failure": text,
    }
    return Scored(cells, {m: failed_method(text) for m in methods}, "")
