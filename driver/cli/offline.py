"""Commands that localize from numbers already measured: ``localize`` (rolls given as (L, Ω)) and
``locate`` (a saved trace)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

import numpy as np
from numpy.typing import NDArray

from localizer import (
    DEFAULT_JAW,
    DIRECTIONS,
    LENGTH_TOL,
    RULES,
    SD_LENGTH,
    SD_TURN,
    TURN_TOL,
    ContactFilter,
    Outline,
    load_part,
    localize,
)

from ..records import (
    CALLS,
    SAME_PART_FLAG,
    check_finger,
    check_same_part,
    open_record,
    reactive_calls,
    replay_log,
)
from ..rig import RigError
from ._options import (
    PLOT_SUFFIXES,
    UsageError,
    add_command,
    check_before_moving,
    jaw_argument,
    off_scale,
    off_scale_argument,
    part_arguments,
    positive,
    read_part,
)
from ._output import belief_fields, emit_run, exit_status, no_fit_line, print_belief, run_summary
from ._wheel import locate_wheel

__all__ = ["register", "localize_command", "locate_command", "locate_reactive"]


def register(sub: Any) -> None:
    """Add ``localize`` and ``locate`` to the subparsers ``sub``."""
    loc = add_command(
        sub,
        "localize",
        localize_command,
        help="find where the jaw rolled from measured (length, turn) rolls",
        description="Find every place on the part where the measured rolls could have happened and rank them.",
    )
    part_arguments(loc)
    loc.add_argument("--length", type=float, required=True, metavar="MM", help="contact travel of the first roll, mm")
    loc.add_argument(
        "--turn",
        type=float,
        required=True,
        metavar="DEG",
        help="jaw rotation of the first roll, degrees (counter-clockwise positive)",
    )
    loc.add_argument(
        "--then",
        nargs=2,
        type=float,
        action="append",
        default=[],
        metavar=("MM", "DEG"),
        help="a following roll: contact travel (mm) and rotation (deg); repeat for more",
    )
    loc.add_argument("--rule", choices=RULES, default="likelihood", help="disambiguation rule (default likelihood)")
    loc.add_argument(
        "--direction", choices=DIRECTIONS, default="ccw", help="direction the contact moved on the part (default ccw)"
    )
    loc.add_argument(
        "--sd-length",
        type=positive,
        default=SD_LENGTH,
        metavar="MM",
        help=f"std. dev. of a measured contact travel (likelihood rule, default {SD_LENGTH} mm)",
    )
    loc.add_argument(
        "--sd-turn",
        type=positive,
        default=round(math.degrees(SD_TURN), 12),
        metavar="DEG",
        help=f"std. dev. of a measured rotation (likelihood rule, default {math.degrees(SD_TURN):.2f} deg)",
    )
    loc.add_argument(
        "--length-tol",
        type=positive,
        default=LENGTH_TOL,
        metavar="MM",
        help=f"paper rule: length tolerance (default {LENGTH_TOL} mm)",
    )
    loc.add_argument(
        "--turn-tol",
        type=positive,
        default=math.degrees(TURN_TOL),
        metavar="DEG",
        help=f"paper rule: turn tolerance (default {TURN_TOL} rad = {math.degrees(TURN_TOL):.4f} deg)",
    )
    loc.add_argument("--json", action="store_true", help="print the result as JSON")
    loc.add_argument("--plot", metavar="FILE.png", help="draw the part, the candidate segments and the contact")

    lct = add_command(
        sub,
        "locate",
        locate_command,
        help="localize from a saved trace",
        description="Recompute the rolls' (L, Ω) from a trace's readings and localize.",
    )
    lct.add_argument(
        "trace",
        help="trace file (.npz) from 'rolltouch simulate' (fixed rolls or --reactive, either finger), or a run log",
    )
    lct.add_argument("--part", required=True, help="part file (the model the localizer is given; a point file)")
    lct.add_argument(
        SAME_PART_FLAG,
        action="store_true",
        help="score the trace on --part although it was made on another part file (one known to be the same)",
    )
    jaw_argument(lct, default=None)
    off_scale_argument(lct, replay=True)
    lct.add_argument("--rule", choices=RULES, default="likelihood", help="disambiguation rule (default likelihood)")
    lct.add_argument("--json", action="store_true", help="print the result as JSON")
    lct.add_argument("--plot", metavar="FILE.png", help="draw the part, the jaw poses, the true and estimated contacts")


def localize_command(args: argparse.Namespace) -> int:
    check_before_moving(args, {"plot": PLOT_SUFFIXES})
    part = read_part(args)
    rolls = [(args.length, np.radians(args.turn))] + [(L, np.radians(d)) for L, d in args.then]
    result = localize(
        part,
        rolls,
        rule=args.rule,
        direction=args.direction,
        sd_length=args.sd_length,
        sd_turn=float(np.radians(args.sd_turn)),
        length_tol=args.length_tol,
        turn_tol=float(np.radians(args.turn_tol)),
    )

    def xy(arc: float) -> list[float]:
        return [float(v) for v in part.point_at_arc(arc)]

    if args.json:
        doc = {
            "part": part.name,
            "perimeter": part.perimeter,
            "rule": result.rule,
            "direction": result.direction,
            "rolls": [{"length": L, "turn": w, "turn_deg": float(np.degrees(w))} for L, w in result.rolls],
            "segments": [dict(s.as_dict(), start_xy=xy(s.start_arc), end_xy=xy(s.end_arc)) for s in result.segments],
            "candidates": [
                dict(c.as_dict(), start_xy=xy(c.start_arc), end_xy=xy(c.end_arc)) for c in result.candidates
            ],
            "best": 0 if result.best is not None else None,
            "ambiguous": result.ambiguous,
            "consistent": result.consistent,
            "fit_pvalue": result.fit_pvalue,
        }
        json.dump(doc, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        if isinstance(part, Outline):
            made = f"{len(part.pieces)} pieces, {len(part.corners)} corners"
        else:
            made = f"{part.n_knots} knots"
        print(f"part {part.name}: perimeter {part.perimeter:.3f} mm, {made}")
        print(f"roll 1 (L={rolls[0][0]:.4g} mm, turn={args.turn:.4g} deg): {len(result.segments)} feasible segment(s)")
        if not result.candidates:
            print("no place on the part fits these rolls")
        else:
            print(f"{'#':>3} {'start mm':>10} {'contact now mm':>15} {'x':>9} {'y':>9} {'prob':>6}")
            for k, c in enumerate(result.candidates):
                x, y = xy(c.end_arc)
                print(f"{k:>3} {c.start_arc:>10.3f} {c.end_arc:>15.3f} {x:>9.3f} {y:>9.3f} {c.probability:>6.3f}")
            verdict = "AMBIGUOUS" if result.ambiguous else "localized"
            best = result.candidates[0]
            if result.consistent:
                where = f"contact now at arc {best.end_arc:.3f} mm"
                print(f"{verdict}: {where} (p={best.probability:.3f}, rule {result.rule})")
            else:
                print(no_fit_line(result.fit_pvalue))
    if args.plot:
        from driver.records import plot_localization

        plot_localization(part, result, args.plot)
        if not args.json:
            print(f"plot written to {args.plot}")
    return 0 if result.consistent else 2


def locate_command(args: argparse.Namespace) -> int:
    check_before_moving(args, {"plot": PLOT_SUFFIXES})
    record = open_record(args.trace)
    if record.kind == "wheel":
        return locate_wheel(args, record)
    off_scale(args, DEFAULT_JAW)  # refused: a straight jaw's record
    if record.kind == "reactive":
        meta, columns, readings = reactive_calls(record)
        truth = readings["true_arcs"] if readings is not None else np.array([], dtype=float)
        return locate_reactive(args, args.trace, meta, columns, truth)
    check_finger(args.trace, DEFAULT_JAW, args.jaw)
    part = load_part(args.part)
    trace = record.fixed()
    check_same_part(trace.metadata.get("part"), part, args.part, f"trace {args.trace}", same=args.same_part)
    if not trace.metadata["steps"]:
        raise RigError(f"trace {args.trace} holds no roll: nothing to localize from")
    estimates = trace.estimates()
    direction = "ccw" if np.sign(trace.metadata["steps"][0]) > 0 else "cw"
    loc = localize(part, estimates, rule=args.rule, direction=direction)
    return emit_run(args, run_summary(part, trace, loc), part, trace, loc)


def locate_reactive(
    args: argparse.Namespace,
    path: str,
    meta: dict[str, Any],
    columns: dict[str, np.ndarray],
    truth: NDArray[np.float64],
) -> int:
    """'locate TRACE --part PART' of a reactive rolling's trace or run log (straight jaw): its filter calls
    (``columns``, :data:`driver.records.filter_log.LOG_COLUMNS`) made again on a filter of the default settings, as
    the run's was, and the belief printed as the run printed it; ``meta``: the run's JSON object and part
    record; ``truth``: the true contact at each reading (empty on a real rig).

    Where the part seemed to differ from its model is the filter's finding, or else the run's own
    (a jump the jaw left, or one no place explains: what the hand did, which the calls do not hold)."""
    check_finger(path, DEFAULT_JAW, args.jaw)
    if args.plot:
        raise UsageError(
            f"--plot {args.plot}: a reactive trace's plot is drawn by the run itself ('simulate --reactive --plot'); "
            "drop --plot to have its belief again"
        )
    part = load_part(args.part)
    check_same_part(meta.get("part"), part, args.part, f"trace {path}", same=args.same_part)
    b = replay_log(ContactFilter(part), columns)
    doc: dict[str, Any] = {
        "part": part.name,
        "method": "reactive",
        **{k: meta[k] for k in ("stopped", "rotation_deg", "steps", "reversals", "regrasps") if k in meta},
        **belief_fields(b),
        "readings": int(np.count_nonzero(columns["call"] == CALLS.index("update"))),
        "modes": [{"arc": m.arc, "probability": m.mass} for m in b.modes[:5]],
    }
    if doc["mismatch"] is None and isinstance(meta.get("mismatch"), dict):
        doc["mismatch"] = meta["mismatch"]
    if truth.size and math.isfinite(truth[-1]):
        doc["true_arc"] = float(truth[-1])
        doc["error_mm"] = float(abs(part.arc_offset(b.map_arc, truth[-1])))
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        print(f"reactive trace, {doc['readings']} readings replayed")
        print_belief(doc)
    return exit_status(doc)
