"""Replay one study trial's reactive filter with other settings: the same readings, another filter.

A failed trial says little by itself: was it the readings, or the filter's model of them? This
reruns one trial of a study (the same seeds, so the same rig, start and readings), records every
call the rolling procedure made to its :class:`localizer.ContactFilter`, and feeds the same calls
to filters built with other settings. Only the filter differs; the rolling is not redone (a
variant that would have stopped earlier, or rolled elsewhere, is judged on the same readings)::

    python -m bench.replay bench/studies/heldout-a.toml --level 3 --trial 26 \\
        --set sd_slope=0 --set sd_jaw=0.045 --set "temper=1 defect_window=0" [--at 35]

Each variant's line gives the stated probability within the success radius, the error of the
most probable present contact, and how much more likely (natural log, the evidence untempered)
the best start within 2 mm of the true one is than the best start elsewhere: negative means the
filter prefers a wrong place. The study of the ×4 failures in docs/robustness.md was done this way.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, TypeAlias, cast

import numpy as np

from localizer import Belief, Boundary, ContactFilter, Outline, Part

from .study import load_study
from .trial import TrialSpec, run_trial

__all__ = ["FilterRecorder", "Recorded", "record_trial", "replay", "calls_until", "VariantResult", "log_columns"]

#: A start within this of the true one counts as the true start (mm).
NEAR = 2.0

_CALLS = ("update", "touch", "bridged", "regrasp", "belief", "reset")

#: One call made to a filter: its name, arguments and keyword arguments.
Call: TypeAlias = tuple[str, tuple[Any, ...], dict[str, Any]]


class FilterRecorder(ContactFilter):
    """A :class:`localizer.ContactFilter` that keeps the calls made to it (``calls``: name, args,
    keyword args), the outermost only (``regrasp`` calls ``update`` itself). ``belief`` is kept too: asking
    it runs the fit test on its schedule, so a replay must ask when the run asked. Each instance is added
    to ``made`` when built: :func:`record_trial` gives a subclass its own list, so that nothing is
    shared between runs."""

    made: ClassVar[list[FilterRecorder]] = []

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.calls: list[Call] = []
        self._depth = 0
        self.settings = dict(kwargs)
        super().__init__(*args, **kwargs)
        self.made.append(self)

    def reset(self) -> None:
        # kept as a call: a run that left the model behind starts its filter again part-way, and a replay
        # must too
        if hasattr(self, "calls"):
            self._record("reset", (), {})
        else:
            super().reset()

    def _record(self, name: str, args: tuple[Any, ...], kwargs: dict[str, Any]) -> Any:
        if self._depth == 0:
            self.calls.append((name, args, kwargs))
        self._depth += 1
        try:
            return getattr(super(), name)(*args, **kwargs)
        finally:
            self._depth -= 1

    def update(self, *args: Any, **kwargs: Any) -> None:
        self._record("update", args, kwargs)

    def touch(self, *args: Any, **kwargs: Any) -> None:
        self._record("touch", args, kwargs)

    def bridged(self, *args: Any, **kwargs: Any) -> float:
        return cast(float, self._record("bridged", args, kwargs))

    def regrasp(self, *args: Any, **kwargs: Any) -> None:
        self._record("regrasp", args, kwargs)

    def belief(self, *args: Any, **kwargs: Any) -> Belief:
        return cast(Belief, self._record("belief", args, kwargs))


@dataclass(frozen=True)
class Recorded:
    """One trial's reactive filter: the part, the settings it was built with, the calls, the trial's
    row of trials.csv and its start (mm)."""

    part: Boundary
    settings: dict[str, Any]
    calls: tuple[Call, ...]
    row: dict[str, Any]
    start_arc: float


@dataclass(frozen=True)
class VariantResult:
    """What a variant of the filter says after the recorded calls.

    mass : stated probability within the success radius; error_mm : the most probable present
    contact against the true start's present contact on the model (mm; NaN where the run started its
    filter again from another contact, where the trial's start is no longer the filter's); margin :
    log-likelihood of
    the best start within :data:`NEAR` mm of the true one minus the best elsewhere (untempered;
    inf if no other is left); noise_scale : the λ the readings say; mismatch : the readings stopped
    fitting the part (a belief that is then never sure)."""

    settings: dict[str, Any]
    mass: float
    error_mm: float
    margin: float
    noise_scale: float
    mismatch: bool = False


def record_trial(study_path: str | os.PathLike[str], level: int, trial: int) -> Recorded:
    """Rerun trial ``trial`` of level ``level`` of a study, recording its reactive filter's calls."""
    study = load_study(study_path)
    if "reactive" not in study.methods:
        raise ValueError(f"study {study_path}: no reactive method to replay (methods = {list(study.methods)})")
    if not 0 <= level < study.levels:
        raise ValueError(f"level={level!r}: the study has levels 0 to {study.levels - 1}")
    made: list[FilterRecorder] = []

    class Recorder(FilterRecorder):
        pass

    Recorder.made = made  # this run's filters only
    row = run_trial(TrialSpec(study, level, trial, filter_class=Recorder))
    rec = made[-1] if made else None
    if rec is None or row.get("reactive_failure"):
        raise RuntimeError(
            f"trial {trial} of level {level} did not run its reactive method: "
            f"{row.get('reactive_failure') or row.get('failure')}"
        )
    return Recorded(
        part=rec.part, settings=rec.settings, calls=tuple(rec.calls), row=row, start_arc=float(row["start_arc"])
    )


