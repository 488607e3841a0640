"""Commands on a simulated rig: ``simulate`` (roll, localize, save the trace) and ``emulate`` (serve the
arm's and the DAQ's serial protocols from a simulated rig)."""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import asdict
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from localizer import Outline, Part, QueryError, WheelJaw

from ..records import REACTIVE_FORMAT, part_record
from ..rig import RigError
from ._options import (
    PLOT_SUFFIXES,
    STEP_DEG,
    UsageError,
    add_command,
    check_before_moving,
    finite,
    jaw_argument,
    off_scale,
    part_arguments,
    pressing,
    reactive_arguments,
    read_part,
    roll_degrees,
    servo_arguments,
    step_degrees,
    tcp_port,
)
from ._output import emit_run, exit_status, print_reactive, run_reactive, run_summary
from ._wheel import simulate_wheel, wheel_rig
from ._world import world_change, world_fields

if TYPE_CHECKING:
    from sim2d import SimRig, WheelRig

__all__ = ["register", "simulate_command", "emulate_command"]


def register(sub: Any) -> None:
    """Add ``simulate`` and ``emulate`` to the subparsers ``sub``."""
    sim = add_command(
        sub,
        "simulate",
        simulate_command,
        help="roll a simulated jaw on a part and save the trace",
        description="Calibrate a simulated rig, establish contact at --start, roll, "
        "localize, and save the readings with their ground truth.",
    )
    part_arguments(sim)
    jaw_argument(sim)
    sim.add_argument(
        "--start",
        type=finite,
        required=True,
        metavar="MM",
        help="arc position of the first contact, mm counter-clockwise from the part's first point",
    )
    sim.add_argument(
        "--roll",
        type=roll_degrees,
        action="append",
        metavar="DEG",
        help="a roll's rotation, degrees (positive: counter-clockwise); repeat for more rolls "
        "(required unless --reactive)",
    )
    sim.add_argument(
        "--noise",
        default="paper",
        metavar="none|paper|FILE.toml",
        help="noise model: a preset or a TOML file (default paper)",
    )
    sim.add_argument(
        "--engine",
        choices=("pymunk", "kinematic"),
        help="pymunk rigid-body world, or the kinematic (static-equilibrium) world (default pymunk; "
        "kinematic for a DXF or SVG outline, with either finger: both read a face and a corner alike there, "
        "and a reactive roll on a drawing takes several times longer in pymunk)",
    )
    sim.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    world = sim.add_mutually_exclusive_group()
    world.add_argument(
        "--world",
        metavar="FILE.toml",
        help="a world whose part is not its model: a [world] table (defects, scale, spikes; as a study's, "
        "drawn from --seed, defects near --start unless it says anywhere)",
    )
    world.add_argument(
        "--world-part",
        metavar="FILE",
        help="the world's own part (a scan of the part, in the model's frame); the model is PART",
    )
    sim.add_argument(
        "--step", type=step_degrees, default=STEP_DEG, metavar="DEG", help=f"rolling step, degrees (default {STEP_DEG})"
    )
    servo_arguments(sim)
    reactive_arguments(sim)
    sim.add_argument("--out", required=True, metavar="TRACE.npz", help="trace file to write")
    sim.add_argument("--plot", metavar="FILE.png", help="draw the part, the jaw poses, the true and estimated contacts")
    sim.add_argument("--json", action="store_true", help="print the result as JSON")

    emu = add_command(
        sub,
        "emulate",
        emulate_command,
        help="serve the arm and DAQ protocols, backed by a simulated rig",
        description="Emulate the arm controller and the DAQ of docs/protocol.md on "
        "loopback TCP (arm on PORT, DAQ on PORT+1) or on two pseudo-terminals, "
        "until killed.",
    )
    part_arguments(emu)
    jaw_argument(emu)
    emu.add_argument("--tcp", type=tcp_port, metavar="PORT", help="serve on 127.0.0.1:PORT and PORT+1 (default: ptys)")
    emu.add_argument(
        "--start",
        type=finite,
        metavar="MM",
        help="the hand starts with the jaw's centre facing this arc position, 1 mm off "
        "(default: the part's most curved point that the whole jaw reaches)",
    )
    emu.add_argument("--noise", default="paper", metavar="none|paper|FILE.toml", help="noise model (default paper)")
    emu.add_argument(
        "--engine", choices=("pymunk", "kinematic"), default="kinematic", help="the simulated world (default kinematic)"
    )
    emu.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    emu.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help=(
            "inject a fault: drop=P, garble=P, delay=S, disconnect-after=N, saturate=V, encoder-stuck=N, "
            "daq-constant=V, limit-after=N, drift=V_PER_S; repeatable"
        ),
    )


