"""The reactive method of a study, scored on a trial: the filter and the policy a study's [reactive] table
describes, the run on a fresh rig from the trial's start, and its cells (error, rotation, the rotation
curve, how it stopped, where the part seemed to differ from its model); a wheel's run is scored as the
reactive method too (:func:`score_wheel`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from .columns import MethodCells, ScoreCells, Scored
from .scoring import JAW_START, MARK_DEG, MethodResult, boundary_error, broken_trial, curve_cell, mass_cell

if TYPE_CHECKING:
    from driver.jaw import Calibration, ReactivePolicy, ReactiveRun
    from driver.wheel import WheelRun
    from localizer import Belief, ContactFilter, Outline, Part
    from sim2d import NoiseModel, WorldChange

    from .study import Study

__all__ = [
    "reactive_filter",
    "reactive_policy",
    "reactive_stop",
    "rotation_curve",
    "score_reactive",
    "score_wheel",
    "mismatch_cell",
]


def reactive_filter(
    study: Study, part: Part | Outline, noise: NoiseModel, filter_class: type[ContactFilter] | None = None
) -> ContactFilter:
    """The ContactFilter a study's [reactive] options describe (``filter_class``: a subclass to build
    instead, e.g. :class:`bench.replay.FilterRecorder`).

    Standard deviations not given are the filter's own defaults; ``sd_slope = "auto"`` takes 5x the
    study's noise model's RMS slope (machined parts vary: measured 0.8e-3 to 1.9e-3 rad RMS at the
    paper preset, whose model RMS is 0.6e-3, and the basis' coefficients are not its values).
    """
    from localizer import ContactFilter
    from sim2d import machining_slope

    o = study.reactive
    given = {k: getattr(o, k) for k in ("sd_position", "sd_scale", "sd_slope") if getattr(o, k) is not None}
    if given.get("sd_slope") == "auto":
        given["sd_slope"] = max(
            5.0 * machining_slope(noise.machining_error, noise.machining_wavelength, part.perimeter), 5e-4
        )
    for key in ("noise_scales", "slope_envelope"):
        if getattr(o, key) is not None:
            given[key] = getattr(o, key)
    for key in ("temper", "shape_spacing", "defect_window", "lookalike_slope", "corner_ends", "stretch_weight"):
        if getattr(o, key) is not None:
            given[key] = getattr(o, key)
    cls = ContactFilter if filter_class is None else filter_class
    return cls(part, radius=study.success_radius, confidence=o.confidence, **given)


def reactive_policy(study: Study) -> ReactivePolicy:
    """The :class:`driver.jaw.ReactivePolicy` a study's ``[reactive]`` table and rolling step describe."""
    from driver.jaw import CONFIRM, ReactivePolicy

    o = study.reactive
    return ReactivePolicy(
        step=math.radians(study.step_deg),
        confidence=o.confidence,
        max_rotation=math.radians(o.max_rotation_deg),
        check_every=o.check_every,
        min_spread=o.min_spread,
        confirm=CONFIRM if o.confirm is None else o.confirm,
        **({} if o.seek is None else {"seek": o.seek}),
    )


def reactive_stop(run: ReactiveRun | WheelRun) -> str:
    """A reactive run's stop as trials.csv says it: confident, mismatch (the readings did not fit the part),
    ambiguous (the belief ended with two or more strong modes) or budget (not sure otherwise: the
    rotation budget, or blocked both ways)."""
    if run.stopped in ("confident", "mismatch"):
        return run.stopped
    return "ambiguous" if run.belief.ambiguous else "budget"


def rotation_curve(
    part: Part | Outline,
    history: Sequence[tuple[float, float, float, float]],
    rotation_deg: float,
    final: float,
    budget_deg: float,
    final_mass: float = math.nan,
) -> list[tuple[float, float, float]]:
    """(mark deg, error mm, stated mass) at every 5° of a rolling's rotation up to ``budget_deg``: the
    belief's at the last check before the mark (``history``: (rotation rad, map_arc, mass, true_arc) per
    check; before the first, an infinite error and no mass), the final error and ``final_mass`` once the
    rolling stopped."""
    curve = []
    mark = MARK_DEG
    while mark <= budget_deg + 1e-9:
        if rotation_deg <= mark + 1e-9:
            e, p = final, final_mass  # stopped (sure, or out of budget) before this mark
        else:
            before = [h for h in history if math.degrees(h[0]) <= mark + 1e-9]
            e = boundary_error(part, before[-1][1], before[-1][3]) if before else math.inf
            p = before[-1][2] if before else math.nan
        curve.append((mark, e, p))
        mark += MARK_DEG
    return curve


def score_reactive(
    study: Study,
    part: Part | Outline,
    noise: NoiseModel,
    cal: Calibration,
    start: float,
    rig_seed: int,
    filter_class: type[ContactFilter] | None = None,
    change: WorldChange | None = None,
) -> MethodResult:
    """The reactive filter from the same start on a rig with the same seed (in world ``change``: the
    study's ``[world]``, :class:`sim2d.WorldChange`)."""
    from driver.jaw import localize_reactively
    from sim2d import SimRig

    o = study.reactive
    rig = SimRig(part, noise=noise, seed=rig_seed, engine=study.engine, change=change)
    res = localize_reactively(
        rig,
        part,
        calibration=cal,
        filter=reactive_filter(study, part, noise, filter_class),
        approach_pose=rig.approach_pose(start, jaw_position=-JAW_START, standoff=1.0),
        policy=reactive_policy(study),
    )
    truth = rig.truth()["contact_arc"]
    final = boundary_error(part, res.estimate_arc, truth)
    rot = math.degrees(res.rotation)
    curve = rotation_curve(part, res.history, rot, final, o.max_rotation_deg, res.belief.mass)
    return {
        "estimate_arc": res.estimate_arc,
        "error_mm": final,
        "rotation_deg": rot,
        "curve": [(k, e) for k, e, _ in curve],
        "mass_curve": [(k, p) for k, _, p in curve],
        "stopped": reactive_stop(res),
        "mass": res.belief.mass,
        "bridges": res.bridges,
        "path": (res.true_arcs, res.segments),
        "mismatch_arc": mismatch_cell(res.belief),
        "spikes": rig.spikes.count,
    }


def mismatch_cell(belief: Belief) -> str:
    """A belief's ``mismatch`` interval as trials.csv writes it: "A-B" (model arc, mm), "unknown" where the run
    found one but could not tell where, empty when none."""
    arcs = getattr(belief, "mismatch", None)
    if not arcs:
        return ""
    if not all(math.isfinite(a) for a in arcs):
        return "unknown"
    return f"{arcs[0]:.2f}-{arcs[1]:.2f}"


def score_wheel(
    study: Study, part: Part | Outline, run: WheelRun | None, truth: float, failure: str, spikes: int | str
) -> Scored:
    """A wheel trial's scores: its ``run`` (sure or not) that ended with the contact at ``truth`` mm, as the
    trial's own cells and the ``reactive`` method's; ``failure`` (run None) says why it did not run."""
    if run is None:
        return broken_trial(("reactive",), failure, candidates="")
    err = boundary_error(part, run.estimate_arc, truth)
    rot = math.degrees(run.rotation)
    curve = rotation_curve(part, run.history, rot, err, study.reactive.max_rotation_deg, run.belief.mass)
    ok = int(err < study.success_radius)
    cells: ScoreCells = {
        "true_arc": truth,
        "estimate_arc": run.estimate_arc,
        "error_mm": err,
        "success": ok,
        "candidates": "",
        "probability": run.belief.mass,
        "ambiguous": int(run.belief.ambiguous),
        "failure": "",
    }
    reactive: MethodCells = {
        "success": ok,
        "error_mm": err,
        "estimate_arc": run.estimate_arc,
        "rotation_deg": rot,
        "curve": curve_cell((k, e) for k, e, _ in curve),
        "stopped": reactive_stop(run),
        "mass": run.belief.mass,
        "failure": "",
        "bridges": run.jumps,
        "bound_mm": "",  # the bound models the straight jaw's readings
        "mismatch_arc": mismatch_cell(run.belief),
        "mass_curve": mass_cell((k, p) for k, _, p in curve),
    }
    return Scored(cells, {"reactive": reactive}, spikes)
