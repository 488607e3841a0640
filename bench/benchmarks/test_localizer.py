"""Exact solver against the paper's unit of cost, in the same run.

Run: ``pytest bench --benchmark-only`` (figures in ``--benchmark-json``).
"""

import time

import numpy as np
import pytest

from bench.benchmarks.baselines import per_second, trapezoid_perimeter, trefoil_part
from localizer import feasible_segments

N_QUERIES = 20


@pytest.fixture(scope="module")
def part():
    p = trefoil_part()
    feasible_segments(p, 10.0, 0.1)  # build and cache the tables once per part
    return p


@pytest.fixture(scope="module")
def queries(part):
    rng = np.random.default_rng(2005)
    P = part.perimeter
    out = []
    for _ in range(N_QUERIES):
        s0, L = rng.uniform(0, P), rng.uniform(5.0, 60.0)
        w = float(part.tangent_angle_at_arc(s0 + L) - part.tangent_angle_at_arc(s0))
        out.append((s0, L, w))
    return out


def _run(part, queries):
    return [feasible_segments(part, L, w) for _, L, w in queries]


def test_exact_query_vs_perimeter_integration(benchmark, part, queries):
    results = benchmark.pedantic(_run, args=(part, queries), rounds=15, iterations=1, warmup_rounds=2)
    for (s0, _, _), segs in zip(queries, results):  # completeness: the truth is always found
        assert np.abs(part.arc_offset([s.start_arc for s in segs], s0)).min() < 1e-6
    if benchmark.disabled:
        return
    integration = min(_timed(trapezoid_perimeter, part) for _ in range(3))
    per_query = benchmark.stats.stats.min / N_QUERIES
    ratio = integration / per_query
    benchmark.extra_info.update(
        {
            "part": "trefoil (90 knots, non-convex)",
            "query_s": per_query,
            "trapezoid_perimeter_h1e-5_s": integration,
            "ratio": ratio,
            "target_ratio": 1000,
            "bar_ratio": 100,
            "mean_candidates": float(np.mean([len(r) for r in results])),
        }
    )
    print(f"\nexact query {per_query * 1e3:.3f} ms, perimeter integration {integration:.3f} s, ratio {ratio:.0f}x")
    assert ratio >= 100


def _timed(fn, *args):
    t0 = time.perf_counter()
    fn(*args)
    return time.perf_counter() - t0


def test_perimeter_integration_h1e5(benchmark, part):
    value = benchmark.pedantic(trapezoid_perimeter, args=(part,), rounds=3, iterations=1)
    assert value == pytest.approx(part.perimeter, rel=1e-9)
    per_second(benchmark, "steps_per_second", part.n_knots / 1e-5)


def test_table_build(benchmark):
    from localizer._table import arc_table

    def build():
        p = trefoil_part()
        return arc_table(p)

    table = benchmark.pedantic(build, rounds=5, iterations=1)
    assert table.theta_error < 1e-9
