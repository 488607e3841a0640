"""The ``rolltouch`` command line.

Angles are given in degrees on the command line and converted to radians
at this edge; lengths are in mm.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from dataclasses import asdict

import numpy as np

from localizer import DIRECTIONS, RULES, LocalizerError, RolltouchError, load_part, localize

from .rig import RigError

__all__ = ["main", "build_parser"]


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text!r} must be a positive number")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rolltouch", description="Localize a jaw on a known curved part by rolling.")
    sub = parser.add_subparsers(dest="command", required=True)
    loc = sub.add_parser("localize", help="find where the jaw rolled from measured (length, turn) rolls",
                         description="Find every place on the part where the measured rolls could have "
                                     "happened and rank them.")
    loc.add_argument("part", help="part file (JSON of DESIGN.md, or CSV of x,y in mm)")
    loc.add_argument("--length", type=float, required=True, metavar="MM", help="contact travel of the first roll, mm")
    loc.add_argument("--turn", type=float, required=True, metavar="DEG",
                     help="jaw rotation of the first roll, degrees (counter-clockwise positive)")
    loc.add_argument("--then", nargs=2, type=float, action="append", default=[], metavar=("MM", "DEG"),
                     help="a following roll: contact travel (mm) and rotation (deg); repeat for more")
    loc.add_argument("--rule", choices=RULES, default="likelihood", help="disambiguation rule (default likelihood)")
    loc.add_argument("--direction", choices=DIRECTIONS, default="ccw",
                     help="direction the contact moved on the part (default ccw)")
    loc.add_argument("--sd-length", type=_positive, default=0.5, metavar="MM",
                     help="std. dev. of a measured contact travel (likelihood rule, default 0.5 mm)")
    loc.add_argument("--sd-turn", type=_positive, default=0.03, metavar="DEG",
                     help="std. dev. of a measured rotation (likelihood rule, default 0.03 deg)")
    loc.add_argument("--length-tol", type=_positive, default=0.004, metavar="MM",
                     help="paper rule: length tolerance (default 0.004 mm)")
    loc.add_argument("--turn-tol", type=_positive, default=float(np.degrees(0.0004)), metavar="DEG",
                     help="paper rule: turn tolerance (default 0.0004 rad = 0.0229 deg)")
    loc.add_argument("--json", action="store_true", help="print the result as JSON")
    loc.add_argument("--plot", metavar="FILE.png", help="draw the part, the candidate segments and the contact")

    sim = sub.add_parser("simulate", help="roll a simulated jaw on a part and save the trace",
                         description="Calibrate a simulated rig, establish contact at --start, roll, "
                                     "localize, and save the readings with their ground truth.")
    sim.add_argument("part", help="part file")
    sim.add_argument("--start", type=float, required=True, metavar="MM",
                     help="arc position of the first contact, mm counter-clockwise from the part's first point")
    sim.add_argument("--roll", type=float, action="append", metavar="DEG",
                     help="a roll's rotation, degrees (positive: counter-clockwise); repeat for more rolls "
                          "(required unless --reactive)")
    sim.add_argument("--noise", default="paper", metavar="none|paper|FILE.toml",
                     help="noise model: a preset or a TOML file (default paper)")
    sim.add_argument("--engine", choices=("pymunk", "kinematic"), default="pymunk",
                     help="pymunk rigid-body world, or the kinematic (static-equilibrium) world (default pymunk)")
    sim.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    sim.add_argument("--step", type=_positive, default=0.2, metavar="DEG", help="rolling step, degrees (default 0.2)")
    _servo_arguments(sim)
    _reactive_arguments(sim)
    sim.add_argument("--out", required=True, metavar="TRACE.npz", help="trace file to write")
    sim.add_argument("--plot", metavar="FILE.png", help="draw the part, the jaw poses, the true and estimated contacts")
    sim.add_argument("--json", action="store_true", help="print the result as JSON")

    lct = sub.add_parser("locate", help="localize from a saved trace",
                         description="Recompute the rolls' (L, Ω) from a trace's readings and localize.")
    lct.add_argument("trace", help="trace file (.npz) from 'rolltouch simulate'")
    lct.add_argument("--part", required=True, help="part file (the model the localizer is given)")
    lct.add_argument("--rule", choices=RULES, default="likelihood", help="disambiguation rule (default likelihood)")
    lct.add_argument("--json", action="store_true", help="print the result as JSON")
    lct.add_argument("--plot", metavar="FILE.png", help="draw the part, the jaw poses, the true and estimated contacts")
    emu = sub.add_parser("emulate", help="serve the arm and DAQ protocols, backed by a simulated rig",
                         description="Emulate the arm controller and the DAQ of docs/protocol.md on "
                                     "loopback TCP (arm on PORT, DAQ on PORT+1) or on two pseudo-terminals, "
                                     "until killed.")
    emu.add_argument("part", help="part file")
    emu.add_argument("--tcp", type=int, metavar="PORT", help="serve on 127.0.0.1:PORT and PORT+1 (default: ptys)")
    emu.add_argument("--start", type=float, metavar="MM",
                     help="the hand starts with the jaw's centre facing this arc position, 1 mm off "
                          "(default: the part's most curved point that the whole jaw reaches)")
    emu.add_argument("--noise", default="paper", metavar="none|paper|FILE.toml", help="noise model (default paper)")
    emu.add_argument("--engine", choices=("pymunk", "kinematic"), default="kinematic",
                     help="the simulated world (default kinematic)")
    emu.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    emu.add_argument("--fault", action="append", default=[], metavar="NAME=VALUE",
                     help="inject a fault: drop=P, garble=P, delay=S, disconnect-after=N, saturate=V; repeatable")

    cal = sub.add_parser("calibrate", help="calibrate the wrist sensor on a rig (paper §III-B)",
                         description="With the jaw's centre facing an immobilized object, clear of it: tap it "
                                     "at 11 jaw positions from -50 to 50 mm and save the ratio spline.")
    _rig_arguments(cal)
    cal.add_argument("--out", required=True, metavar="CAL.json", help="calibration file to write")

    run = sub.add_parser("run", help="roll on a rig and localize",
                         description="From the present pose (the jaw's centre facing the start point, clear "
                                     "of the part): calibrate if no calibration is given, slide 40 mm, "
                                     "establish contact, roll, localize.")
    run.add_argument("part", help="part file")
    _rig_arguments(run)
    run.add_argument("--calibration", metavar="CAL.json", help="calibration from 'rolltouch calibrate'")
    run.add_argument("--roll", type=float, action="append", metavar="DEG",
                     help="a roll's rotation in degrees; repeat (default 20 then 15)")
    run.add_argument("--step", type=_positive, default=0.2, metavar="DEG", help="rolling step (default 0.2°)")
    _servo_arguments(run)
    _reactive_arguments(run)
    run.add_argument("--log", metavar="FILE.jsonl", help="run log, JSON Lines, flushed per sample")
    run.add_argument("--plot", metavar="FILE.png", help="draw the part, the jaw poses and the estimate")
    run.add_argument("--json", action="store_true", help="print the same object as 'rolltouch locate --json'")
    return parser


def _rig_arguments(p) -> None:
    """--arm, --daq and --timeout of the commands that talk to a rig."""
    p.add_argument("--arm", required=True, metavar="URL", help="arm controller: device path or pyserial URL")
    p.add_argument("--daq", required=True, metavar="URL", help="DAQ: device path or pyserial URL")
    p.add_argument("--timeout", type=_positive, default=2.0, metavar="S", help="reply deadline (default 2 s)")


def _servo_arguments(p) -> None:
    """--servo-gain and --no-guard: hold the force with the arm's servo after every press."""
    p.add_argument("--servo-gain", type=_positive, metavar="G",
                   help="after every press, hold Δv1 with the arm's 1 kHz force servo at this gain (N/N) "
                        "for 0.3 s, refusing a loop that loses the part or rings above 0.05 V (docs/passivity.md); default: no servo")
    p.add_argument("--no-guard", action="store_true",
                   help="run that servo without its passivity observer/controller")


