"""A trial of a study with the paper's straight jaw, start to score: draw the trial (part, noise, world),
calibrate the simulated wrist, draw a start the fixed rolls can run from, roll, and score every method on
that same trial (:mod:`bench.methods`)."""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from localizer import Outline

from .columns import world_cells
from .study import Study
from .trial_draw import draw_trial, draw_world

if TYPE_CHECKING:
    from driver.jaw import RollResult
    from localizer import Localization, ModeTracks, Part
    from sim2d import SimRig

    from .trial_draw import TrialSpec

__all__ = ["run_straight_trial", "start_sampler"]


def start_sampler(
    part: Part | Outline, rolls: Sequence[float], jaw_start: float
) -> tuple[npt.NDArray[np.intp], ModeTracks]:
    """Boundary points (grid indices) and grid step of the filter's tracks from which the jaw, laid with
    the contact at ``jaw_start`` mm on it, rolls through ``rolls`` (rad, one sign) without bridging,
    with a millimetre to spare (:meth:`localizer.ModeTracks.rollable`), and not on a flat face."""
    from localizer import tracks_for

    tracks = tracks_for(part, 0.02)
    total = float(sum(rolls))
    turns = np.append(np.arange(0.0, abs(total), math.radians(1.0)), abs(total)) * math.copysign(1.0, total)
    # not on a flat face of an outline: a jaw laid there lies flush, its contact a line, not the start
    ok = np.flatnonzero(tracks.rollable(turns, jaw_start, margin=1.0) & (tracks.kappa != 0))
    return ok, tracks


def run_straight_trial(spec: TrialSpec) -> dict[str, Any]:
    """:func:`bench.trial.run_trial` with the paper's straight jaw.

    The start is drawn uniformly over the boundary points from which the fixed rolls can run
    (:func:`start_sampler`); a start where the simulated rig still refuses to roll (a bridge, or the jaw
    laid off the point) is redrawn, up to 20 times (``restarts``). With ``methods``, every
    method is scored on that same trial, each on its own.
    """
    from driver.jaw import calibrate_simulated, laid_off, roll_sequence
    from driver.rig import RigError
    from sim2d import SimRig

    from .methods import broken_rule, score_methods, score_rule
    from .scoring import JAW_START

    s = spec.study
    t0 = time.perf_counter()
    rng, part_file, part, noise, row = draw_trial(spec)
    rolls = [math.radians(r) for r in s.rolls_deg]
    jaw_start = -JAW_START if rolls[0] > 0 else JAW_START
    rule = s.method if s.method in ("paper", "likelihood") else "paper"
    failure: str | None = None
    try:
        cal = calibrate_simulated(part, noise, seed=int(rng.integers(1 << 31)), engine=s.engine)
        candidates, tracks = start_sampler(part, rolls, jaw_start)
        if candidates.size == 0:
            raise RigError(f"no start on {part.name} lets the {s.rolls_deg} degree rolls run without bridging")

        def roll_fixed(rig: SimRig, start: float) -> tuple[RollResult, ...]:
            return roll_sequence(
                rig,
                rolls,
                calibration=cal,
                step=math.radians(s.step_deg),
                approach_pose=rig.approach_pose(start, jaw_position=jaw_start, standoff=1.0),
                faces=part.faces if isinstance(part, Outline) else (),
            )

        run = None
        for restarts in range(20):  # noqa: B007 (the count is reported after the loop)
            start = float(part.wrap_arc(tracks.sigma[int(rng.choice(candidates))] + rng.uniform(-0.5, 0.5) * tracks.h))
            rig_seed = int(rng.integers(1 << 31))
            rig = SimRig(part, noise=noise, seed=rig_seed, engine=s.engine)
            try:
                run = roll_fixed(rig, start)
            except RigError:
                continue
            if laid_off(part, run[0].truth[0].contact_arc, start):
                run = None
                continue
            break
        if run is None:
            raise RigError("no start out of 20 let the rolls run on the simulated rig")
        # the start was drawn on the model as machined, the same in every world; the world's own part and
        # wrist (a [world] table) then roll the fixed rolls from there
        change = draw_world(spec, part_file, part, start)
        fixed_failure = ""
        if change is not None and change.differs:
            rig = SimRig(part, noise=noise, seed=rig_seed, engine=s.engine, change=change)
            try:
                run = roll_fixed(rig, start)
            except RigError as exc:
                run, fixed_failure = None, f"the fixed rolls on the world's part: {type(exc).__name__}: {exc}"[:200]
    except Exception as exc:  # the trial broke before any method could run: every method's failure
        failure = f"{type(exc).__name__}: {exc}"[:200]
    if failure is not None:
        row.update(_broken_trial(s, failure))
        change, spikes = None, ""
    else:
        true_arc = rig.truth()["contact_arc"]
        row.update(
            {
                "start_arc": start,
                "true_arc": true_arc,
                "restarts": restarts,
                "failure": "",
                "lengths": " ".join(f"{r.length:.6f}" for r in run) if run is not None else "",
                "turns": " ".join(f"{r.turn:.8f}" for r in run) if run is not None else "",
            }
        )
        rules: dict[str, Localization | Exception] = {}
        own = score_rule(s, part, run, rule, true_arc, rules) if run is not None else broken_rule(fixed_failure)
        row.update(
            {
                "estimate_arc": own["estimate_arc"],
                "error_mm": own["error_mm"],
                "success": int(own["error_mm"] < s.success_radius),
                "candidates": own["candidates"],
                "probability": own["probability"],
                "ambiguous": own["ambiguous"],
                "failure": "" if s.methods else own["failure"],
            }
        )
        if s.methods:
            row.update(
                score_methods(
                    s,
                    part,
                    noise,
                    cal,
                    run,
                    start,
                    rig_seed,
                    true_arc,
                    rules,
                    filter_class=spec.filter_class,
                    change=change,
                    fixed_failure=fixed_failure,
                )
            )
            first_method = s.methods[0]
            for key in ("success", "error_mm", "estimate_arc"):
                row[key] = row[f"{first_method}_{key}"]
        spikes = row.pop("_spikes", rig.spikes.count)
    if s.world is not None:
        row.update(world_cells(change, spikes))
    row["time_s"] = time.perf_counter() - t0
    if s.fingers:
        row.update(_finger_cells(spec, part, rolls, jaw_start))
    return row


