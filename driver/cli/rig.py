"""Commands on a real rig over serial lines: ``calibrate`` (the wrist sensor, paper §III-B) and ``run``
(roll and localize). On any failure the run log records it and is closed; the rig itself is made safe
by :class:`driver.link.serial_rig.SerialRig` on leaving."""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, cast

from localizer import SUCCESS_RADIUS, Outline, Part, StraightJaw, WheelJaw

from ..records import calls_event, part_record
from ._options import (
    PLOT_SUFFIXES,
    STEP_DEG,
    add_command,
    check_before_moving,
    jaw_argument,
    off_scale,
    part_arguments,
    pressing,
    reactive_arguments,
    read_part,
    rig_arguments,
    roll_degrees,
    servo_arguments,
    step_degrees,
)
from ._output import (
    CONNECTING,
    RELEASED,
    emit_run,
    ending_progress_line,
    exit_status,
    print_reactive,
    run_reactive,
    run_summary,
)
from ._wheel import calibrate_wheel_here, run_wheel

if TYPE_CHECKING:
    from ..jaw import Calibration
    from ..link import SerialRig
    from ..records import RunLog
    from ..wheel import WheelCalibration

__all__ = ["register", "calibrate_command", "run_command"]


def register(sub: Any) -> None:
    """Add ``calibrate`` and ``run`` to the subparsers ``sub``."""
    cal = add_command(
        sub,
        "calibrate",
        calibrate_command,
        help="calibrate the wrist sensor on a rig (paper §III-B)",
        description="With the jaw's centre facing an immobilized object, clear of it: tap it "
        "at 11 jaw positions from -50 to 50 mm and save the ratio spline.",
    )
    rig_arguments(cal)
    jaw_argument(cal)
    cal.add_argument("--out", required=True, metavar="CAL.json", help="calibration file to write")

    run = add_command(
        sub,
        "run",
        run_command,
        help="roll on a rig and localize",
        description="From the present pose (the jaw's centre facing the start point, clear "
        "of the part): calibrate if no calibration is given, slide 40 mm, "
        "establish contact, roll, localize.",
    )
    part_arguments(run)
    rig_arguments(run)
    jaw_argument(run)
    run.add_argument("--calibration", metavar="CAL.json", help="calibration from 'rolltouch calibrate'")
    run.add_argument(
        "--roll",
        type=roll_degrees,
        action="append",
        metavar="DEG",
        help="a roll's rotation in degrees; repeat (default 20 then 15)",
    )
    run.add_argument(
        "--step", type=step_degrees, default=STEP_DEG, metavar="DEG", help=f"rolling step (default {STEP_DEG}°)"
    )
    servo_arguments(run)
    reactive_arguments(run)
    run.add_argument("--log", metavar="FILE.jsonl", help="run log, JSON Lines, flushed per sample")
    run.add_argument("--plot", metavar="FILE.png", help="draw the part, the jaw poses and the estimate")
    run.add_argument("--json", action="store_true", help="print the same object as 'rolltouch locate --json'")


def calibrate_command(args: argparse.Namespace) -> int:
    from driver.jaw import calibrate
    from driver.link import SerialRig

    check_before_moving(args, {"out": (".json",)})
    args.interrupted = CONNECTING
    if isinstance(args.jaw, WheelJaw):
        with SerialRig(args.arm, args.daq, timeout=args.timeout) as rig:
            wheel_cal = calibrate_wheel_here(rig, args.jaw)
        args.interrupted = RELEASED
        wheel_cal.save(args.out)
        print(
            f"calibration of {wheel_cal.jaw} written to {args.out}: radius {wheel_cal.radius:.4f} mm, "
            f"direction zero {math.degrees(wheel_cal.direction_zero):+.3f}°, {wheel_cal.steps} steps"
        )
        return 0
    with SerialRig(args.arm, args.daq, timeout=args.timeout) as rig:
        _check_straight_hand(rig, args.jaw)
        calibration = calibrate(rig, rig.pose())
    args.interrupted = RELEASED
    calibration.save(args.out)
    print(
        f"calibration written to {args.out}: ratio {calibration.ratios[0]:.5f} at -50 mm to "
        f"{calibration.ratios[-1]:.5f} at +50 mm"
    )
    return 0


def _check_straight_hand(rig: SerialRig, jaw: StraightJaw) -> None:
    """Refuse, before anything moves, to run a straight jaw's procedure on a hand with a wheel: its
    readings would say only "no contact"."""
    from driver.rig import RigError

    if rig.has_wheel():
        raise RigError(
            f"the hand has a wheel on an axle encoder (its arm answers AXLE) but --jaw is {jaw}: "
            "give --jaw wheel:RADIUS with the wheel's radius in mm, or connect the straight jaw's hand"
        )