def _reactive_arguments(p) -> None:
    """--reactive and its options: roll until the belief is sure (driver.reactive)."""
    p.add_argument("--reactive", action="store_true",
                   help="instead of fixed rolls, roll step by step until the contact is known within 0.3 mm "
                        "with --confidence, or --max-rotation is rolled (docs/robustness.md)")
    p.add_argument("--confidence", type=_positive, default=0.95, metavar="P",
                   help="reactive: probability within 0.3 mm that stops the rolling (default 0.95)")
    p.add_argument("--max-rotation", type=_positive, default=240.0, metavar="DEG",
                   help="reactive: rotation budget, both directions counted (default 240°)")


def _reactive(args, rig, part, calibration, approach_pose, observer=None) -> dict:
    """Run the reactive localization on ``rig``; the JSON object of 'simulate|run --reactive'."""
    from driver.reactive import localize_reactively
    from localizer import ContactFilter

    if not 0 < args.confidence < 1:
        raise RigError(f"--confidence {args.confidence} must be between 0 and 1")
    res = localize_reactively(rig, part, calibration=calibration, filter=ContactFilter(part),
                              approach_pose=approach_pose, step=math.radians(args.step),
                              confidence=args.confidence, max_rotation=math.radians(args.max_rotation),
                              observer=observer, **_servo_option(args))
    b = res.belief
    doc = {"part": part.name, "method": "reactive", "estimate_arc": b.map_arc, "mass": b.mass,
           "ambiguous": b.ambiguous, "informative": b.informative, "stopped": res.stopped,
           "rotation_deg": math.degrees(res.rotation), "steps": res.steps, "reversals": res.reversals,
           "regrasps": res.regrasps, "modes": [{"arc": m.arc, "probability": m.mass} for m in b.modes[:5]]}
    truth = getattr(rig, "truth", None)
    if truth is not None:
        true_arc = truth()["contact_arc"]
        doc["true_arc"] = true_arc
        doc["error_mm"] = float(abs(part.arc_offset(b.map_arc, true_arc))) if math.isfinite(true_arc) else None
    return doc, res


