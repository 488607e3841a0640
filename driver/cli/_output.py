"""What the commands print and save: the JSON objects of a run and their text form, and the plots."""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

from localizer import FIT_ALPHA, SUCCESS_RADIUS, Belief, Localization, Outline, Part

from ..rig import GroundTruth, Rig
from ._options import pressing

if TYPE_CHECKING:
    import numpy as np

    from ..jaw import Calibration, ReactiveRun
    from ..records import RunLog, Trace

__all__ = [
    "CONNECTING",
    "RELEASED",
    "ending_progress_line",
    "run_reactive",
    "belief_fields",
    "truth_fields",
    "print_belief",
    "print_reactive",
    "run_summary",
    "emit_run",
    "print_run",
    "no_fit_line",
    "mismatch_line",
    "exit_status",
]


#: What an interrupted rig command had done, before it had the arm and after it let it go (inside,
#: the serial rig's safe stop says what it did).
CONNECTING = "no motion had been sent to the arm (it was being connected)"
RELEASED = "the arm's part of the run had ended: nothing was moving"


@contextlib.contextmanager
def ending_progress_line(log: RunLog | None) -> Iterator[None]:
    """End the progress line on stderr; on any failure log it and close the run log, then re-raise."""
    try:
        yield
        sys.stderr.write("\n")
    except BaseException as exc:
        sys.stderr.write("\n")
        if log is not None:
            notes = "; ".join(getattr(exc, "__notes__", []))
            log({"event": "error", "message": str(exc) or type(exc).__name__, "host": notes})
            log.close()
        raise


def run_reactive(
    args: argparse.Namespace,
    rig: Rig,
    part: Part | Outline,
    calibration: Calibration,
    approach_pose: tuple[float, float, float],
    observer: Callable[[dict[str, Any]], object] | None = None,
) -> tuple[dict[str, Any], ReactiveRun, dict[str, np.ndarray]]:
    """Run the reactive localization on ``rig``: the JSON object of 'simulate|run --reactive', the
    :class:`driver.jaw.ReactiveRun` and its filter's calls (:meth:`driver.records.LoggedFilter.columns`)."""
    from driver.jaw import ReactivePolicy, localize_reactively
    from driver.records import LoggedFilter

    rule = {} if getattr(args, "policy", None) is None else {"seek": args.policy == "seek"}  # else the policy's
    policy = ReactivePolicy(
        step=math.radians(args.step), confidence=args.confidence, max_rotation=math.radians(args.max_rotation), **rule
    )
    res = localize_reactively(
        rig,
        part,
        calibration=calibration,
        filter=(flt := LoggedFilter(part)),
        approach_pose=approach_pose,
        policy=policy,
        pressing=pressing(args),
        observer=observer,
    )
    b = res.belief
    doc = {
        "part": part.name,
        "method": "reactive",
        "policy": "seek" if policy.seek else "spread",
        **belief_fields(b),
        "stopped": res.stopped,
        "rotation_deg": math.degrees(res.rotation),
        "steps": res.steps,
        "reversals": res.reversals,
        "regrasps": res.regrasps,
        "modes": [{"arc": m.arc, "probability": m.mass} for m in b.modes[:5]],
        **truth_fields(part, b, rig),
    }
    return doc, res, flt.columns()


def belief_fields(b: Belief) -> dict[str, Any]:
    """``estimate_arc``, ``mass``, ``ambiguous``, ``informative``, ``consistent`` and ``mismatch`` of a belief,
    for a rolling's JSON object. ``mismatch`` is null, or where on the model the part seems to differ from
    it: ``{"from_arc", "to_arc"}`` (mm, counter-clockwise) and ``size_mm`` (how far the readings there are
    off the model, or the jump the jaw made where the model has none; null if unknown)."""
    mismatch = None
    if b.mismatch is not None:
        size = float(b.mismatch_mm)
        lo, hi = (float(v) for v in b.mismatch)
        mismatch = {
            "from_arc": lo if math.isfinite(lo) else None,
            "to_arc": hi if math.isfinite(hi) else None,
            "size_mm": size if math.isfinite(size) else None,
        }
    return {
        "estimate_arc": b.map_arc,
        "mass": b.mass,
        "ambiguous": b.ambiguous,
        "informative": b.informative,
        "consistent": bool(b.consistent),
        "mismatch": mismatch,
    }


def mismatch_line(doc: dict[str, Any]) -> str | None:
    """The ending's line when the part seems not to be its model (``doc["mismatch"]``), else None."""
    m = doc.get("mismatch")
    if m is None:
        if doc.get("consistent", True):
            return None
        return "MODEL MISMATCH: nothing on the part's model fits the readings; not localized"
    size = "" if m.get("size_mm") is None else f", readings {m['size_mm']:.2f} mm off the model there"
    where = (
        f"near arc {m['from_arc']:.1f}–{m['to_arc']:.1f} mm"
        if m["from_arc"] is not None
        else "(where on the model could not be told: nothing fitted long enough)"
    )
    return (
        f"MODEL MISMATCH {where}{size}: the part differs from its model "
        "(a burr, a dent, debris, or another revision); the estimate is not to be trusted as sure"
    )


