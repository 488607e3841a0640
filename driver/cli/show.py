"""``rolltouch show``: a picture of how a run's belief narrowed."""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from ..rig import RigError
from ._options import UsageError, add_command, jaw_argument, off_scale, off_scale_argument, writable_file

__all__ = ["register", "show_command"]


def register(sub: Any) -> None:
    """Add ``show`` to the subparsers ``sub``."""
    p = add_command(
        sub,
        "show",
        show_command,
        help="draw how a rolling's belief narrowed (PNG), or animate it (GIF, MP4)",
        description=(
            "Make a rolling's filter calls again (a straight jaw's or a wheel's trace from 'simulate --reactive', "
            "a run log of 'run --reactive', or fixed rolls given to the reactive method's filter) and draw the belief "
            "along the part against the rotation rolled, the truth where known, the rolling's events, and the final "
            "places on the part; or animate it."
        ),
    )
    p.add_argument(
        "trace", metavar="TRACE", help="a trace (.npz, fixed rolls or reactive, either finger) or run log (.jsonl)"
    )
    p.add_argument("--part", required=True, help="part file (the model the run was given)")
    p.add_argument(
        "--out",
        required=True,
        metavar="FILE",
        help="the output: .png the belief against rotation; .gif or .mp4 (with ffmpeg) the rolling animated",
    )
    p.add_argument("--fps", type=int, default=10, metavar="N", help="frames per second of an animation (default 10)")
    jaw_argument(p, default=None)
    off_scale_argument(p, replay=True)
    p.add_argument(
        "--same-part",
        action="store_true",
        help="draw the record on --part although it was made on another part file (one known to be the same)",
    )


def show_command(args: argparse.Namespace) -> int:
    from localizer import DEFAULT_JAW, ContactFilter, WheelFilter, load_part

    from ..records import (
        FILM_SUFFIXES,
        check_film,
        check_finger,
        check_same_part,
        open_record,
        plot_belief_history,
        reactive_calls,
        replay_beliefs,
        replay_wheel_beliefs,
        sequence_calls,
        write_film,
    )

    writable_file(args.out, "--out", (".png", *FILM_SUFFIXES))
    if not 1 <= args.fps <= 60:
        raise UsageError(f"--fps {args.fps} must be from 1 to 60")
    if not str(args.out).lower().endswith(".png"):
        check_film(args.out, args.fps)  # before the replay: an MP4 without ffmpeg is refused at once
    path = str(args.trace)
    record = open_record(path)
    wheel = record.wheel() if record.kind == "wheel" else None
    check_finger(path, wheel.metadata["jaw"] if wheel is not None else DEFAULT_JAW, args.jaw)
    radius: float | None = None
    if wheel is not None:
        part = load_part(args.part)
        check_same_part(wheel.metadata.get("part"), part, args.part, f"trace {path}", same=args.same_part)
        odds = off_scale(args, wheel.wheel, wheel.metadata.get("off_scale"))
        history = replay_wheel_beliefs(WheelFilter(part, wheel.wheel, off_scale=odds), wheel.columns)
        radius = wheel.wheel.radius
    else:
        off_scale(args, DEFAULT_JAW)  # refused: a straight jaw's record
        if record.kind == "reactive":
            meta, columns, readings = reactive_calls(record)
        else:  # fixed rolls: their readings given to the reactive method's filter, as the studies' grid method
            trace = record.fixed()
            seq = trace.step_sequence()
            meta, columns = trace.metadata, sequence_calls(seq)
            readings = {"arcs": seq["z"], "turns": seq["turn"], "true_arcs": seq["truth"]}
        part = load_part(args.part)
        check_same_part(meta.get("part"), part, args.part, f"trace {path}", same=args.same_part)
        history = replay_beliefs(ContactFilter(part), columns, readings)
    if not history.rotation.size:
        raise RigError(f"trace {path}: the rolling never asked its belief; nothing to draw")
    if str(args.out).lower().endswith(".png"):
        plot_belief_history(part, history, args.out, wheel_radius=radius)
        drawn = f"{history.rotation.size} checks"
    else:
        drawn = f"{write_film(part, history, args.out, fps=args.fps, wheel_radius=radius)} frames"
    b = history.final
    print(
        f"{args.out}: {drawn} over {np.degrees(history.rotation[-1]):.1f} degrees; "
        f"the last belief {b.mass:.1%} within {b.radius:g} mm of arc {b.map_arc:.2f} mm"
    )
    return 0