def _broken_trial(s: Study, text: str) -> dict[str, Any]:
    """The cells of a trial that broke before any method could run: every method's failure ``text``."""
    row: dict[str, Any] = {
        "start_arc": math.nan,
        "true_arc": math.nan,
        "estimate_arc": math.nan,
        "error_mm": math.inf,
        "success": 0,
        "candidates": 0,
        "probability": 0.0,
        "ambiguous": 0,
        "lengths": "",
        "turns": "",
        "restarts": 0,
        "failure": text,
    }
    for m in s.methods:
        row.update(
            {
                f"{m}_success": 0,
                f"{m}_error_mm": math.inf,
                f"{m}_estimate_arc": math.nan,
                f"{m}_rotation_deg": math.nan,
                f"{m}_curve": "",
                f"{m}_stopped": "error",
                f"{m}_mass": "",
                f"{m}_failure": text,
                f"{m}_bridges": "",
            }
        )
    return row


def _finger_cells(spec: TrialSpec, part: Part | Outline, rolls: Sequence[float], jaw_start: float) -> dict[str, Any]:
    """The :data:`bench.columns.FINGER_COLUMNS` of a straight jaw's trial in a study that names its finger: how
    often a uniform start over the whole boundary (from a stream of its own, so that the trial itself is the
    same as in any other study) would have had to be redrawn for the fixed rolls to run, and how much of the
    boundary they run from."""
    s = spec.study
    rng = np.random.default_rng(np.random.SeedSequence([s.seed, spec.level, spec.trial, 1]))
    candidates, tracks = start_sampler(part, rolls, jaw_start)
    ok = np.zeros(tracks.sigma.size, dtype=bool)
    ok[candidates] = True
    redraws = 0
    while redraws < 1000 and not ok[int(rng.uniform(0, part.perimeter) / tracks.h) % ok.size]:
        redraws += 1
    return {"jaw": s.level_jaw(spec.level), "redraws": redraws, "reachable": float(ok.mean()), "arc_mm": ""}
