"""One Monte Carlo trial with a wheel finger (a study's ``jaw = "wheel:R"`` or a sweep over fingers).

Reproducible from (seed, level, trial) as the straight jaw's trials: the part is drawn first, then the
wheel's true radius (its nominal one within a ground wheel's tolerance, :data:`RADIUS_SD`), then the
start: uniformly over the whole boundary, redrawn until the wheel surely reaches it
(:class:`localizer.WheelReach`; the redraws are counted). The wheel is calibrated on the part itself
(:func:`driver.wheel.calibrate_wheel` on a rig of its own: the same wheel, another machined part and
noise), then :func:`driver.wheel.localize_with_wheel` rolls from the start, both rigs in the study's world
(``engine``: kinematic or pymunk), with the study's
``[reactive]`` confidence and rotation budget. :func:`bench.methods.score_trial` scores the run as the
``reactive`` method; the row has :data:`bench.columns.FINGER_COLUMNS` too.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .columns import FingerCells, RollCells

if TYPE_CHECKING:
    from driver.wheel import WheelRun
    from sim2d import WorldChange

    from .trial_context import TrialContext

__all__ = ["WheelRoll", "roll_wheel", "RADIUS_SD", "MAX_REDRAWS"]

#: The real wheel's radius about its nominal one, mm (a ground wheel: IT6 on a 10 mm diameter is ±9 µm).
RADIUS_SD = 0.01
#: Uniform draws over the boundary before a trial gives up finding a start the wheel reaches.
MAX_REDRAWS = 1000


class WheelRoll(NamedTuple):
    """A wheel's rolling in a trial: its cells and the finger's, the run (None where it failed: ``failure``
    says why), the true contact at its end (mm), the world and the localizing rig's spiked readings."""

    cells: RollCells
    finger: FingerCells
    run: WheelRun | None
    true_arc: float
    change: WorldChange | None
    spikes: int | str
    failure: str


def roll_wheel(ctx: TrialContext) -> WheelRoll:
    """One wheel trial's rolling (module notes). Never raises: a failure is the roll's ``failure``."""
    from driver.wheel import WheelPolicy, calibrate_wheel, localize_with_wheel, wheel_calibration_arc
    from localizer import WheelFilter, WheelJaw, parse_jaw, wheel_reach_for
    from sim2d import WheelRig

    s, rng, part, noise = ctx.study, ctx.rng, ctx.part, ctx.noise
    wheel = parse_jaw(ctx.jaw)
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
    cells: RollCells = {"start_arc": start, "lengths": "", "turns": "", "restarts": 0}
    finger: FingerCells = {"jaw": ctx.jaw, "redraws": redraws, "reachable": float(sure.mean()), "arc_mm": math.nan}
    cal_seed, rig_seed = int(rng.integers(1 << 31)), int(rng.integers(1 << 31))
    change = None
    try:
        if not math.isfinite(start):
            raise RuntimeError(f"no start the {wheel} reaches in {MAX_REDRAWS} draws on {part.name}")
        cal_rig = WheelRig(part, wheel, noise=noise, seed=cal_seed, true_radius=true_radius, engine=s.engine)
        cal = calibrate_wheel(cal_rig, wheel, cal_rig.approach_pose(wheel_calibration_arc(part, wheel)), part=part)
        # the world (a [world] table) is the localizing rig's; the calibration is another session's
        change = ctx.world.draw(part, start, ctx.world_rng, ctx.part_index) if ctx.world is not None else None
        rig = WheelRig(part, wheel, noise=noise, seed=rig_seed, true_radius=true_radius, change=change, engine=s.engine)
        policy = WheelPolicy(confidence=s.reactive.confidence, max_rotation=math.radians(s.reactive.max_rotation_deg))
        run = localize_with_wheel(
            rig,
            part,
            wheel,
            approach_pose=rig.approach_pose(start),
            calibration=cal,
            policy=policy,
            filter=WheelFilter(part, wheel, off_scale=s.reactive.off_scale),
        )
    except Exception as exc:  # noqa: BLE001 - the trial's failure is its result
        return WheelRoll(cells, finger, None, math.nan, change, "", f"{type(exc).__name__}: {exc}"[:200])
    finger["arc_mm"] = run.arc
    return WheelRoll(cells, finger, run, rig.truth()["contact_arc"], change, rig.spikes.count, "")
