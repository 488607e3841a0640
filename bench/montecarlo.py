"""The Monte Carlo runner: trials in parallel, appended to ``trials.csv`` as they finish, resumable.

Local processes by default; with a scheduler address the same trials run on
a Dask distributed cluster through its ``concurrent.futures`` executor.
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import os
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

from driver.lockfile import LockHeld, hold_lock
from localizer import fingerprint, load_part

from .study import TRIAL_COLUMNS, Study, StudyError, TrialSpec, run_trial

__all__ = ["run_study", "read_trials", "summarize", "wilson"]


#: How long a Dask scheduler has to answer, s.
SCHEDULER_TIMEOUT = 10.0


def wilson(successes: int, n: int, z: float = 1.96):
    """Wilson 95% interval of a success rate, (low, high).

    Examples
    --------
    >>> [round(v, 3) for v in wilson(45, 100)]
    [0.356, 0.548]
    >>> wilson(100, 100)[1]
    1.0
    """
    if n == 0:
        return (math.nan, math.nan)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    # in exact arithmetic the interval holds p; rounding at p = 1 (or 0) must not put it outside
    return (max(0.0, min(p, centre - half)), min(1.0, max(p, centre + half)))


def read_trials(path, *, warn: bool = False) -> list:
    """Rows of a trials.csv, one per (level, trial): a truncated last line (a killed run) is dropped, a
    repeated trial keeps its first row, and a row whose level, trial or success is not a whole number
    (a damaged file) is dropped, so that it runs again on ``--resume``; ``warn`` says so on stderr."""
    path = Path(path)
    if not path.exists():
        return []
    with open(path, newline="") as f:
        text = f.read()
    lines = text.split("\n")
    complete = text.endswith("\n")
    if not complete:
        lines = lines[:-1]
    rows = []
    seen: set[tuple[int, int]] = set()
    damaged, repeated = [], 0
    reader = csv.DictReader(lines)
    width = len(reader.fieldnames or ())
    for r in reader:
        if r is None or None in r.values() or len(r) != width or width < len(TRIAL_COLUMNS):
            continue
        try:
            key = (int(r["level"]), int(r["trial"]))
            if int(r["success"]) not in (0, 1):
                raise ValueError
        except (KeyError, TypeError, ValueError):
            damaged.append(reader.line_num)
            continue
        if key in seen:
            repeated += 1
            continue
        seen.add(key)
        rows.append(r)
    if warn and (damaged or repeated):
        sys.stderr.write(
            f"{path}: dropped {len(damaged)} damaged row(s)"
            + (f" (lines {', '.join(map(str, damaged[:10]))})" if damaged else "")
            + f" and {repeated} repeated trial(s); the damaged ones run again\n"
        )
    return rows


def _fmt(v):
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else str(v)


def run_study(
    study: Study,
    out,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
) -> dict:
    """Run every (level, trial) of ``study`` not yet in ``out/trials.csv``; write the summary and plots.

    Parameters
    ----------
    workers : int, optional
        Local worker processes (default: all cores); 1 runs in this process.
    scheduler : str, optional
        Address of a Dask distributed scheduler; trials then run on that cluster.
    resume : bool
        Keep the finished trials of ``out/trials.csv`` and run only the missing ones.
        Without it an existing table is replaced.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with _folder_lock(out):
        return _run_locked(study, out, workers=workers, scheduler=scheduler, resume=resume, progress=progress)


