"""The commands' work with a wheel finger (``--jaw wheel:MM``, docs/wheel.md): simulate, calibrate, run,
emulate and locate, each the wheel's counterpart of the straight jaw's."""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from localizer import Outline, Part, QueryError, WheelFilter, WheelJaw, wheel_reach_for

from ..records import check_finger, check_same_part, part_record
from ..rig import Rig, RigError
from ..wheel import wheel_calibration_arc
from ._options import UsageError, off_scale, pressing
from ._output import (
    CONNECTING,
    RELEASED,
    belief_fields,
    ending_progress_line,
    exit_status,
    print_belief,
    truth_fields,
)
from ._world import world_change, world_fields

if TYPE_CHECKING:
    from sim2d import WheelRig

    from ..jaw import Calibration
    from ..records import RunLog, RunRecord
    from ..wheel import WheelCalibration, WheelPolicy, WheelRun

__all__ = [
    "wheel_policy",
    "wheel_doc",
    "print_wheel",
    "simulate_wheel",
    "calibrate_wheel_here",
    "run_wheel",
    "wheel_rig",
    "locate_wheel",
]


def wheel_policy(args: argparse.Namespace) -> WheelPolicy:
    """The wheel's rolling from the reactive options (``--confidence``, ``--max-rotation``); ``--policy`` is refused."""
    from ..wheel import WheelPolicy

    if getattr(args, "policy", None) is not None:
        raise UsageError(
            f"--policy {args.policy} is the straight jaw's direction rule: a wheel turns round only where it is blocked"
        )
    return WheelPolicy(confidence=args.confidence, max_rotation=math.radians(args.max_rotation))


def wheel_doc(part: Part | Outline, run: WheelRun, rig: Rig, calibration: WheelCalibration) -> dict[str, Any]:
    """The JSON object of a wheel's run."""
    b = run.belief
    return {
        "part": part.name,
        "method": "reactive",
        "jaw": calibration.jaw,
        **belief_fields(b),
        "stopped": run.stopped,
        "rotation_deg": math.degrees(run.rotation),
        "arc_mm": run.arc,
        "steps": run.steps,
        "reversals": run.reversals,
        "jumps": run.jumps,
        "slip_mm": run.slip,
        "calibration": calibration.as_dict(),
        "modes": [{"arc": m.arc, "probability": m.mass} for m in b.modes[:5]],
        "part_scale": run.part_scale._asdict(),
        **truth_fields(part, b, rig),
    }


def print_wheel(doc: dict[str, Any]) -> None:
    print(
        f"{doc['jaw']}: rolled {doc['arc_mm']:.1f} mm, the hand turned {doc['rotation_deg']:.1f}°, in {doc['steps']} "
        f"steps ({doc['stopped']}, {doc['jumps']} jumps undone, slip {doc['slip_mm']:+.3f} mm)"
    )
    print_belief(doc)
    said = doc.get("part_scale")  # what the readings say of it where they fit the model: not after a mismatch
    if said is not None and said["probability"] >= 0.5 and doc["stopped"] != "mismatch":
        print(
            f"the part seems {100 * (said['scale'] - 1):+.2f}% ± {100 * said['sd']:.2f}% off its model's size "
            f"(probability {said['probability']:.2f}): made to another revision, or scaled on export?"
        )


def _emit(args: argparse.Namespace, doc: dict[str, Any], part: Part | Outline, run: WheelRun, out: str | None) -> int:
    if out:
        doc["trace"] = str(out)
    if getattr(args, "plot", None):
        from driver.records import plot_reactive

        plot_reactive(part, run, args.plot)
        doc["plot"] = str(args.plot)
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        print_wheel(doc)
        if out:
            print(f"readings written to {out}")
    return exit_status(doc)


def simulate_wheel(args: argparse.Namespace, part: Part | Outline, wheel: WheelJaw) -> int:
    """'simulate --jaw wheel:MM --reactive': calibrate a simulated wheel, roll it from --start, save the trace."""
    from sim2d import WheelRig, load_noise

    from ..records import WheelTrace
    from ..wheel import calibrate_wheel, localize_with_wheel

    if not args.reactive:
        raise UsageError(f"a {wheel} rolls until it is sure: give --reactive (fixed --roll rolls are a straight jaw's)")
    if not 0 <= args.start < part.perimeter:
        raise QueryError(f"--start {args.start} mm must be in [0, perimeter={part.perimeter:.3f}) mm")
    if not bool(wheel_reach_for(part, wheel).touchable(args.start)):
        raise RigError(f"--start {args.start} mm: a {wheel} laid there would touch the part elsewhere; pick another")
    noise = load_noise(args.noise)
    cal_rig = WheelRig(part, wheel, noise=noise, seed=args.seed + 1, engine=args.engine)
    calibration = calibrate_wheel(cal_rig, wheel, cal_rig.approach_pose(wheel_calibration_arc(part, wheel)), part=part)

    change = world_change(args, part)
    rig = WheelRig(part, wheel, noise=noise, seed=args.seed, engine=args.engine, change=change)
    odds = off_scale(args, wheel)
    run = localize_with_wheel(
        rig,
        part,
        wheel,
        approach_pose=rig.approach_pose(args.start),
        calibration=calibration,
        policy=wheel_policy(args),
        pressing=pressing(args),
        filter=WheelFilter(part, wheel, off_scale=odds),
    )
    doc = wheel_doc(part, run, rig, calibration)
    doc.update(world_fields(change, rig))
    trace = WheelTrace.from_run(
        run,
        calibration,
        part=part_record(part, args.part),
        engine=args.engine,
        noise=str(args.noise),
        seed=args.seed,
        start_arc=args.start,
        off_scale=odds,
        result=doc,
    )
    trace.save(args.out)
    return _emit(args, doc, part, run, args.out)