def exit_status(doc: dict[str, Any]) -> int:
    """2 when a rolling found the part not to be its model (:func:`mismatch_line`), else 0."""
    return 2 if mismatch_line(doc) is not None else 0


def truth_fields(part: Part | Outline, b: Belief, rig: Rig) -> dict[str, Any]:
    """``true_arc`` and ``error_mm`` (mm) of a belief on a rig that knows the truth (nothing on a real rig)."""
    if not isinstance(rig, GroundTruth):
        return {}
    true_arc = rig.truth()["contact_arc"]
    error = float(abs(part.arc_offset(b.map_arc, true_arc))) if math.isfinite(true_arc) else None
    return {"true_arc": true_arc, "error_mm": error}


def print_reactive(doc: dict[str, Any]) -> None:
    print(
        f"rolled {doc['rotation_deg']:.1f}° in {doc['steps']} steps ({doc['stopped']}, "
        f"{doc['reversals']} reversals, {doc['regrasps']} regrasps)"
    )
    print_belief(doc)


def print_belief(doc: dict[str, Any]) -> None:
    """The verdict, the other modes and the truth of a rolling's JSON object (either finger); a model
    mismatch last, as the ending."""
    verdict = "AMBIGUOUS" if doc["ambiguous"] else ("no information" if not doc["informative"] else "localized")
    print(f"{verdict}: contact now at arc {doc['estimate_arc']:.3f} mm, {doc['mass']:.1%} within {SUCCESS_RADIUS} mm")
    for m in doc["modes"][1:3]:
        print(f"  another mode: arc {m['arc']:.3f} mm, probability {m['probability']:.3f}")
    if doc.get("error_mm") is not None:
        err = doc["error_mm"]
        print(
            f"truth: {doc['true_arc']:.3f} mm, error {err:.3f} mm "
            f"({'success' if err < SUCCESS_RADIUS else 'failure'} at {SUCCESS_RADIUS} mm)"
        )
    line = mismatch_line(doc)
    if line is not None:
        print(line)


def run_summary(part: Part | Outline, trace: Trace, loc: Localization) -> dict[str, Any]:
    """The JSON object of 'simulate' and 'locate'."""
    best = loc.best
    estimate = best.end_arc if best is not None else None
    doc = {
        "part": part.name,
        "estimates": [{"length": L, "turn": w, "turn_deg": math.degrees(w)} for L, w in loc.rolls],
        "estimate_arc": estimate,
        "ambiguous": loc.ambiguous,
        "consistent": loc.consistent,
        "fit_pvalue": loc.fit_pvalue,
        "candidates": [c.as_dict() for c in loc.candidates],
    }
    true_arc = trace.true_arc
    if math.isfinite(true_arc):
        doc["true_arc"] = true_arc
        doc["error_mm"] = None if estimate is None else abs(float(part.arc_offset(estimate, true_arc)))
    return doc


def emit_run(
    args: argparse.Namespace, doc: dict[str, Any], part: Part | Outline, trace: Trace, loc: Localization
) -> int:
    """Print a run's result (JSON or text) and draw it if asked: simulate, locate and run alike. Returns
    the exit status: 2 when the readings fit no place on the part (:func:`no_fit_line`), else 0."""
    if args.json:
        json.dump(doc, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print_run(doc)
        if "trace" in doc:
            print(f"trace written to {doc['trace']}")
    if args.plot:
        from driver.records import plot_run

        plot_run(part, trace, loc, args.plot)
        if not args.json:
            print(f"plot written to {args.plot}")
    return 0 if loc.consistent else 2


def no_fit_line(pvalue: float) -> str:
    """What the CLI says when the readings fit no place on the part."""
    return (
        f"NO CONSISTENT CONTACT: the readings fit no place on the part (goodness of fit p = {pvalue:.3g}, "
        f"below {FIT_ALPHA:g}); check the arm's rotation readings and the contact sensor's calibration. "
        "No candidate is an answer"
    )


def print_run(doc: dict[str, Any]) -> None:
    for k, e in enumerate(doc["estimates"]):
        print(f"roll {k + 1}: L = {e['length']:.3f} mm, Ω = {e['turn_deg']:.3f}°")
    if doc["estimate_arc"] is None:
        print("no place on the part fits these rolls")
    elif not doc["consistent"]:
        print(no_fit_line(doc["fit_pvalue"]))
    else:
        verdict = "AMBIGUOUS" if doc["ambiguous"] else "localized"
        print(
            f"{verdict}: contact now at arc {doc['estimate_arc']:.3f} mm (p={doc['candidates'][0]['probability']:.3f})"
        )
    if "true_arc" in doc:
        err = doc["error_mm"]
        print(
            f"truth: {doc['true_arc']:.3f} mm, error {err:.3f} mm "
            f"({'success' if err is not None and err < SUCCESS_RADIUS else 'failure'} at {SUCCESS_RADIUS} mm)"
        )