def calls_until(calls: Sequence[Call], at_deg: float | None) -> list[Call]:
    """The calls made before the rolling had turned ``at_deg`` degrees in all (the rotation rolled, both
    ways, as a run's rotation curve counts it: the sum of the turns between readings; every call: None)."""
    if at_deg is None:
        return list(calls)
    out: list[Call] = []
    rolled, last = 0.0, None
    for call in calls:
        name, args, _ = call
        if name == "reset":
            last = None  # the run's turns start again from the contact it then touches
        if name in ("update", "regrasp"):
            turn = float(args[1])
            rolled += abs(turn - last) if last is not None else abs(turn)
            last = turn
            if name == "update" and rolled >= math.radians(at_deg):
                break
        out.append(call)
    return out


def _restarted(calls: Sequence[Call]) -> bool:
    """Whether the filter was reset after it had taken a reading."""
    read = False
    for name, _, _ in calls:
        read = read or name == "update"
        if read and name == "reset":
            return True
    return False


def replay(rec: Recorded, at_deg: float | None = None, *, margin: bool = True, **changes: Any) -> VariantResult:
    """Feed ``rec``'s calls to a filter with its settings, ``changes`` applied; with ``at_deg``, only those
    made before the rolling had turned that many degrees in all (:func:`calls_until`: the belief the
    filter had there). Without
    ``margin`` the true start's margin and the noise scale are not weighed (NaN; a second filter that
    prunes nothing, most of the cost); the error is then from the filter's own nominal contacts."""
    settings = {**rec.settings, **changes}
    flt = ContactFilter(rec.part, **settings)
    # the margin from a filter that prunes nothing (the belief from one as run: what a stretch left out,
    # or a fit test, says depends on which starts are still weighed)
    full = ContactFilter(rec.part, **{**settings, "prune": math.inf}) if margin else flt
    calls = calls_until(rec.calls, at_deg)
    for name, args, kwargs in calls:
        getattr(flt, name)(*args, **kwargs)
        if margin:
            getattr(full, name)(*args, **kwargs)
    belief = flt.belief()
    part = rec.part
    off = np.abs(np.asarray(part.arc_offset(flt.grid, rec.start_arc)))
    i = int(np.flatnonzero(off < NEAR)[np.argmin(off[off < NEAR])])
    error = abs(float(part.arc_offset(belief.map_arc, float(part.wrap_arc(full.current[i])))))
    if _restarted(calls):
        error = math.nan  # the filter started again from another contact: the trial's start is not its start
    mismatched = belief.mismatch is not None or not belief.consistent
    if not margin:
        return VariantResult(dict(changes), belief.mass, error, math.nan, math.nan, mismatched)
    ll = full.log_likelihood() / full.temper
    near, far = ll[off < NEAR], ll[off >= NEAR]
    best_near = float(near.max()) if near.size else -math.inf
    best_far = float(far.max()) if far.size else -math.inf
    true_margin = best_near - best_far if np.isfinite(best_far) else math.inf
    return VariantResult(dict(changes), belief.mass, error, true_margin, full.noise_scale(), mismatched)


