"""One Monte Carlo trial with a wheel finger (a study's ``jaw = "wheel:R"`` or a sweep over fingers).

Reproducible from (seed, level, trial) as the straight jaw's trials: the part is drawn first, then the
wheel's true radius (its nominal one within a ground wheel's tolerance, :data:`RADIUS_SD`), then the
start: uniformly over the whole boundary, redrawn until the wheel surely reaches it
(:class:`localizer.WheelReach`; the redraws are counted). The wheel is calibrated on the part itself
(:func:`driver.wheel.calibrate_wheel` on a rig of its own: the same wheel, another machined part and
noise), then :func:`driver.wheel.localize_with_wheel` rolls from the start with the study's
``[reactive]`` confidence and rotation budget. The row has the straight jaw's columns, the
``reactive_*`` method columns, and :data:`bench.columns.FINGER_COLUMNS`.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from driver.wheel import WheelRun
    from localizer import Outline, Part

    from .study import Study
    from .trial_draw import TrialSpec

__all__ = ["run_wheel_trial", "RADIUS_SD", "MAX_REDRAWS"]

#: The real wheel's radius about its nominal one, mm (a ground wheel: IT6 on a 10 mm diameter is ±9 µm).
RADIUS_SD = 0.01
#: Uniform draws over the boundary before a trial gives up finding a start the wheel reaches.
MAX_REDRAWS = 1000


def run_wheel_trial(spec: TrialSpec) -> dict[str, Any]:
    """One wheel trial (module notes). Never raises: a failure is the row's ``failure``."""
    from driver.wheel import WheelPolicy, calibrate_wheel, localize_with_wheel, wheel_calibration_arc
    from localizer import WheelJaw, parse_jaw, wheel_reach_for
    from sim2d import WheelRig

    from .columns import world_cells
    from .trial_draw import draw_trial, draw_world

    s = spec.study
    t0 = time.perf_counter()
    rng, part_file, part, noise, row = draw_trial(spec)
    jaw = s.level_jaw(spec.level)
    wheel = parse_jaw(jaw)
    assert isinstance(wheel, WheelJaw)
    true_radius = wheel.radius + float(rng.normal(0.0, RADIUS_SD))
    reach = wheel_reach_for(part, wheel)
    sure = np.asarray(reach.sure)
    redraws, start = 0, math.nan
    while redraws < MAX_REDRAWS:
        u = float(rng.uniform(0.0, part.perimeter))
        if sure[int(u / reach.h) % sure.size]:
            start = u
            break
        redraws += 1
    row.update(
        {
            "start_arc": start,
            "lengths": "",
            "turns": "",
            "restarts": 0,
            "candidates": "",
            "jaw": jaw,
            "redraws": redraws,
            "reachable": float(sure.mean()),
        }
    )
    cal_seed, rig_seed = int(rng.integers(1 << 31)), int(rng.integers(1 << 31))
    change = None
    failure: str | None = None
    try:
        if not math.isfinite(start):
            raise RuntimeError(f"no start the {wheel} reaches in {MAX_REDRAWS} draws on {part.name}")
        cal_rig = WheelRig(part, wheel, noise=noise, seed=cal_seed, true_radius=true_radius)
        cal = calibrate_wheel(cal_rig, wheel, cal_rig.approach_pose(wheel_calibration_arc(part, wheel)), part=part)
        # the world (a [world] table) is the localizing rig's; the calibration is another session's
        change = draw_world(spec, part_file, part, start)
        rig = WheelRig(part, wheel, noise=noise, seed=rig_seed, true_radius=true_radius, change=change)
        policy = WheelPolicy(confidence=s.reactive.confidence, max_rotation=math.radians(s.reactive.max_rotation_deg))
        run = localize_with_wheel(
            rig, part, wheel, approach_pose=rig.approach_pose(start), calibration=cal, policy=policy
        )
    except Exception as exc:  # noqa: BLE001 - the trial's failure is its result
        failure = f"{type(exc).__name__}: {exc}"[:200]
    if failure is not None:
        spikes: int | str = ""
        row.update(
            {
                "true_arc": math.nan,
                "estimate_arc": math.nan,
                "error_mm": math.inf,
                "success": 0,
                "probability": 0.0,
                "ambiguous": 0,
                "failure": failure,
                "arc_mm": math.nan,
                "reactive_success": 0,
                "reactive_error_mm": math.inf,
                "reactive_estimate_arc": math.nan,
                "reactive_rotation_deg": math.nan,
                "reactive_curve": "",
                "reactive_stopped": "error",
                "reactive_mass": "",
                "reactive_failure": failure,
                "reactive_bridges": "",
                "reactive_bound_mm": "",
                "reactive_mismatch_arc": "",
            }
        )
    else:
        spikes = rig.spikes.count
        row.update(_run_cells(s, part, run, rig.truth()["contact_arc"]))
    row["time_s"] = time.perf_counter() - t0
    if s.world is not None:
        row.update(world_cells(change, spikes))
    return row


def _run_cells(s: Study, part: Part | Outline, run: WheelRun, truth: float) -> dict[str, Any]:
    """The cells of a wheel's run that ended (sure or not) with the contact at ``truth`` mm."""
    from .reactive_method import mismatch_cell, reactive_stop, rotation_curve
    from .scoring import boundary_error, curve_cell

    err = boundary_error(part, run.estimate_arc, truth)
    rot = math.degrees(run.rotation)
    ok = int(err < s.success_radius)
    return {
        "true_arc": truth,
        "estimate_arc": run.estimate_arc,
        "error_mm": err,
        "success": ok,
        "probability": run.belief.mass,
        "ambiguous": int(run.belief.ambiguous),
        "failure": "",
        "arc_mm": run.arc,
        "reactive_success": ok,
        "reactive_error_mm": err,
        "reactive_estimate_arc": run.estimate_arc,
        "reactive_rotation_deg": rot,
        "reactive_curve": curve_cell(rotation_curve(part, run.history, rot, err, s.reactive.max_rotation_deg)),
        "reactive_stopped": reactive_stop(run),
        "reactive_mass": run.belief.mass,
        "reactive_failure": "",
        "reactive_bridges": run.jumps,
        "reactive_bound_mm": "",  # the bound models the straight jaw's readings
        "reactive_mismatch_arc": mismatch_cell(run.belief),
    }
