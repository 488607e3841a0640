"""The paper's marching algorithm: cost at the paper's step, Theorem 2, Proposition 1.

Run: ``pytest bench --benchmark-only`` (figures in ``--benchmark-json``); the
full studies and plots are ``python -m bench.reports.march_study``.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import pytest

from bench.benchmarks.baselines import trefoil_part
from bench.reports.march_study import proposition_1
from localizer import MarchOptions, feasible_segments, march, march_grid

if TYPE_CHECKING:
    from pytest_benchmark.fixture import BenchmarkFixture
    from pytest_benchmark.stats import Metadata

    from localizer import MarchGrid, MarchResult, Part

H = 1e-5  # the paper's step


@pytest.fixture(scope="module")
def part() -> Part:
    p = trefoil_part()
    feasible_segments(p, 10.0, 0.1)
    march_grid(p, H)
    return p


@pytest.fixture(scope="module")
def query(part: Part) -> tuple[float, float, float]:
    s0, L = 120.0, 25.0
    return s0, L, float(part.tangent_angle_at_arc(s0 + L) - part.tangent_angle_at_arc(s0))


def test_march_query_at_paper_step(benchmark: BenchmarkFixture, part: Part, query: tuple[float, float, float]) -> None:
    s0, L, w = query
    res: MarchResult = benchmark.pedantic(  # type: ignore[no-untyped-call,unused-ignore]
        march, args=(part, L, w), kwargs={"options": MarchOptions(step=H)}, rounds=100, iterations=1
    )
    assert 0 < res.steps <= 6 * res.grid_cells  # Theorem 2
    nearest = min(abs(part.arc_offset(g.start_arc, s0)) for g in res.segments)
    assert nearest < 0.1
    t0 = time.perf_counter()
    exact = feasible_segments(part, L, w)
    t_exact = time.perf_counter() - t0
    benchmark.extra_info.update(
        {
            "h": H,
            "steps": res.steps,
            "steps_per_period": res.steps / res.grid_cells,
            "bound": 6,
            "segments_march": len(res.segments),
            "segments_exact": len(exact),
            "march_error_mm": nearest,
            "exact_error_mm": min(abs(part.arc_offset(g.start_arc, s0)) for g in exact),
            "exact_s": t_exact,
        }
    )
    if not benchmark.disabled:
        benchmark.extra_info["march_over_exact"] = cast("Metadata", benchmark.stats).stats.min / t_exact


def test_march_grid_at_paper_step(benchmark: BenchmarkFixture) -> None:
    p = trefoil_part()

    def build() -> MarchGrid:
        p.forget_tables()
        return march_grid(p, H)

    grid: MarchGrid = benchmark.pedantic(build, rounds=2, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    assert grid.length[-1] == pytest.approx(p.perimeter, rel=1e-9)
    assert grid.turn[-1] == pytest.approx(2 * np.pi, abs=1e-6)


def test_proposition_1_ratio(benchmark: BenchmarkFixture) -> None:
    rows: list[dict[str, Any]] = benchmark.pedantic(  # type: ignore[no-untyped-call,unused-ignore]
        proposition_1, args=(2, 11), kwargs=dict(h=1e-4), rounds=1, iterations=1
    )
    ok = [r for r in rows if r["measured"] is not None and r["kind"] == "simple"]
    dev = np.array([abs(r["measured"] - r["predicted"]) for r in ok])
    benchmark.extra_info.update(
        {
            "segments": len(rows),
            "measured": len(ok),
            "abs_dev_median": float(np.median(dev)),
            "abs_dev_max": float(dev.max()),
        }
    )
    assert len(ok) >= 10 and dev.max() < 0.01