def _value(text: str) -> bool | int | float | tuple[float, ...] | str:
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    if text.startswith("(") or text.startswith("["):
        return tuple(float(v) for v in text.strip("()[]").split(",") if v.strip())
    return text


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.replay", description=__doc__.split("\n\n")[0])
    ap.add_argument("study", type=Path)
    ap.add_argument("--level", type=int, required=True, help="level index (0 = the first swept value)")
    ap.add_argument("--trial", type=int, required=True)
    ap.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="ContactFilter settings for one variant, space-separated (repeat for more variants)",
    )
    ap.add_argument("--at", type=float, metavar="DEG", help="the beliefs after this many degrees of rolling")
    ap.add_argument(
        "--show",
        metavar="FILE.png",
        help="also draw how the trial's belief narrowed (as 'rolltouch show' draws a trace)",
    )
    args = ap.parse_args(argv)
    if args.show is not None and not args.show.lower().endswith(".png"):
        ap.error(f"--show {args.show}: the file name must end in .png")
    variants: list[dict[str, Any]] = [{}]
    for group in args.set:
        variant = {}
        for item in group.split():
            name, sep, value = item.partition("=")
            if not sep:
                ap.error(f"--set {item!r}: use NAME=VALUE, e.g. sd_slope=0")
            variant[name] = _value(value)
        variants.append(variant)
    rec = record_trial(args.study, args.level, args.trial)
    r = rec.row
    print(
        f"{r['part']} {r['value']} trial {args.trial}: reactive {r['reactive_stopped']} at mass "
        f"{r['reactive_mass']}, error {float(r['reactive_error_mm']):.3f} mm after "
        f"{float(r['reactive_rotation_deg']):.1f} degrees, {len(rec.calls)} filter calls"
        + ("" if args.at is None else f"; the beliefs after {args.at:g} degrees")
    )
    for changes in variants:
        try:
            v = replay(rec, args.at, **changes)
        except (TypeError, ValueError) as exc:
            print(f"  {changes!s:40s} cannot be built: {exc}", file=sys.stderr)
            continue
        print(
            f"  {str(changes) if changes else 'as run':40s} mass {v.mass:.3f}  error {v.error_mm:8.3f} mm  "
            f"true-start margin {v.margin:+8.2f} nats  noise scale {v.noise_scale:.2f}"
            + ("  MISMATCH" if v.mismatch else "")
        )
    if args.show is not None:
        from driver.records import plot_belief_history, replay_beliefs

        history = replay_beliefs(ContactFilter(rec.part, **rec.settings), log_columns(rec.calls))
        title = f"{Path(str(r['part'])).name}, {r['value']}, trial {args.trial}: the belief while rolling"
        plot_belief_history(cast("Part | Outline", rec.part), history, args.show, title=title)
        print(f"  drawn to {args.show}")
    return 0


def log_columns(calls: Sequence[Call]) -> dict[str, np.ndarray]:
    """Recorded calls as the kept log's columns (:func:`driver.records.log_table`), which
    :func:`driver.records.replay_log` and :func:`driver.records.replay_beliefs` make again."""
    from driver.records import log_table
    from localizer import BRIDGE_JUMP

    kept = []
    for name, args, kwargs in calls:
        given = dict(zip(_SIGNATURES[name], args)) | kwargs
        value = given.get("jump", BRIDGE_JUMP) if name == "bridged" else given.get("radius")
        kept.append((name, given.get("arc"), given.get("turn"), given.get("jaw"), value))
    return log_table(kept)


#: The positional parameters of each recorded call, by name.
_SIGNATURES = {
    "update": ("arc", "turn", "jaw"),
    "regrasp": ("arc", "turn", "jaw"),
    "touch": ("jaw",),
    "bridged": ("turn", "jaw", "jump"),
    "belief": ("radius",),
    "reset": (),
}


if __name__ == "__main__":
    raise SystemExit(main())