def _progress(event: dict[str, Any]) -> None:
    if event.get("event") == "reading":
        sys.stderr.write(
            f"\rroll {event['roll'] + 1}  step {event['step']:>4}/{event['steps']}  "
            f"Δv1 {event['dv1']:.3f} V  contact {event['jaw_position']:+7.2f} mm "
        )
        sys.stderr.flush()


def run_command(args: argparse.Namespace) -> int:
    from driver.jaw import Calibration, run_from_here
    from driver.link import SerialRig
    from driver.records import RunLog, Trace
    from driver.wheel import check_calibration, load_calibration

    check_before_moving(args, {"plot": PLOT_SUFFIXES, "log": ()})
    part = read_part(args)
    rolls = args.roll or [20.0, 15.0]
    loaded = load_calibration(args.calibration) if args.calibration else None
    if loaded is not None:
        check_calibration(loaded, args.jaw)
    if isinstance(args.jaw, WheelJaw):
        log = RunLog(args.log, _wheel_header(args, part, cast("WheelCalibration | None", loaded))) if args.log else None
        return run_wheel(args, part, args.jaw, loaded, log, lambda event: None)
    off_scale(args, args.jaw)  # refused for a straight jaw
    calibration = loaded if isinstance(loaded, Calibration) else None
    header = {
        "jaw": str(args.jaw),
        "part": part_record(part, args.part),
        "arm": args.arm,
        "daq": args.daq,
        "rolls_deg": rolls,
        "step_deg": args.step,
    }
    if calibration is not None:
        header["calibration"] = {
            "positions": list(calibration.positions),
            "ratios": list(calibration.ratios),
            "target": calibration.target,
        }
    log = RunLog(args.log, header) if args.log else None

    def observer(event: dict[str, Any]) -> None:
        if log is not None:
            log(event)
        _progress(event)

    if args.reactive:
        return _run_reactively(args, part, calibration, log, observer)
    args.interrupted = CONNECTING
    with ending_progress_line(log), SerialRig(args.arm, args.daq, timeout=args.timeout, log=log) as rig:
        _check_straight_hand(rig, args.jaw)
        run, calibration = run_from_here(
            rig,
            part,
            [math.radians(r) for r in rolls],
            calibration=calibration,
            step=math.radians(args.step),
            observer=observer,
            pressing=pressing(args),
        )
    args.interrupted = RELEASED
    trace = Trace.from_run(
        run,
        calibration,
        part=header["part"],
        arm=args.arm,
        daq=args.daq,
        rolls_deg=rolls,
        step_deg=args.step,
        engine="serial",
    )
    doc = run_summary(part, trace, run.localization)
    if log is not None:
        log({"event": "result", **doc})
        log.close()
    return emit_run(args, doc, part, trace, run.localization)


def _wheel_header(
    args: argparse.Namespace, part: Part | Outline, calibration: WheelCalibration | None
) -> dict[str, Any]:
    header = {
        "jaw": str(args.jaw),
        "part": part_record(part, args.part),
        "arm": args.arm,
        "daq": args.daq,
        "off_scale": off_scale(args, args.jaw),
    }
    if calibration is not None:
        header["calibration"] = calibration.as_dict()
    return header


def _run_reactively(
    args: argparse.Namespace,
    part: Part | Outline,
    calibration: Calibration | None,
    log: RunLog | None,
    observer: Callable[[dict[str, Any]], object],
) -> int:
    """'run --reactive': from the present pose, calibrate if needed, slide 40 mm, roll until sure."""
    from driver.jaw import Hand, calibrate
    from driver.link import SerialRig

    def progress(event: dict[str, Any]) -> None:
        observer(event)
        if event.get("event") == "belief":
            sys.stderr.write(
                f"\rrolled {math.degrees(event['rotation']):6.1f}°  best {event['map_arc']:8.2f} mm  "
                f"{event['mass']:6.1%} within {SUCCESS_RADIUS} mm "
            )
            sys.stderr.flush()

    args.interrupted = CONNECTING
    with ending_progress_line(log), SerialRig(args.arm, args.daq, timeout=args.timeout, log=log) as rig:
        _check_straight_hand(rig, args.jaw)
        here = tuple(rig.pose())
        if calibration is None:
            calibration = calibrate(rig, here)
            Hand(rig, here)
        x, y, phi = here
        start = (x + 40.0 * math.cos(phi), y + 40.0 * math.sin(phi), phi)  # as run_from_here: contact at -40 mm
        doc, _, calls = run_reactive(args, rig, part, calibration, start, observer=progress)
    args.interrupted = RELEASED
    if log is not None:
        # the filter's calls, for 'locate' to have the belief again (driver.records.filter_log)
        log(calls_event(calls))
        log({"event": "result", **doc})
        log.close()
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        print_reactive(doc)
    return exit_status(doc)