def _print_reactive(doc) -> None:
    verdict = "AMBIGUOUS" if doc["ambiguous"] else ("no information" if not doc["informative"] else "localized")
    print(f"rolled {doc['rotation_deg']:.1f}° in {doc['steps']} steps ({doc['stopped']}, "
          f"{doc['reversals']} reversals, {doc['regrasps']} regrasps)")
    print(f"{verdict}: contact now at arc {doc['estimate_arc']:.3f} mm, {doc['mass']:.1%} within 0.3 mm")
    for m in doc["modes"][1:3]:
        print(f"  another mode: arc {m['arc']:.3f} mm, probability {m['probability']:.3f}")
    if doc.get("error_mm") is not None:
        err = doc["error_mm"]
        print(f"truth: {doc['true_arc']:.3f} mm, error {err:.3f} mm ({'success' if err < 0.3 else 'failure'} at 0.3 mm)")


def _servo_option(args) -> dict:
    if args.servo_gain is None:
        if args.no_guard:
            raise RigError("--no-guard needs --servo-gain: without the servo there is nothing to guard")
        return {}
    return {"servo": {"gain": args.servo_gain, "guard": not args.no_guard, "duration": 0.3, "max_std": 0.05}}


def _run_summary(part, trace, loc) -> dict:
    """The JSON object of 'simulate' and 'locate'."""
    best = loc.best
    estimate = best.end_arc if best is not None else None
    doc = {
        "part": part.name,
        "estimates": [{"length": L, "turn": w, "turn_deg": math.degrees(w)} for L, w in loc.rolls],
        "estimate_arc": estimate,
        "ambiguous": loc.ambiguous,
        "candidates": [c.as_dict() for c in loc.candidates],
    }
    true_arc = trace.true_arc
    if math.isfinite(true_arc):
        doc["true_arc"] = true_arc
        doc["error_mm"] = None if estimate is None else abs(float(part.arc_offset(estimate, true_arc)))
    return doc


