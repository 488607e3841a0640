"""The rolling of a trial with the paper's straight jaw: calibrate the simulated wrist, draw a start the
fixed rolls can run from, roll them (in the trial's world), for :mod:`bench.methods` to score every
method on that same trial."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import numpy.typing as npt

from localizer import Outline

from .columns import FingerCells, RollCells
from .scoring import JAW_START

if TYPE_CHECKING:
    from driver.jaw import Calibration, RollResult
    from localizer import ModeTracks, Part
    from sim2d import SimRig, WorldChange

    from .trial_context import TrialContext

__all__ = ["StraightRoll", "roll_straight", "start_sampler"]


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


class StraightRoll(NamedTuple):
    """The straight jaw's rolling in a trial: its cells and the finger's; where it started (mm), the
    wrist's calibration, the fixed rolls (None where they could not run in the trial's world:
    ``fixed_failure`` says why), the rig's seed the reactive method rolls from again, the true contact at
    the end (mm), the world and the rig's spiked readings; ``failure``: why the trial broke before any
    method could run ("" when it did not; then the rest is empty)."""

    cells: RollCells
    finger: FingerCells | None
    start: float
    cal: Calibration | None
    rolls: tuple[RollResult, ...] | None
    rig_seed: int
    true_arc: float
    change: WorldChange | None
    fixed_failure: str
    spikes: int | str
    failure: str


def roll_straight(ctx: TrialContext) -> StraightRoll:
    """The fixed rolls of a trial with the paper's straight jaw (:func:`bench.trial.run_trial`).

    The start is drawn uniformly over the boundary points from which the fixed rolls can run
    (:func:`start_sampler`); a start where the simulated rig still refuses to roll (a bridge, or the jaw
    laid off the point) is redrawn, up to 20 times (``restarts``). The methods are scored on that same
    trial, each on its own (:func:`bench.methods.score_trial`).
    """
    from driver.jaw import calibrate_simulated, laid_off, roll_sequence
    from driver.rig import RigError
    from sim2d import SimRig

    s, rng, part, noise = ctx.study, ctx.rng, ctx.part, ctx.noise
    rolls = [math.radians(r) for r in s.rolls_deg]
    jaw_start = -JAW_START if rolls[0] > 0 else JAW_START
    finger = _finger_cells(ctx, rolls, jaw_start) if s.fingers else None
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
        change = ctx.world.draw(part, start, ctx.world_rng, ctx.part_index) if ctx.world is not None else None
        fixed_failure = ""
        if change is not None and change.differs:
            rig = SimRig(part, noise=noise, seed=rig_seed, engine=s.engine, change=change)
            try:
                run = roll_fixed(rig, start)
            except RigError as exc:
                run, fixed_failure = None, f"the fixed rolls on the world's part: {type(exc).__name__}: {exc}"[:200]
    except Exception as exc:  # the trial broke before any method could run: every method's failure
        broken: RollCells = {"start_arc": math.nan, "restarts": 0, "lengths": "", "turns": ""}
        failure = f"{type(exc).__name__}: {exc}"[:200]
        return StraightRoll(broken, finger, math.nan, None, None, 0, math.nan, None, "", "", failure)
    cells: RollCells = {
        "start_arc": start,
        "restarts": restarts,
        "lengths": " ".join(f"{r.length:.6f}" for r in run) if run is not None else "",
        "turns": " ".join(f"{r.turn:.8f}" for r in run) if run is not None else "",
    }
    true_arc = rig.truth()["contact_arc"]
    return StraightRoll(cells, finger, start, cal, run, rig_seed, true_arc, change, fixed_failure, rig.spikes.count, "")


def _finger_cells(ctx: TrialContext, rolls: Sequence[float], jaw_start: float) -> FingerCells:
    """The :data:`bench.columns.FINGER_COLUMNS` of a straight jaw's trial in a study that names its finger: how
    often a uniform start over the whole boundary (from a stream of its own, so that the trial itself is the
    same as in any other study) would have had to be redrawn for the fixed rolls to run, and how much of the
    boundary they run from."""
    s, spec = ctx.study, ctx.spec
    rng = np.random.default_rng(np.random.SeedSequence([s.seed, spec.level, spec.trial, 1]))
    candidates, tracks = start_sampler(ctx.part, rolls, jaw_start)
    ok = np.zeros(tracks.sigma.size, dtype=bool)
    ok[candidates] = True
    redraws = 0
    while redraws < 1000 and not ok[int(rng.uniform(0, ctx.part.perimeter) / tracks.h) % ok.size]:
        redraws += 1
    return {"jaw": ctx.jaw, "redraws": redraws, "reachable": float(ok.mean()), "arc_mm": ""}