def _run_locked(study: Study, out: Path, *, workers, scheduler, resume: bool, progress: bool) -> dict:
    table = out / "trials.csv"
    if resume and table.exists():
        _check_same_study(study, out)
    (out / "study.json").write_text(json.dumps(_study_record(study), indent=2) + "\n")
    done = set()
    if resume and table.exists():
        rows = read_trials(table, warn=True)
        done = {(int(r["level"]), int(r["trial"])) for r in rows}
        # rewrite without a truncated tail so that appending continues a clean file
        with open(table, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=study.columns)
            w.writeheader()
            for r in rows:
                w.writerow(r)
    else:
        with open(table, "w", newline="") as f:
            csv.DictWriter(f, fieldnames=study.columns).writeheader()
    specs = [
        TrialSpec(study, level, trial)
        for level in range(study.levels)
        for trial in range(study.trials)
        if (level, trial) not in done
    ]
    total = study.levels * study.trials
    finished = len(done)
    successes = sum(int(r["success"]) for r in read_trials(table)) if done else 0
    t0 = time.monotonic()

    def record(row, f, writer):
        nonlocal finished, successes
        writer.writerow({k: _fmt(row.get(k)) for k in study.columns})
        f.flush()
        finished += 1
        successes += int(row["success"])
        if progress:
            rate = (finished - len(done)) / max(time.monotonic() - t0, 1e-9)
            bar = "#" * int(30 * finished / total)
            sys.stderr.write(
                f"\r[{bar:<30}] {finished}/{total} trials  {rate:.2f}/s  success {successes / max(finished, 1):.1%} "
            )
            sys.stderr.flush()

    with open(table, "a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=study.columns)
        if not specs:
            pass
        elif scheduler:
            try:
                from distributed import Client
            except ImportError:
                raise StudyError("--scheduler needs dask.distributed: pip install 'rolltouch[dask]'") from None
            try:
                client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)
            except OSError as exc:
                raise StudyError(
                    f"--scheduler {scheduler}: no Dask scheduler answered within {SCHEDULER_TIMEOUT:g} s ({exc}); "
                    "is it running, and is the address tcp://HOST:PORT?"
                ) from None
            with client:
                executor = client.get_executor(pure=False)
                futures = [executor.submit(run_trial, s) for s in specs]
                for fut in as_completed(futures):
                    record(fut.result(), f, writer)
        elif (workers or os.cpu_count() or 1) == 1:
            for s in specs:
                record(run_trial(s), f, writer)
        else:
            pool = ProcessPoolExecutor(
                max_workers=workers or os.cpu_count(), initializer=_die_with_parent, initargs=(os.getpid(),)
            )
            try:
                futures = [pool.submit(run_trial, s) for s in specs]
                for fut in as_completed(futures):
                    record(fut.result(), f, writer)
            except BaseException:
                # Ctrl-C (or a failure): the queued trials are dropped, not waited for; the finished
                # ones are in the table already and stay there, summarized below
                pool.shutdown(wait=False, cancel_futures=True)
                if progress:
                    sys.stderr.write("\n")
                _write_summary(study, table, out, t0)
                raise
            pool.shutdown()
    if progress:
        sys.stderr.write("\n")
    return _write_summary(study, table, out, t0)


def _write_summary(study: Study, table: Path, out: Path, t0: float) -> dict:
    """summary.json and the plots from the finished rows of ``table``."""
    summary = summarize(study, read_trials(table))
    summary["wall_s"] = time.monotonic() - t0
    (out / "summary.json").write_text(json.dumps(json_safe(summary), indent=2, allow_nan=False) + "\n")
    plot_study(study, read_trials(table), out)
    return summary


def _study_record(study: Study) -> dict:
    """study.json: the study's settings, and the fingerprint (:func:`localizer.fingerprint`) of each of its
    part files and world part files, by path: a part file edited between runs is another study."""
    files = list(study.parts) + list(study.world.world_parts if study.world is not None else ())
    # read afresh, not from the worker's cache: the file as it is now is the question
    return {**study.as_dict(), "fingerprints": {f: fingerprint(load_part(f)) for f in dict.fromkeys(files)}}


def _check_same_study(study: Study, out: Path) -> None:
    """Refuse to resume a table that another study wrote (its study.json differs, or is missing), or that
    was written on part files since edited (their fingerprints differ)."""
    saved = out / "study.json"
    try:
        before = json.loads(saved.read_text())
    except (OSError, ValueError):
        raise StudyError(
            f"--resume: {out / 'trials.csv'} has no readable study.json beside it, so whose trials it holds "
            "cannot be told; use another --out or drop --resume"
        ) from None
    now = json.loads(json.dumps(_study_record(study)))
    marks = before.get("fingerprints")
    if isinstance(marks, dict):
        edited = [f for f, mark in now["fingerprints"].items() if f in marks and marks[f] != mark]
        if edited:
            raise StudyError(
                f"--resume: {out / 'trials.csv'} was written on {edited[0]} as it was before (fingerprint "
                f"{marks[edited[0]]}, now {now['fingerprints'][edited[0]]}): the part file has changed since, "
                f"so its trials and new ones would mix two geometries; use another --out, or drop --resume to "
                "start afresh"
            )
    else:  # written before study.json held fingerprints: the settings alone can be compared
        now.pop("fingerprints")
    # where the study file lies is not what it asks for (a copied study is the same study)
    differ = sorted(k for k in set(before) | set(now) if k != "source" and before.get(k) != now.get(k))
    if differ:
        shown = ", ".join(f"{k}: {before.get(k)!r} → {now.get(k)!r}" for k in differ[:4])
        raise StudyError(
            f"--resume: {out / 'trials.csv'} belongs to another study ({shown}); use another --out, or drop "
            "--resume to start this one afresh"
        )


