"""Soak run: ``rolltouch run`` against the emulator with injected faults, many times in a row.

Every run must end, either localized (exit 0) or with one clear error line (exit 2), within its
deadline, and leave a run log that reads back (:func:`driver.records.trace.Trace.from_log`). Each run is its
own process (as a user runs it) against an emulator in this process with its own seed; the faults
default to ``drop=0.05,garble=0.05,delay=0.01``.

``python -m bench.soak --runs 50 --out out/soak`` writes ``runs.json`` (one record per run) and
prints the tally.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any, cast

__all__ = ["soak", "main"]

DEFAULT_FAULTS = ("drop=0.05", "garble=0.05", "delay=0.01")
ROOT = Path(__file__).resolve().parents[1]


def soak(
    runs: int,
    out: Path,
    *,
    faults: Iterable[str] = DEFAULT_FAULTS,
    part: str = "parts/trefoil.json",
    deadline: float = 600.0,
) -> list[dict[str, Any]]:
    """Run ``runs`` runs; returns their records (``rc``, ``seconds``, ``outcome``, ``log_ok``, ``last``)."""
    from driver.link import Emulator, Faults
    from driver.records import Trace, read_log
    from driver.rig import RigError
    from localizer import load_part
    from sim2d import SimRig

    out.mkdir(parents=True, exist_ok=True)
    model = load_part(ROOT / part)
    records: list[dict[str, Any]] = []
    for k in range(runs):
        rig = SimRig(model, noise="paper", seed=k)
        emu = Emulator(
            rig,
            start_pose=rig.approach_pose(120.0, jaw_position=0.0, standoff=1.0),
            faults=Faults.parse(list(faults)),
            seed=k,
        )
        arm, daq = emu.serve_tcp(0)
        log = out / f"run-{k:03d}.jsonl"
        cmd = [sys.executable, "-m", "driver.cli", "run", str(ROOT / part), "--arm", arm, "--daq", daq]
        cmd += ["--log", str(log), "--json", "--timeout", "0.5"]
        t0 = time.monotonic()
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=deadline)
            rc, stdout, stderr = done.returncode, done.stdout, done.stderr
        except subprocess.TimeoutExpired:
            rc, stdout, stderr = None, "", "hung"
        finally:
            force = float(cast(SimRig, emu.rig).world.contact().force)
            emu.close()
        seconds = time.monotonic() - t0
        errors = [line for line in stderr.splitlines() if line.startswith("rolltouch:")]
        if rc == 0:
            outcome = "localized" if json.loads(stdout).get("consistent", True) else "no consistent contact"
        elif rc == 2 and len(errors) == 1:
            outcome = "clear error"
        else:
            outcome = "hung" if rc is None else "unclear"
        try:
            read_log(log)
            log_ok = True
        except RigError:
            log_ok = False
        try:
            Trace.from_log(log)
            trace_ok = True
        except RigError:  # a run that failed before its calibration was logged has no trace to make
            trace_ok = False
        records.append(
            {
                "run": k,
                "rc": rc,
                "seconds": round(seconds, 2),
                "outcome": outcome,
                "log_ok": log_ok,
                "trace_ok": trace_ok,
                "force_after": force,
                "last": errors[-1] if errors else "",
            }
        )
        print(f"run {k + 1}/{runs}: {outcome} in {seconds:.1f} s{'' if log_ok else ' (log unreadable)'}", flush=True)
    (out / "runs.json").write_text(json.dumps(records, indent=1) + "\n")
    return records


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.soak", description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=50)
    ap.add_argument("--out", default="out/soak", metavar="DIR")
    ap.add_argument("--fault", action="append", metavar="NAME=VALUE", help=f"default {' '.join(DEFAULT_FAULTS)}")
    args = ap.parse_args(argv)
    records = soak(args.runs, Path(args.out), faults=tuple(args.fault or DEFAULT_FAULTS))
    tally: dict[str, int] = {}
    for r in records:
        tally[r["outcome"]] = tally.get(r["outcome"], 0) + 1
    secs = sorted(r["seconds"] for r in records)
    print(f"{len(records)} runs: " + ", ".join(f"{v} {k}" for k, v in sorted(tally.items())))
    print(f"seconds per run: median {secs[len(secs) // 2]:.1f}, longest {secs[-1]:.1f}")
    print(f"logs that read back: {sum(r['log_ok'] for r in records)}/{len(records)}")
    print(f"... and make a trace: {sum(r['trace_ok'] for r in records)}/{len(records)}")
    failed = [r for r in records if r["rc"] != 0]
    print(f"jaw off the part after an error: {sum(r['force_after'] == 0.0 for r in failed)}/{len(failed)}")
    bad = [r for r in records if r["outcome"] in ("hung", "unclear") or not r["log_ok"]]
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