def wheel_rig(
    part: Part | Outline, wheel: WheelJaw, args: argparse.Namespace
) -> tuple[WheelRig, tuple[float, float, float]]:
    """The simulated wheel rig 'emulate --jaw wheel:MM' serves, and its start pose (the wheel 1 mm off)."""
    from sim2d import WheelRig

    rig = WheelRig(part, wheel, noise=args.noise, seed=args.seed, engine=args.engine)
    start = wheel_calibration_arc(part, wheel) if args.start is None else float(args.start) % part.perimeter
    return rig, rig.approach_pose(start)


def calibrate_wheel_here(rig: Rig, wheel: WheelJaw) -> WheelCalibration:
    """'calibrate --jaw wheel:MM': roll 40 mm from the present pose (the hand's axis facing a smooth surface
    the wheel fits, clear of it) and measure the radius and the channels' rotation."""
    from ..wheel import calibrate_wheel

    return calibrate_wheel(rig, wheel, tuple(rig.pose()))


def run_wheel(
    args: argparse.Namespace,
    part: Part | Outline,
    wheel: WheelJaw,
    calibration: Calibration | WheelCalibration | None,
    log: RunLog | None,
    observer: Callable[[dict[str, Any]], object],
) -> int:
    """'run --jaw wheel:MM --reactive': from the present pose (the hand's axis facing the part, clear of it),
    calibrate there unless a calibration is given, then roll until sure."""
    from ..link import SerialRig
    from ..wheel import WheelCalibration, calibrate_wheel, localize_with_wheel

    if not args.reactive:
        raise UsageError(f"a {wheel} rolls until it is sure: give --reactive (fixed --roll rolls are a straight jaw's)")
    if calibration is not None:
        if not isinstance(calibration, WheelCalibration):
            raise RigError(f"the calibration is for {calibration.jaw}, the finger is {wheel}: calibrate this finger")
        calibration.check(wheel)

    def progress(event: dict[str, Any]) -> None:
        if event.get("event") == "reading" and log is not None:
            log(event)
        if event.get("event") == "belief":
            b = event["belief"]
            if log is not None:
                log({"event": "belief", "arc": event["arc"], "map_arc": b.map_arc, "mass": b.mass})
            sys.stderr.write(f"\rrolled {event['arc']:7.1f} mm  best {b.map_arc:8.2f} mm  {b.mass:6.1%} ")
            sys.stderr.flush()

    args.interrupted = CONNECTING
    with ending_progress_line(log), SerialRig(args.arm, args.daq, timeout=args.timeout, log=log) as rig:
        here = tuple(rig.pose())
        if calibration is None:
            calibration = calibrate_wheel(rig, wheel, here, part=part)
            if log is not None:
                log({"event": "calibration", **calibration.as_dict()})
        run = localize_with_wheel(
            rig,
            part,
            wheel,
            approach_pose=here,
            calibration=calibration,
            policy=wheel_policy(args),
            pressing=pressing(args),
            observer=progress,
            filter=WheelFilter(part, wheel, off_scale=off_scale(args, wheel)),
        )
    args.interrupted = RELEASED
    doc = wheel_doc(part, run, rig, calibration)
    if log is not None:
        log({"event": "result", **doc})
        log.close()
    return _emit(args, doc, part, run, None)


def locate_wheel(args: argparse.Namespace, record: RunRecord) -> int:
    """'locate TRACE --part PART' of a wheel's trace or run log: its readings replayed into the filter for its
    finger."""
    from localizer import load_part

    path = record.path
    trace = record.wheel()
    check_finger(path, trace.metadata["jaw"], args.jaw)
    part = load_part(args.part)
    check_same_part(trace.metadata.get("part"), part, args.part, f"trace {path}", same=args.same_part)
    b = trace.relocalize(part, off_scale=off_scale(args, trace.wheel, trace.metadata.get("off_scale")))
    true = trace.true_arc
    doc = {
        "part": part.name,
        "jaw": trace.metadata["jaw"],
        **belief_fields(b),
        "readings": int(trace.columns["length"].size),
        "modes": [{"arc": m.arc, "probability": m.mass} for m in b.modes[:5]],
    }
    # where the run found the part not to be its model (it may have rolled on past it: the belief replayed is the
    # last segment's, which did not read it)
    result = trace.metadata.get("result")
    if doc["mismatch"] is None and isinstance(result, dict) and isinstance(result.get("mismatch"), dict):
        doc["mismatch"] = result["mismatch"]
    if math.isfinite(true):
        doc["true_arc"] = true
        doc["error_mm"] = float(abs(part.arc_offset(b.map_arc, true)))
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        print(f"{doc['jaw']} trace, {doc['readings']} readings replayed")
        print_belief(doc)
    return exit_status(doc)
