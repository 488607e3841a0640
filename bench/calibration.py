"""How well a method's stated probability means what it says, over the studies it was run in.

``python -m bench.calibration DIR [DIR ...] [--method reactive] [--json FILE]`` reads each study folder's
trials.csv and prints, per study and level and then pooled over the studies level by level, the
method's calibration (:func:`bench.summary.calibration`: the trial-weighted gap between the stated
probability within the success radius and how often it was so, and the worst bin of at least
:data:`bench.summary.FULL_BIN` trials), with how often it stopped sure and sure and wrong; and its
calibration along the rolling: the stated probability at every 5° mark of every trial against whether
the estimate was within the radius there, up to the first mark at or past where the rolling stopped
(``<method>_mass_curve`` and ``<method>_curve``; studies run before those columns have none).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

from .montecarlo import read_trials
from .scoring import MARK_DEG, parse_curve
from .summary import binned, calibration, calibration_of, cell_number, json_safe

__all__ = ["calibration_table", "main"]


def calibration_table(folders: Sequence[str | Path], method: str = "reactive") -> list[dict[str, Any]]:
    """One record per (study folder, level) and one per level pooled over the folders (``study`` "pooled"),
    then one over everything (``level`` "all"): trials, sure, sure and wrong, and the calibration.

    Raises
    ------
    FileNotFoundError
        A folder without a trials.csv.
    KeyError
        A study that did not run ``method``.
    """
    by_level: dict[str, list[Trial]] = {}
    out = []
    everything: list[Trial] = []
    for folder in folders:
        table = Path(folder) / "trials.csv"
        if not table.exists():
            raise FileNotFoundError(f"{folder}: no trials.csv (is it a study's --out folder?)")
        rows = read_trials(table)
        if rows and f"{method}_mass" not in rows[0]:
            raise KeyError(f"{folder}: the study did not run the method {method!r}")
        record = Path(folder) / "study.json"
        radius = float(json.loads(record.read_text())["success_radius"]) if record.exists() else math.nan
        levels: dict[str, list[Trial]] = {}
        for r in rows:
            levels.setdefault(str(r.get("value", "")), []).append(Trial(r, radius))
        for level, sel in levels.items():
            out.append(_record(Path(folder).name, level, method, sel))
            by_level.setdefault(level, []).extend(sel)
            everything.extend(sel)
    if len(folders) > 1:
        out += [_record("pooled", level, method, sel) for level, sel in by_level.items()]
    out.append(_record("pooled" if len(folders) > 1 else Path(folders[0]).name, "all", method, everything))
    return out


class Trial(NamedTuple):
    """A row of a study's trials.csv and its study's success radius, mm (NaN: its study.json is missing)."""

    row: dict[str, Any]
    radius: float


def _record(study: str, level: str, method: str, trials: Sequence[Trial]) -> dict[str, Any]:
    rows = [t.row for t in trials]
    sure = [r for r in rows if r.get(f"{method}_stopped") == "confident"]
    stated, right = [], []
    for r, radius in trials:
        errors = dict(parse_curve(r.get(f"{method}_curve", "")))
        rotation = cell_number(r.get(f"{method}_rotation_deg", ""))
        for mark, p in parse_curve(r.get(f"{method}_mass_curve", "")):
            if mark >= rotation + MARK_DEG:
                break  # the rolling had stopped: the curve repeats its last statement
            if mark in errors and math.isfinite(radius):
                stated.append(p)
                right.append(float(errors[mark] < radius))
    return {
        "study": study,
        "level": level,
        "trials": len(rows),
        "sure": len(sure),
        "sure_wrong": sum(1 - int(r[f"{method}_success"]) for r in sure),
        "calibration": calibration(method, rows),
        "along": calibration_of(binned(stated, right)),
    }


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.calibration", description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+", metavar="DIR", help="a study's --out folder (with trials.csv)")
    parser.add_argument("--method", default="reactive", help="the method whose stated probability (default reactive)")
    parser.add_argument("--json", metavar="FILE", help="also write the records as JSON")
    args = parser.parse_args(argv)
    try:
        records = calibration_table(args.folders, args.method)
    except (FileNotFoundError, KeyError) as exc:
        print(f"error: {exc.args[0]}", file=sys.stderr)
        return 2
    head = ("study", "level", "trials", "sure", "wrong", "cal. error", "worst bin", "along", "marks")
    print("{:28s} {:>12s} {:>6s} {:>5s} {:>5s} {:>10s} {:>9s} {:>6s} {:>6s}".format(*head))
    for r in records:
        cal = r["calibration"]
        err = "-" if cal is None else f"{cal['error']:.3f}"
        worst = "-" if cal is None or cal["worst_gap"] is None else f"{cal['worst_gap']:.3f}"
        along = "-" if r["along"] is None else f"{r['along']['error']:.3f}"
        marks = "-" if r["along"] is None else str(r["along"]["trials"])
        print(
            f"{r['study'][:28]:28s} {(r['level'] or '-')[:12]:>12s} {r['trials']:6d} {r['sure']:5d} "
            f"{r['sure_wrong']:5d} {err:>10s} {worst:>9s} {along:>6s} {marks:>6s}"
        )
    if args.json:
        Path(args.json).write_text(json.dumps(json_safe(records), indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