def _emit_run(args, doc, part, trace, loc) -> None:
    """Print a run's result (JSON or text) and draw it if asked: simulate, locate and run alike."""
    if args.json:
        json.dump(doc, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        _print_run(doc)
        if "trace" in doc:
            print(f"trace written to {doc['trace']}")
    if args.plot:
        from driver.plotting import plot_run

        plot_run(part, trace, loc, args.plot)
        if not args.json:
            print(f"plot written to {args.plot}")


def _print_run(doc) -> None:
    for k, e in enumerate(doc["estimates"]):
        print(f"roll {k + 1}: L = {e['length']:.3f} mm, Ω = {e['turn_deg']:.3f}°")
    if doc["estimate_arc"] is None:
        print("no place on the part fits these rolls")
    else:
        verdict = "AMBIGUOUS" if doc["ambiguous"] else "localized"
        print(f"{verdict}: contact now at arc {doc['estimate_arc']:.3f} mm "
              f"(p={doc['candidates'][0]['probability']:.3f})")
    if "true_arc" in doc:
        err = doc["error_mm"]
        print(f"truth: {doc['true_arc']:.3f} mm, error {err:.3f} mm "
              f"({'success' if err is not None and err < 0.3 else 'failure'} at 0.3 mm)")


def _simulate(args) -> int:
    from driver.procedures import calibrate, localize_by_rolling
    from driver.trace import Trace
    from sim2d import SimRig, load_noise

    part = load_part(args.part)
    noise = load_noise(args.noise)
    if not args.roll and not args.reactive:
        raise RigError("give the rolls (--roll DEG, repeated) or --reactive")
    rolls = [math.radians(r) for r in (args.roll or [20.0])]
    if not 0 <= args.start < part.perimeter:
        raise LocalizerError(f"--start {args.start} mm must be in [0, perimeter={part.perimeter:.3f}) mm")
    # calibrate on the part's most curved point that the whole jaw reaches, with its own rig instance
    cal_rig = SimRig(part, noise=noise, seed=args.seed + 1, engine=args.engine)
    calibration = calibrate(cal_rig, cal_rig.calibration_pose())
    rig = SimRig(part, noise=noise, seed=args.seed, engine=args.engine)
    jaw_start = -40.0 if rolls[0] > 0 else 40.0
    _check_reach(part, args.start, jaw_start)
    if args.reactive:
        doc, res = _reactive(args, rig, part, calibration,
                             rig.approach_pose(args.start, jaw_position=jaw_start, standoff=1.0))
        np.savez(args.out, arcs=np.array(res.arcs), turns=np.array(res.turns), true_arcs=np.array(res.true_arcs),
                 segments=np.array(res.segments), history=np.array(res.history, dtype=float).reshape(-1, 4),
                 metadata=np.array(json.dumps({**doc, "noise": str(args.noise), "seed": args.seed,
                                               "engine": args.engine, "start_arc": args.start})))
        doc["trace"] = str(args.out)
        print(json.dumps(doc, indent=2) if args.json else "", end="\n" if args.json else "")
        if not args.json:
            _print_reactive(doc)
            print(f"readings written to {args.out}")
        return 0
    run = localize_by_rolling(rig, part, rolls, calibration=calibration, step=math.radians(args.step),
                              approach_pose=rig.approach_pose(args.start, jaw_position=jaw_start, standoff=1.0),
                              **_servo_option(args))
    first = run.rolls[0].truth[0][0]
    if math.isfinite(first) and abs(float(part.arc_offset(first, args.start))) > 1.0:
        raise RigError(f"--start {args.start} mm is not on the part's convex hull: a straight jaw laid there "
                       f"touches at {first:.2f} mm instead")
    trace = Trace.from_run(run, calibration, part={"name": part.name, "file": str(args.part),
                                                   "perimeter": part.perimeter},
                           engine=args.engine, noise_name=str(args.noise), noise=asdict(noise), seed=args.seed,
                           start_arc=args.start, rolls_deg=list(args.roll), step_deg=args.step)
    trace.save(args.out)
    doc = _run_summary(part, trace, run.localization)
    doc["trace"] = str(args.out)
    _emit_run(args, doc, part, trace, run.localization)
    return 0


def _check_reach(part, start: float, jaw: float) -> None:
    """Refuse, before anything moves, a start the jaw cannot be laid on with the contact at ``jaw`` mm."""
    from localizer import DEFAULT_JAW, reach_for

    reach = reach_for(part, DEFAULT_JAW)
    if bool(reach.touchable(start, jaw=jaw)):
        return
    lo, hi = (float(v) for v in reach.interval(start))
    lo, hi = max(lo, -DEFAULT_JAW.half), min(hi, DEFAULT_JAW.half)
    where = (f"it touches there only with the contact between {lo:+.1f} and {hi:+.1f} mm on the jaw"
             if lo < hi else "no place on the jaw touches there (a concave stretch, or a concavity narrower "
                             "than the jaw)")
    raise RigError(f"--start {start} mm: a {DEFAULT_JAW} jaw laid there with the contact at {jaw:+.0f} mm on it "
                   f"would touch the part elsewhere; {where}. Pick another start")


def _locate(args) -> int:
    from driver.trace import Trace

    part = load_part(args.part)
    trace = Trace.load(args.trace)
    estimates = trace.estimates()
    direction = "ccw" if np.sign(trace.metadata["steps"][0]) > 0 else "cw"
    loc = localize(part, estimates, rule=args.rule, direction=direction)
    _emit_run(args, _run_summary(part, trace, loc), part, trace, loc)
    return 0


def _localize(args) -> int:
    part = load_part(args.part)
    rolls = [(args.length, np.radians(args.turn))] + [(L, np.radians(d)) for L, d in args.then]
    result = localize(part, rolls, rule=args.rule, direction=args.direction, sd_length=args.sd_length,
                      sd_turn=float(np.radians(args.sd_turn)), length_tol=args.length_tol,
                      turn_tol=float(np.radians(args.turn_tol)))

    def xy(arc):
        return [float(v) for v in part.point_at_arc(arc)]

    if args.json:
        doc = {
            "part": part.name,
            "perimeter": part.perimeter,
            "rule": result.rule,
            "direction": result.direction,
            "rolls": [{"length": L, "turn": w, "turn_deg": float(np.degrees(w))} for L, w in result.rolls],
            "segments": [dict(s.as_dict(), start_xy=xy(s.start_arc), end_xy=xy(s.end_arc)) for s in result.segments],
            "candidates": [dict(c.as_dict(), start_xy=xy(c.start_arc), end_xy=xy(c.end_arc))
                           for c in result.candidates],
            "best": 0 if result.best is not None else None,
            "ambiguous": result.ambiguous,
        }
        json.dump(doc, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(f"part {part.name}: perimeter {part.perimeter:.3f} mm, {part.n_knots} knots")
        print(f"roll 1 (L={rolls[0][0]:.4g} mm, turn={args.turn:.4g} deg): "
              f"{len(result.segments)} feasible segment(s)")
        if not result.candidates:
            print("no place on the part fits these rolls")
        else:
            print(f"{'#':>3} {'start mm':>10} {'contact now mm':>15} {'x':>9} {'y':>9} {'prob':>6}")
            for k, c in enumerate(result.candidates):
                x, y = xy(c.end_arc)
                print(f"{k:>3} {c.start_arc:>10.3f} {c.end_arc:>15.3f} {x:>9.3f} {y:>9.3f} {c.probability:>6.3f}")
            verdict = "AMBIGUOUS" if result.ambiguous else "localized"
            print(f"{verdict}: contact now at arc {result.best.end_arc:.3f} mm "
                  f"(p={result.best.probability:.3f}, rule {result.rule})")
    if args.plot:
        from driver.plotting import plot_localization

        plot_localization(part, result, args.plot)
        if not args.json:
            print(f"plot written to {args.plot}")
    return 0


def _emulate(args) -> int:
    import signal
    import threading

    from driver.emulator import Emulator, Faults
    from sim2d import SimRig

    part = load_part(args.part)
    faults = Faults.parse(args.fault)
    rig = SimRig(part, noise=args.noise, seed=args.seed, engine=args.engine)
    if args.start is None:
        start_pose = rig.calibration_pose()
    else:
        start_pose = rig.approach_pose(float(args.start) % part.perimeter, jaw_position=0.0, standoff=1.0)
    emulator = Emulator(rig, start_pose=start_pose, faults=faults, seed=args.seed)
    if args.tcp is not None:
        arm, daq = emulator.serve_tcp(args.tcp)
    else:
        arm, daq = emulator.serve_pty()
    print(f"arm {arm}", flush=True)
    print(f"daq {daq}", flush=True)
    done = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: done.set())
    try:
        while not done.wait(0.5) and not emulator.stopped.is_set():
            pass
    except KeyboardInterrupt:
        pass
    emulator.close()
    return 0


def _calibrate(args) -> int:
    from driver.procedures import calibrate
    from driver.serial_rig import SerialRig

    with SerialRig(args.arm, args.daq, timeout=args.timeout) as rig:
        calibration = calibrate(rig, rig.pose())
    calibration.save(args.out)
    print(f"calibration written to {args.out}: ratio {calibration.ratios[0]:.5f} at -50 mm to "
          f"{calibration.ratios[-1]:.5f} at +50 mm")
    return 0


def _progress(event) -> None:
    if event.get("event") == "reading":
        sys.stderr.write(f"\rroll {event['roll'] + 1}  step {event['step']:>4}/{event['steps']}  "
                         f"Δv1 {event['dv1']:.3f} V  contact {event['jaw_position']:+7.2f} mm ")
        sys.stderr.flush()


def _run(args) -> int:
    from driver.procedures import Calibration, run_from_here
    from driver.runlog import RunLog
    from driver.serial_rig import SerialRig
    from driver.trace import Trace

    part = load_part(args.part)
    rolls = args.roll or [20.0, 15.0]
    calibration = Calibration.load(args.calibration) if args.calibration else None
    header = {"part": {"name": part.name, "file": str(args.part), "perimeter": part.perimeter},
              "arm": args.arm, "daq": args.daq, "rolls_deg": rolls, "step_deg": args.step}
    if calibration is not None:
        header["calibration"] = {"positions": list(calibration.positions), "ratios": list(calibration.ratios),
                                 "target": calibration.target}
    log = RunLog(args.log, header) if args.log else None

    def observer(event):
        if log is not None:
            log(event)
        _progress(event)

    if args.reactive:
        return _run_reactive(args, part, calibration, log, observer)
    with _ending_progress_line(log), SerialRig(args.arm, args.daq, timeout=args.timeout, log=log) as rig:
        run, calibration = run_from_here(rig, part, [math.radians(r) for r in rolls], calibration=calibration,
                                         step=math.radians(args.step), observer=observer,
                                         **_servo_option(args))
    trace = Trace.from_run(run, calibration, part=header["part"], arm=args.arm, daq=args.daq,
                           rolls_deg=rolls, step_deg=args.step, engine="serial")
    doc = _run_summary(part, trace, run.localization)
    if log is not None:
        log({"event": "result", **doc})
        log.close()
    _emit_run(args, doc, part, trace, run.localization)
    return 0


@contextlib.contextmanager
def _ending_progress_line(log):
    """End the progress line on stderr; on any failure log it and close the run log, then re-raise."""
    try:
        yield
        sys.stderr.write("\n")
    except BaseException as exc:
        sys.stderr.write("\n")
        if log is not None:
            log({"event": "error", "message": str(exc) or type(exc).__name__})
            log.close()
        raise


def _run_reactive(args, part, calibration, log, observer) -> int:
    """'run --reactive': from the present pose, calibrate if needed, slide 40 mm, roll until sure."""
    from driver.procedures import Hand, calibrate
    from driver.serial_rig import SerialRig

    def progress(event):
        observer(event)
        if event.get("event") == "belief":
            sys.stderr.write(f"\rrolled {math.degrees(event['rotation']):6.1f}°  best {event['map_arc']:8.2f} mm  "
                             f"{event['mass']:6.1%} within 0.3 mm ")
            sys.stderr.flush()

    with _ending_progress_line(log), SerialRig(args.arm, args.daq, timeout=args.timeout, log=log) as rig:
        here = tuple(rig.pose())
        if calibration is None:
            calibration = calibrate(rig, here)
            Hand(rig, here)
        x, y, phi = here
        start = (x + 40.0 * math.cos(phi), y + 40.0 * math.sin(phi), phi)  # as run_from_here: contact at -40 mm
        doc, _ = _reactive(args, rig, part, calibration, start, observer=progress)
    if log is not None:
        log({"event": "result", **doc})
        log.close()
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        _print_reactive(doc)
    return 0


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        if args.command == "localize":
            return _localize(args)
        if args.command == "simulate":
            return _simulate(args)
        if args.command == "locate":
            return _locate(args)
        if args.command == "emulate":
            return _emulate(args)
        if args.command == "calibrate":
            return _calibrate(args)
        if args.command == "run":
            return _run(args)
    except RolltouchError as exc:
        print(f"rolltouch: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("rolltouch: interrupted: the arm was stopped and the jaw backed off", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    parser.error(f"unknown command {args.command!r}")
    return 2


if __name__ == "__main__":
    sys.exit(main())