def simulate_command(args: argparse.Namespace) -> int:
    from driver.jaw import calibrate_simulated, laid_off, localize_by_rolling
    from driver.records import Trace
    from sim2d import SimRig, load_noise

    check_before_moving(args, {"out": (".npz",), "plot": PLOT_SUFFIXES})
    part = read_part(args)
    if args.engine is None:
        args.engine = "kinematic" if isinstance(part, Outline) else "pymunk"
    if isinstance(args.jaw, WheelJaw):
        return simulate_wheel(args, part, args.jaw)
    off_scale(args, args.jaw)  # refused for a straight jaw
    noise = load_noise(args.noise)
    if not args.roll and not args.reactive:
        raise UsageError("give the rolls (--roll DEG, repeated) or --reactive")
    rolls = [math.radians(r) for r in (args.roll or [20.0])]
    if not 0 <= args.start < part.perimeter:
        raise QueryError(f"--start {args.start} mm must be in [0, perimeter={part.perimeter:.3f}) mm")
    calibration = calibrate_simulated(part, noise, seed=args.seed + 1, engine=args.engine)
    change = world_change(args, part)
    rig = SimRig(part, noise=noise, seed=args.seed, engine=args.engine, change=change)
    jaw_start = -40.0 if rolls[0] > 0 else 40.0
    _check_reach(part, args.start, jaw_start)
    if args.reactive:
        doc, res, calls = run_reactive(
            args, rig, part, calibration, rig.approach_pose(args.start, jaw_position=jaw_start, standoff=1.0)
        )
        doc.update(world_fields(change, rig))
        np.savez(
            args.out,
            arcs=np.array(res.arcs),
            turns=np.array(res.turns),
            true_arcs=np.array(res.true_arcs),
            segments=np.array(res.segments),
            history=np.array(res.history, dtype=float).reshape(-1, 4),
            **cast(dict[str, Any], calls),
            metadata=np.array(
                json.dumps(
                    {
                        **doc,
                        "format": REACTIVE_FORMAT,
                        "part": part_record(part, args.part),
                        "jaw": str(args.jaw),
                        "noise": str(args.noise),
                        "seed": args.seed,
                        "engine": args.engine,
                        "start_arc": args.start,
                        **world_fields(change, rig),
                    }
                )
            ),
        )
        doc["trace"] = str(args.out)
        if args.plot:
            from driver.records import plot_reactive

            plot_reactive(part, res, args.plot)
            doc["plot"] = str(args.plot)
        print(json.dumps(doc, indent=2) if args.json else "", end="\n" if args.json else "")
        if not args.json:
            print_reactive(doc)
            print(f"readings written to {args.out}")
        return exit_status(doc)
    run = localize_by_rolling(
        rig,
        part,
        rolls,
        calibration=calibration,
        step=math.radians(args.step),
        approach_pose=rig.approach_pose(args.start, jaw_position=jaw_start, standoff=1.0),
        pressing=pressing(args),
    )
    first = run.rolls[0].truth[0].contact_arc
    if laid_off(part, first, args.start):
        raise RigError(
            f"--start {args.start} mm is not on the part's convex hull: a straight jaw laid there "
            f"touches at {first:.2f} mm instead"
        )
    trace = Trace.from_run(
        run,
        calibration,
        part=part_record(part, args.part),
        engine=args.engine,
        jaw=str(args.jaw),
        noise_name=str(args.noise),
        noise=asdict(noise),
        seed=args.seed,
        start_arc=args.start,
        rolls_deg=list(args.roll),
        step_deg=args.step,
        **world_fields(change, rig),
    )
    trace.save(args.out)
    doc = run_summary(part, trace, run.localization)
    doc.update(world_fields(change, rig))
    doc["trace"] = str(args.out)
    return emit_run(args, doc, part, trace, run.localization)


def _check_reach(part: Part | Outline, start: float, jaw: float) -> None:
    """Refuse, before anything moves, a start the jaw cannot be laid on with the contact at ``jaw`` mm."""
    from localizer import DEFAULT_JAW, reach_for

    reach = reach_for(part, DEFAULT_JAW)
    if bool(reach.touchable(start, jaw=jaw)):
        return
    lo, hi = (float(v) for v in reach.interval(start))
    lo, hi = max(lo, -DEFAULT_JAW.half), min(hi, DEFAULT_JAW.half)
    where = (
        f"it touches there only with the contact between {lo:+.1f} and {hi:+.1f} mm on the jaw"
        if lo < hi
        else "no place on the jaw touches there (a concave stretch, or a concavity narrower than the jaw)"
    )
    raise RigError(
        f"--start {start} mm: a {DEFAULT_JAW} jaw laid there with the contact at {jaw:+.0f} mm on it "
        f"would touch the part elsewhere; {where}. Pick another start"
    )


def emulate_command(args: argparse.Namespace) -> int:
    import signal
    import threading

    from driver.link import Emulator, Faults
    from sim2d import SimRig

    part = read_part(args)
    faults = Faults.parse(args.fault)
    rig: SimRig | WheelRig
    if isinstance(args.jaw, WheelJaw):
        rig, start_pose = wheel_rig(part, args.jaw, args)
    else:
        rig = SimRig(part, noise=args.noise, seed=args.seed, engine=args.engine)
        if args.start is None:
            start_pose = rig.calibration_pose()
        else:
            # laid where it touches elsewhere, every later command would read nonsense (a calibration "not
            # monotone"): refused before the ports are served
            _check_reach(part, float(args.start) % part.perimeter, 0.0)
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
