"""Exact solver against the paper's unit of cost, in the same run, part by part.

The parts: the shipped trefoil (90 knots), a 36-point random star, and three 90-point outlines
traced as from silhouettes (:func:`bench.benchmarks.baselines.traced_outline`, seeds 0–2), whose
curvature changes 25–30 times faster than the trefoil's. Each query's cost is set against one
perimeter integration at the paper's h = 1e-5 on the same part, timed in the same test.

Run: ``pytest bench --benchmark-only`` (figures in ``--benchmark-json``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, cast

import numpy as np
import pytest

from bench.benchmarks.baselines import per_second, random_outline, traced_outline, trapezoid_perimeter, trefoil_part
from localizer import feasible_segments, part_from_points

if TYPE_CHECKING:
    from pytest_benchmark.fixture import BenchmarkFixture
    from pytest_benchmark.stats import Metadata

    from localizer import Part, Segment
    from localizer.solve._table import ArcTable

N_QUERIES = 20


def _star() -> Part:
    return part_from_points(random_outline(np.random.default_rng(0), n=36, amplitude=5.0), name="star-36")


def _traced(seed: int) -> Callable[[], Part]:
    return lambda: part_from_points(traced_outline(np.random.default_rng(seed)), name=f"traced-90-{seed}")


PARTS = {"trefoil": trefoil_part, "star-36": _star, **{f"traced-90-{s}": _traced(s) for s in range(3)}}


@pytest.fixture(scope="module", params=list(PARTS))
def part(request: pytest.FixtureRequest) -> Part:
    p = PARTS[request.param]()
    feasible_segments(p, 10.0, 0.1)  # build and cache the tables once per part (and compile the kernels)
    return p


@pytest.fixture(scope="module")
def queries(part: Part) -> list[tuple[float, float, float]]:
    rng = np.random.default_rng(2005)
    P = part.perimeter
    out = []
    for _ in range(N_QUERIES):
        s0, L = rng.uniform(0, P), rng.uniform(5.0, 60.0)
        w = float(part.tangent_angle_at_arc(s0 + L) - part.tangent_angle_at_arc(s0))
        out.append((s0, L, w))
    return out


def _run(part: Part, queries: list[tuple[float, float, float]]) -> list[list[Segment]]:
    return [feasible_segments(part, L, w) for _, L, w in queries]


def test_exact_query_vs_perimeter_integration(
    benchmark: BenchmarkFixture, part: Part, queries: list[tuple[float, float, float]]
) -> None:
    # rounds spread over a second or more: the machine's speed drifts over seconds (docs/contributing.md)
    results: list[list[Segment]] = benchmark.pedantic(  # type: ignore[no-untyped-call,unused-ignore]
        _run, args=(part, queries), rounds=200, iterations=1, warmup_rounds=2
    )
    for (s0, L, w), segs in zip(queries, results):  # completeness: the truth is always found, exactly
        assert np.abs(part.arc_offset([s.start_arc for s in segs], s0)).min() < 1e-6
        for s in segs:
            assert abs(part.arc_length(s.start_param, s.end_param) - L) < 1e-9
            assert abs(part.total_curvature(s.start_param, s.end_param) - w) < 1e-9
    if benchmark.disabled:
        return
    integration = min(_timed(trapezoid_perimeter, part) for _ in range(3))
    per_query = cast("Metadata", benchmark.stats).stats.min / N_QUERIES
    ratio = integration / per_query
    benchmark.extra_info.update(
        {
            "part": part.name,
            "knots": part.n_knots,
            "query_s": per_query,
            "trapezoid_perimeter_h1e-5_s": integration,
            "ratio": ratio,
            "target_ratio": 1000,
            "segments_per_query": float(np.mean([len(r) for r in results])),
        }
    )
    print(f"\n{part.name}: exact query {per_query * 1e3:.3f} ms, integration {integration:.3f} s, ratio {ratio:.0f}x")
    assert ratio >= 1000


def _timed(fn: Callable[..., object], *args: object) -> float:
    t0 = time.perf_counter()
    fn(*args)
    return time.perf_counter() - t0


def test_perimeter_integration_h1e5(benchmark: BenchmarkFixture) -> None:
    part = trefoil_part()
    value: float = benchmark.pedantic(trapezoid_perimeter, args=(part,), rounds=3, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    assert value == pytest.approx(part.perimeter, rel=1e-9)
    per_second(benchmark, "steps_per_second", part.n_knots / 1e-5)


def test_table_build(benchmark: BenchmarkFixture) -> None:
    from localizer.solve._table import arc_table

    def build() -> ArcTable:
        p = trefoil_part()
        return arc_table(p)

    table: ArcTable = benchmark.pedantic(build, rounds=200, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    assert table.theta_error < 1e-9
