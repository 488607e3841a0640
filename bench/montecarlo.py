"""The Monte Carlo runner: trials in parallel, appended to ``trials.csv`` as they finish, resumable.

Local processes by default; with a scheduler address the same trials run on
a Dask distributed cluster through its ``concurrent.futures`` executor.
"""

from __future__ import annotations

import contextlib
import csv
import json
import multiprocessing
import os
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any, TextIO

from tqdm import tqdm

from driver.link import LockHeld, hold_lock
from localizer import fingerprint, load_part

from .columns import TRIAL_COLUMNS
from .study import Study, StudyError
from .study_plots import plot_study
from .summary import (
    json_safe,
    summarize,
)
from .trial import TrialSpec, run_trial

__all__ = ["run_study", "read_trials"]


#: How long a Dask scheduler has to answer, s.
SCHEDULER_TIMEOUT = 10.0


def read_trials(path: str | os.PathLike[str], *, warn: bool = False) -> list[dict[str, Any]]:
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
    rows: list[dict[str, Any]] = []
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


def _fmt(v: object) -> str:
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else str(v)


def run_study(
    study: Study,
    out: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
) -> dict[str, Any]:
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


def _run_locked(
    study: Study, out: Path, *, workers: int | None, scheduler: str | None, resume: bool, progress: bool
) -> dict[str, Any]:
    table = out / "trials.csv"
    if resume and table.exists():
        _check_same_study(study, out)
    (out / "study.json").write_text(json.dumps(_study_record(study), indent=2) + "\n")
    done: set[tuple[int, int]] = set()
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
    # the progress line: trials done of all, rate, time left, and the success rate so far (tqdm)
    bar = tqdm(total=total, initial=finished, unit="trial", disable=not progress, file=sys.stderr, mininterval=0.5)

    def record(row: dict[str, Any], f: TextIO, writer: csv.DictWriter[str]) -> None:
        nonlocal finished, successes
        writer.writerow({k: _fmt(row.get(k)) for k in study.columns})
        f.flush()
        finished += 1
        successes += int(row["success"])
        bar.set_postfix_str(f"success {successes / max(finished, 1):.1%}", refresh=False)
        bar.update(1)

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
                client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)  # type: ignore[no-untyped-call,unused-ignore]
            except OSError as exc:
                raise StudyError(
                    f"--scheduler {scheduler}: no Dask scheduler answered within {SCHEDULER_TIMEOUT:g} s ({exc}); "
                    "is it running, and is the address tcp://HOST:PORT?"
                ) from None
            with client:
                executor = client.get_executor(pure=False)  # type: ignore[no-untyped-call,unused-ignore]
                futures = [executor.submit(run_trial, s) for s in specs]
                for fut in as_completed(futures):
                    record(fut.result(), f, writer)
        elif (workers or os.cpu_count() or 1) == 1:
            for s in specs:
                record(run_trial(s), f, writer)
        else:
            pool = ProcessPoolExecutor(max_workers=workers or os.cpu_count(), initializer=_die_with_parent)
            try:
                futures = [pool.submit(run_trial, s) for s in specs]
                for fut in as_completed(futures):
                    record(fut.result(), f, writer)
            except BaseException:
                # Ctrl-C (or a failure): the queued trials are dropped, not waited for; the finished
                # ones are in the table already and stay there, summarized below
                pool.shutdown(wait=False, cancel_futures=True)
                bar.close()
                _write_summary(study, table, out, t0)
                raise
            pool.shutdown()
    bar.close()
    return _write_summary(study, table, out, t0)


def _write_summary(study: Study, table: Path, out: Path, t0: float) -> dict[str, Any]:
    """summary.json and the plots from the finished rows of ``table``."""
    summary = summarize(study, read_trials(table))
    summary["wall_s"] = time.monotonic() - t0
    (out / "summary.json").write_text(json.dumps(json_safe(summary), indent=2, allow_nan=False) + "\n")
    plot_study(study, read_trials(table), out)
    return summary


def _study_record(study: Study) -> dict[str, Any]:
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
def _folder_lock(out: Path) -> Iterator[None]:
    """Hold ``out/.lock`` for the run: two runs writing one folder would interleave their rows."""
    try:
        handle = hold_lock(out / ".lock", f"rolltouch montecarlo pid {os.getpid()}")
    except LockHeld as held:
        raise StudyError(f"{out} is being written by {held.holder}: wait for it, or use another --out") from None
    with handle:
        yield


def _die_with_parent() -> None:
    """A worker's initializer: exit as soon as the run that started it is gone (SIGKILL leaves workers
    otherwise running for ever).

    The run is watched through multiprocessing's own handle on it, the end of a pipe that the run holds
    open while it lives, under every start method: the worker's parent process is the run under fork and
    spawn, but the fork server under forkserver (the default on Linux from Python 3.14)."""
    run = multiprocessing.parent_process()
    if run is None:  # not a worker: called in the run itself
        return

    def watch() -> None:
        run.join()  # returns once the run has exited
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="die-with-parent").start()