@contextlib.contextmanager
def _folder_lock(out: Path):
    """Hold ``out/.lock`` for the run: two runs writing one folder would interleave their rows."""
    try:
        handle = hold_lock(out / ".lock", f"rolltouch montecarlo pid {os.getpid()}")
    except LockHeld as held:
        raise StudyError(f"{out} is being written by {held.holder}: wait for it, or use another --out") from None
    with handle:
        yield


def _die_with_parent(parent: int) -> None:
    """A worker's initializer: exit when the parent that started it is gone (SIGKILL leaves workers
    otherwise running for ever)."""

    def watch() -> None:
        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, daemon=True, name="die-with-parent").start()


def json_safe(value):
    """``value`` with every non-finite float as None: JSON has no NaN or Infinity."""
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def _number(text) -> float:
    """A trials.csv cell as a float (empty: nan)."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def summarize(study: Study, rows) -> dict:
    """Success rate per level with its 95% interval, error quantiles, failures."""
    levels = []
    for level in range(study.levels):
        sel = [r for r in rows if int(r["level"]) == level]
        n = len(sel)
        ok = sum(int(r["success"]) for r in sel)
        err = np.array([float(r["error_mm"]) for r in sel]) if sel else np.array([])
        levels.append(
            {
                "level": level,
                "parameter": study.parameter,
                "value": study.level_label(level),
                "trials": n,
                "success": ok,
                "success_rate": ok / n if n else None,
                "ci95": list(wilson(ok, n)),
                "error_median_mm": float(np.median(err)) if n else None,
                "error_p90_mm": float(np.quantile(err, 0.9)) if n else None,
                "ambiguous": sum(int(r["ambiguous"]) for r in sel),
                "broken": sum(bool(r["failure"]) for r in sel),
                "mean_time_s": float(np.mean([float(r["time_s"]) for r in sel])) if n else None,
                "mean_restarts": float(np.mean([float(r["restarts"]) for r in sel])) if n else None,
            }
        )
        if study.methods:
            levels[-1]["methods"] = {m: method_detail(study, m, sel) for m in study.methods}
        if study.fingers and n:
            arcs = np.array([_number(r.get("arc_mm", "")) for r in sel], dtype=float)
            levels[-1].update(
                {
                    "jaw": study.level_jaw(level),
                    "reachable": float(np.mean([float(r["reachable"]) for r in sel])),
                    "mean_redraws": float(np.mean([float(r["redraws"]) for r in sel])),
                    "mean_arc_mm": float(np.nanmean(arcs)) if np.isfinite(arcs).any() else None,
                }
            )
    out = {
        "study": study.name,
        "method": study.method,
        "engine": study.engine,
        "noise": study.noise,
        "success_radius": study.success_radius,
        "levels": levels,
    }
    if study.methods:
        out.update(summarize_methods(study, rows))
    return out


def method_detail(study: Study, m: str, rows) -> dict:
    """One method's record over ``rows``: success, how it stopped, confident and wrong, per part."""
    n = len(rows)
    ok = sum(int(r[f"{m}_success"]) for r in rows)
    rot = np.array([_number(r[f"{m}_rotation_deg"]) for r in rows], dtype=float)
    err = np.array([_number(r[f"{m}_error_mm"]) for r in rows], dtype=float)
    stopped = [r.get(f"{m}_stopped", "") for r in rows]
    confident = [r for r, st in zip(rows, stopped) if st == "confident"]
    per_part: dict = {}
    for r in rows:
        d = per_part.setdefault(r["part"], {"success": 0, "trials": 0})
        d["trials"] += 1
        d["success"] += int(r[f"{m}_success"])
    wrong = sum(1 - int(r[f"{m}_success"]) for r in confident)
    ratio = error_over_bound(m, rows)
    return {
        "success": ok,
        "trials": n,
        "ci95": list(wilson(ok, n)),
        "mean_rotation_deg": float(np.nanmean(rot)) if n and np.isfinite(rot).any() else None,
        "median_rotation_deg": float(np.nanmedian(rot)) if n and np.isfinite(rot).any() else None,
        "error_median_mm": float(np.median(err)) if n else None,
        "confident": len(confident),
        "confident_wrong": wrong,
        "mismatch": stopped.count("mismatch"),
        "confident_wrong_ci95": list(wilson(wrong, len(confident))),
        "stopped": {k: stopped.count(k) for k in sorted(set(stopped)) if k},
        "failures": sum(bool(r.get(f"{m}_failure", "")) for r in rows),
        "per_part": dict(sorted(per_part.items())),
        "error_over_bound_rms": float(np.sqrt(np.mean(ratio**2))) if ratio.size else None,
        "error_over_bound_median": float(np.median(ratio)) if ratio.size else None,
        "bounded_successes": int(ratio.size),
    }


