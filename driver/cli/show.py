"""``rolltouch show``: a picture of how a run's belief narrowed."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

import numpy as np

from ..rig import RigError
from ._options import UsageError, add_command, jaw_argument, writable_file

if TYPE_CHECKING:
    from ..records import WheelTrace

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
    p.add_argument(
        "--same-part",
        action="store_true",
        help="draw the record on --part although it was made on another part file (one known to be the same)",
    )


def show_command(args: argparse.Namespace) -> int:
    from localizer import DEFAULT_JAW, ContactFilter, WheelFilter, load_part

    from ..records import (
        FILM_SUFFIXES,
        LOG_COLUMNS,
        REACTIVE_FORMAT,
        Trace,
        calls_from_events,
        check_same_part,
        plot_belief_history,
        read_archive,
        read_log,
        replay_beliefs,
        replay_wheel_beliefs,
        sequence_calls,
        trace_format,
        write_film,
    )

    writable_file(args.out, "--out", (".png", *FILM_SUFFIXES))
    if not 1 <= args.fps <= 60:
        raise UsageError(f"--fps {args.fps} must be from 1 to 60")
    path = str(args.trace)
    wheel = _wheel_record(path)
    finger = wheel.metadata["jaw"] if wheel is not None else str(DEFAULT_JAW)
    if args.jaw is not None and str(args.jaw) != finger:
        raise RigError(f"trace {path} is of the {finger} finger, not of --jaw {args.jaw}")
    if wheel is not None:
        part = load_part(args.part)
        check_same_part(wheel.metadata.get("part"), part, args.part, f"trace {path}", same=args.same_part)
        history = replay_wheel_beliefs(WheelFilter(part, wheel.wheel), wheel.columns)
        radius: float | None = wheel.wheel.radius
    else:
        if path.endswith(".jsonl") and (calls := calls_from_events(read_log(path))) is not None:
            columns, recorded, readings = calls, read_log(path)[0].get("part"), None
        elif trace_format(path) == REACTIVE_FORMAT:
            meta, columns = read_archive(path, LOG_COLUMNS)
            readings = read_archive(path, ("arcs", "turns", "true_arcs"))[1]
            recorded = meta.get("part")
        else:  # fixed rolls: their readings given to the reactive method's filter, as the studies' grid method
            if path.endswith(".jsonl") and any(e.get("event") == "belief" for e in read_log(path)):
                raise RigError(f"run log {path}: a reactive run's log without its filter calls (it ended before them)")
            trace = Trace.load(path)
            seq = trace.step_sequence()
            columns = sequence_calls(seq)
            readings = {"arcs": seq["z"], "turns": seq["turn"], "true_arcs": seq["truth"]}
            recorded = trace.metadata.get("part")
        part = load_part(args.part)
        check_same_part(recorded, part, args.part, f"trace {path}", same=args.same_part)
        history = replay_beliefs(ContactFilter(part), columns, readings)
        radius = None
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


def _wheel_record(path: str) -> WheelTrace | None:
    """The wheel's trace or run log at ``path``, or None if it is a straight jaw's record."""
    from ..records import WHEEL_FORMAT, WheelTrace, read_log, trace_format

    if path.endswith(".jsonl"):
        if not str(read_log(path)[0].get("jaw", "straight")).startswith("wheel"):
            return None
    elif trace_format(path) != WHEEL_FORMAT:
        return None
    return WheelTrace.load(path)
