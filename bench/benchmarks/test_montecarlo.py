"""Monte Carlo throughput: trials per second on each engine, and the speed-up of 2 workers.

Run: ``pytest bench --benchmark-only`` (figures in ``--benchmark-json``). The trial rate repeats one
trial (the same seed each round, so that its fastest round is comparable between runs). The
speed-up of 2 workers runs a 32-trial study with warm caches (docs/studies.md has the figures); below 1.2 the
pool has stopped sharing the work.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from bench.benchmarks.baselines import per_second
from bench.montecarlo import run_study
from bench.study import load_study
from bench.trial import TrialSpec, run_trial

if TYPE_CHECKING:
    from pytest_benchmark.fixture import BenchmarkFixture

STUDY = Path(__file__).resolve().parents[1] / "studies" / "paper.toml"
#: One trial before the pymunk world settled until the jaw was still (commit 8b9ee9b, this machine,
#: 2026-12-05, fastest round, s).
BEFORE_MIN_S = {"kinematic": 0.119, "pymunk": 2.902}


@pytest.mark.parametrize("engine", ["kinematic", "pymunk"])
def test_trial_rate(benchmark: BenchmarkFixture, engine: str) -> None:
    study = load_study(STUDY).with_overrides(engine=engine)

    def one() -> dict[str, Any]:
        return run_trial(TrialSpec(study, 0, 0))

    kinematic = engine == "kinematic"
    row: dict[str, Any] = benchmark.pedantic(  # type: ignore[no-untyped-call,unused-ignore]
        one, rounds=5 if kinematic else 2, iterations=1, warmup_rounds=1 if kinematic else 0
    )
    assert row["failure"] == "" and row["error_mm"] >= 0
    per_second(benchmark, "trials_per_second")
    benchmark.extra_info["before_min_s"] = BEFORE_MIN_S[engine]


def test_two_worker_speedup(benchmark: BenchmarkFixture, tmp_path: Path) -> None:
    study = load_study(STUDY).with_overrides(trials=32)
    # the parts' tables and reach built first, in this process: the workers are forked with them, as a
    # long study's workers have them after their first trials; the summary and its plots (about a
    # second, serial) are in both timings
    run_study(study.with_overrides(trials=2 * len(study.parts)), tmp_path / "warm", workers=1, progress=False)
    timings: dict[int, float] = {}

    def run(workers: int) -> None:
        t0 = time.perf_counter()
        run_study(study, tmp_path / f"w{workers}", workers=workers, progress=False)
        timings[workers] = time.perf_counter() - t0

    benchmark.pedantic(run, args=(2,), rounds=1, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    run(1)
    speedup = timings[1] / timings[2]
    benchmark.extra_info.update({"one_worker_s": timings[1], "two_workers_s": timings[2], "speedup": speedup})
    if not benchmark.disabled:
        assert speedup >= 1.2