def error_over_bound(m: str, rows) -> np.ndarray:
    """Error / Cramér–Rao bound of method ``m`` over its successful trials that have a finite bound."""
    out = []
    for r in rows:
        bound = _number(r.get(f"{m}_bound_mm", ""))
        if int(r[f"{m}_success"]) and math.isfinite(bound) and bound > 0:
            out.append(_number(r[f"{m}_error_mm"]) / bound)
    return np.array(out, dtype=float)


def summarize_methods(study: Study, rows) -> dict:
    """``methods`` {name: success rate} over all trials, with details and success against rotation."""
    from .methods import MARK_DEG, parse_curve

    rates, details, curves = {}, {}, {}
    n = len(rows)
    for m in study.methods:
        details[m] = method_detail(study, m, rows)
        rates[m] = details[m]["success"] / n if n else None
        per_mark: dict = {}
        for r in rows:
            pairs = parse_curve(r[f"{m}_curve"])
            last = pairs[-1][1] if pairs else math.inf
            marks = {round(k, 6): e for k, e in pairs}
            # a method that rolled no further than its last mark keeps its last answer
            top = max(marks) if marks else 0.0
            k = MARK_DEG
            while k <= max(study.reactive.max_rotation_deg, sum(abs(a) for a in study.rolls_deg)) + 1e-9:
                e = marks.get(round(k, 6), last if k > top else math.inf)
                per_mark.setdefault(k, []).append(e < study.success_radius)
                k += MARK_DEG
        curves[m] = {f"{k:g}": float(np.mean(v)) for k, v in sorted(per_mark.items())}
    return {"methods": rates, "method_details": details, "success_by_rotation_deg": curves}


#: Bins of stated confidence in the reliability diagram (fine near 1, where the stops are).
RELIABILITY_BINS = (0.0, 0.5, 0.8, 0.9, 0.95, 0.97, 0.99, 0.999, 1.0 + 1e-12)


def reliability(study: Study, m: str, rows) -> list:
    """(mean stated mass, fraction within the success radius, trials) per bin of stated mass."""
    mass = np.array([_number(r.get(f"{m}_mass", "")) for r in rows])
    hit = np.array([int(r[f"{m}_success"]) for r in rows])
    out = []
    for lo, hi in zip(RELIABILITY_BINS[:-1], RELIABILITY_BINS[1:]):
        sel = np.isfinite(mass) & (mass >= lo) & (mass < hi)
        if sel.any():
            out.append((float(mass[sel].mean()), float(hit[sel].mean()), int(sel.sum())))
    return out


def plot_study(study: Study, rows, out: Path) -> None:
    """success.png (rate against the swept value), errors.png, failures.png (where on the parts)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from localizer import Outline, load_part

    full = summarize(study, rows)
    summ = full["levels"]
    if study.methods and rows:
        _plot_methods(study, full, out)
        _plot_reliability(study, rows, out)
        _plot_bound(study, rows, out)
    if study.parameter == "jaw" and rows:
        _plot_fingers(study, rows, summ, out)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    x = [lv["value"] if isinstance(lv["value"], (int, float)) else k for k, lv in enumerate(summ)]
    if not all(isinstance(lv["value"], (int, float)) for lv in summ):
        ax.set_xticks(range(len(summ)), [str(lv["value"]) for lv in summ], fontsize=8)
    rate = np.array([lv["success_rate"] if lv["success_rate"] is not None else np.nan for lv in summ])
    lo = np.array([lv["ci95"][0] for lv in summ])
    hi = np.array([lv["ci95"][1] for lv in summ])
    ax.errorbar(x, rate, yerr=[rate - lo, hi - rate], fmt="o-", capsize=4, label=f"{study.name} ({study.method} rule)")
    ax.axhline(0.45, color="tab:red", lw=1, ls="--", label="the paper's rig: about 45%")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel(study.parameter or "level")
    ax.set_ylabel(f"success rate (error < {study.success_radius} mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "success.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    bins = np.logspace(-4, 3, 36).tolist()
    for lv in range(study.levels):
        e = np.array([float(r["error_mm"]) for r in rows if int(r["level"]) == lv])
        e = np.clip(e[np.isfinite(e)], 1e-4, 1e3)
        if e.size:
            label = f"{study.parameter}={study.level_label(lv)}" if study.parameter else "all trials"
            ax.hist(e, bins=bins, histtype="step", lw=1.5, label=label)
    ax.axvline(study.success_radius, color="tab:red", lw=1, ls="--", label=f"{study.success_radius} mm")
    ax.set_xscale("log")
    ax.set_xlabel("arc error of the final contact (mm)")
    ax.set_ylabel("trials")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "errors.png", dpi=110)
    plt.close(fig)

    names = sorted({r["part"] for r in rows})
    if names:
        fig, axes = plt.subplots(1, len(names), figsize=(4.3 * len(names), 4.4), squeeze=False)
        by_name = {Path(p).name: p for p in study.parts}
        for ax, name in zip(axes[0], names):
            part = load_part(by_name[name])
            # an outline from CAD every 0.5 mm with its corners, a spline 16 points per piece
            xy = part.sample(0.5) if isinstance(part, Outline) else part.sample(16)
            ax.plot(xy[:, 0], xy[:, 1], color="0.6", lw=1)
            sel = [r for r in rows if r["part"] == name and r["true_arc"] not in ("", "nan")]
            for ok, colour, label in ((1, "tab:green", "success"), (0, "tab:red", "failure")):
                arcs = np.array([float(r["true_arc"]) for r in sel if int(r["success"]) == ok])
                arcs = arcs[np.isfinite(arcs)]
                if arcs.size:
                    p = part.point_at_arc(arcs)
                    ax.plot(p[:, 0], p[:, 1], "o", ms=3, color=colour, alpha=0.6, label=f"{label} ({arcs.size})")
            ax.set_title(f"{name}: final true contacts", fontsize=9)
            ax.set_aspect("equal")
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7)
            else:  # no trial's fixed rolls ran on this part (e.g. every world's part made them bridge)
                ax.text(0.5, 0.5, "no fixed-roll trial", transform=ax.transAxes, ha="center", fontsize=8)
        fig.tight_layout()
        fig.savefig(out / "failures.png", dpi=110)
        plt.close(fig)


def _plot_fingers(study: Study, rows, levels: list, out: Path) -> None:
    """fingers.png for a sweep over fingers: success against the rotation used, per finger (left), and
    where each can start and how far it rolled (right)."""
    import matplotlib.pyplot as plt

    from .methods import MARK_DEG, parse_curve

    m = study.methods[0]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1.6, 1]})
    for lv in levels:
        sel = [r for r in rows if int(r["level"]) == lv["level"]]
        marks = np.arange(MARK_DEG, study.reactive.max_rotation_deg + 1e-9, MARK_DEG)
        hit = np.zeros(marks.size)
        for r in sel:
            pairs = dict((round(k, 6), e) for k, e in parse_curve(r[f"{m}_curve"]))
            hit += [pairs.get(round(k, 6), math.inf) < study.success_radius for k in marks]
        d = lv["methods"][m]
        ax.plot(
            marks,
            hit / max(len(sel), 1),
            "o-",
            ms=2.5,
            label=f"{lv['value']}: {d['success']}/{d['trials']}, median {d['median_rotation_deg']:.0f}°",
        )
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("rotation used (degrees; a wheel: the hand's turning)")
    ax.set_ylabel(f"success rate (error < {study.success_radius} mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    names = [str(lv["value"]) for lv in levels]
    reach = [lv.get("reachable", math.nan) for lv in levels]
    bx.bar(names, reach, color="tab:blue", alpha=0.7, label="boundary a start can be drawn from")
    for k, lv in enumerate(levels):
        bx.text(k, reach[k] + 0.02, f"{lv.get('mean_redraws', 0):.1f} redraws", ha="center", fontsize=7)
    bx.set_ylim(0, 1.15)
    bx.set_ylabel("fraction of the boundary")
    bx.legend(fontsize=7, loc="lower right")
    bx.grid(alpha=0.3, axis="y")
    bx.tick_params(axis="x", labelsize=8)
    fig.suptitle(f"{study.name}: fingers on the same trial seeds, noise {Path(str(study.noise)).stem}", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "fingers.png", dpi=110)
    plt.close(fig)


def _plot_bound(study: Study, rows, out: Path) -> None:
    """bound.png: each method's final error against the Cramér–Rao bound of its readings, trial by trial
    (successes filled, failures hollow), with the bound itself and 1.3 times it."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 5.0))
    lo, hi = math.inf, 0.0
    for k, m in enumerate(study.methods):
        bound = np.array([_number(r.get(f"{m}_bound_mm", "")) for r in rows])
        err = np.array([_number(r[f"{m}_error_mm"]) for r in rows])
        ok = np.array([int(r[f"{m}_success"]) for r in rows], dtype=bool)
        keep = np.isfinite(bound) & (bound > 0) & np.isfinite(err)
        if not keep.any():
            continue
        err = np.maximum(err, 1e-5)
        ratio = error_over_bound(m, rows)
        rms = f", rms error/bound {np.sqrt(np.mean(ratio**2)):.2f} over {ratio.size} successes" if ratio.size else ""
        colour = f"C{k}"
        ax.loglog(bound[keep & ok], err[keep & ok], "o", ms=3, color=colour, alpha=0.6, label=f"{m}{rms}")
        ax.loglog(bound[keep & ~ok], err[keep & ~ok], "o", ms=3, mfc="none", color=colour, alpha=0.6)
        lo, hi = min(lo, bound[keep].min()), max(hi, bound[keep].max())
    if hi > 0:
        line = np.array([lo / 2, hi * 2])
        ax.loglog(line, line, "k-", lw=1, label="error = bound")
        ax.loglog(line, 1.3 * line, "k--", lw=1, label="1.3 × bound")
        ax.axhline(
            study.success_radius, color="tab:red", lw=1, ls=":", label=f"success radius {study.success_radius} mm"
        )
    ax.set_xlabel("Cramér–Rao bound of the final place from the readings taken (mm)")
    ax.set_ylabel("final error (mm)")
    ax.set_title(f"{study.name}: error against its bound (hollow: failures)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    if hi > 0:
        ax.legend(fontsize=7)
    else:  # no method stated a bound for any trial (every trial broke, or none had readings to bound)
        ax.text(0.5, 0.5, "no trial with a bound", transform=ax.transAxes, ha="center", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "bound.png", dpi=110)
    plt.close(fig)


def _plot_methods(study: Study, summary: dict, out: Path) -> None:
    """methods.png: success rate against rotation rolled for each method."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.4))
    for m in study.methods:
        curve = summary["success_by_rotation_deg"][m]
        x = [float(k) for k in curve]
        d = summary["method_details"][m]
        label = f"{m}: {summary['methods'][m]:.1%} at the end, mean rotation {d['mean_rotation_deg']:.0f}°"
        ax.plot(x, list(curve.values()), "o-", ms=3, label=label)
    ax.axhline(0.45, color="tab:red", lw=1, ls="--", label="the paper's rig: about 45%")
    ax.axvline(
        sum(abs(a) for a in study.rolls_deg),
        color="0.5",
        lw=1,
        ls=":",
        label=f"the fixed rolls: {sum(abs(a) for a in study.rolls_deg):g}°",
    )
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("rotation rolled (degrees)")
    ax.set_ylabel(f"success rate (error < {study.success_radius} mm)")
    ax.set_title(f"{study.name}: {len(study.methods)} methods on the same trials", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(out / "methods.png", dpi=110)
    plt.close(fig)


def _plot_reliability(study: Study, rows, out: Path) -> None:
    """reliability.png: stated confidence at the stop against the fraction within the radius, per level.

    For each method that states one: the whole range, and the range from 0.9 up, where a promise
    of 95% is about the few that miss. Bars: each bin's 95% Wilson interval."""
    import matplotlib.pyplot as plt

    stating = [m for m in study.methods if any(np.isfinite(_number(r.get(f"{m}_mass", ""))) for r in rows)]
    if not stating:
        return
    fig, axes = plt.subplots(len(stating), 2, figsize=(10, 4.2 * len(stating)), squeeze=False)
    for row_axes, m in zip(axes, stating):
        if not any(r.get(f"{m}_stopped") == "confident" for r in rows):
            row_axes[1].set_visible(False)  # it never stops sure: nothing to zoom into
        for ax, lo in zip(row_axes, (0.0, 0.9)):
            if not ax.get_visible():
                continue
            ax.plot([lo, 1], [lo, 1], color="0.6", lw=1, ls="--", label="a promise kept")
            for level in range(study.levels):
                sel = [r for r in rows if int(r["level"]) == level]
                pts = [p for p in reliability(study, m, sel) if p[0] >= lo]
                if not pts:
                    continue
                x, y, n = (np.array(v) for v in zip(*pts))
                ci = np.array([wilson(int(round(a * b)), int(b)) for a, b in zip(y, n)])
                label = str(study.level_label(level)) if study.parameter else "all trials"
                err = [np.clip(y - ci[:, 0], 0, None), np.clip(ci[:, 1] - y, 0, None)]
                ax.errorbar(x, y, yerr=err, fmt="o-", ms=3, capsize=2, lw=1, label=label)
                for xi, yi, ni in zip(x, y, n):
                    ax.annotate(str(ni), (xi, yi), fontsize=6, xytext=(3, -9), textcoords="offset points")
            ax.set_xlim(lo, 1.0 + (1 - lo) * 0.01)
            ax.set_ylim(lo if lo else 0.0, 1.0 + (1 - lo) * 0.01)
            ax.set_xlabel("stated probability within the radius at the stop")
            ax.set_ylabel(f"fraction actually within {study.success_radius} mm")
            ax.set_title(f"{m}" + (" (from 0.9 up)" if lo else ""), fontsize=10)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper left" if not lo else "lower right")
    fig.suptitle(f"{study.name}: reliability (numbers: trials per bin; bars: 95% intervals)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "reliability.png", dpi=110)
    plt.close(fig)


def print_summary(summary: dict) -> None:
    print(
        f"study {summary['study']}: {summary['method']} rule, {summary['engine']} engine, "
        f"noise {Path(str(summary['noise'])).name}"
    )
    for lv in summary["levels"]:
        v = "" if lv["value"] is None else f"{lv['parameter']} = {lv['value']}: "
        rate = lv["success_rate"]
        print(
            f"  {v}{lv['success']}/{lv['trials']} within {summary['success_radius']} mm = "
            f"{rate:.1%} (95% CI {lv['ci95'][0]:.1%}–{lv['ci95'][1]:.1%}), median error "
            f"{lv['error_median_mm']:.3f} mm"
            if rate is not None
            else f"  {v}no trials"
        )
        if len(summary["levels"]) > 1:
            for m, d in lv.get("methods", {}).items():
                _print_method(m, d, indent="    ")
    for m, d in summary.get("method_details", {}).items():
        _print_method(m, d, indent="  ")


def _print_method(m: str, d: dict, indent: str) -> None:
    if not d["trials"]:
        return
    rot = "" if d["mean_rotation_deg"] is None else f"mean rotation {d['mean_rotation_deg']:.1f}°, "
    print(
        f"{indent}{m:10s} {d['success']}/{d['trials']} = {d['success'] / d['trials']:.1%} "
        f"(95% CI {d['ci95'][0]:.1%}–{d['ci95'][1]:.1%}), {rot}median error {d['error_median_mm']:.3f} mm; "
        f"stopped confident {d['confident']}, of which wrong {d['confident_wrong']}"
        + (f"; model mismatch {d['mismatch']}" if d.get("mismatch") else "")
    )
