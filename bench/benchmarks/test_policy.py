"""A decision of the reactive policy that seeks information (bound: ≤ 20 ms on the benchmark part): the
expected gain each way over the 64 most probable starts, and whether each way is clear.

Run: ``pytest bench/benchmarks/test_policy.py --benchmark-only``. The filter is first fed a 10° noise-free
roll from 20 mm on the trefoil (50 readings, a belief every 5 as the reactive procedure checks), where
two places still fit (0.81 on the leading one) and the rule has something to weigh.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, TypeAlias, cast

import numpy as np

from bench.benchmarks.baselines import trefoil_part
from driver.jaw import ReactivePolicy, clear_ahead, information_by_direction
from localizer import ContactFilter

if TYPE_CHECKING:
    import numpy.typing as npt
    from pytest_benchmark.fixture import BenchmarkFixture

    FloatArray: TypeAlias = npt.NDArray[np.float64]


def test_seeking_decision(benchmark: BenchmarkFixture) -> None:
    part = trefoil_part()
    flt = ContactFilter(part)
    policy = ReactivePolicy(seek=True)
    i = int(round(20.0 / flt.tracks.h))
    turns = cast("FloatArray", math.radians(0.2) * np.arange(1, 51))
    arcs, ok = flt.tracks.advance(np.full(turns.size, i), turns)
    assert ok.all()
    for k, (a, t) in enumerate(zip(arcs - flt.grid[i], turns)):
        flt.update(float(a), float(t))
        if k % 5 == 4:
            belief = flt.belief()
    assert len([m for m in belief.modes if m.mass >= flt.mode_floor]) >= 2  # a decision to make
    explored = (float(turns[-1]), 0.0)

    def decide() -> tuple[float, ...]:
        gains = information_by_direction(flt, policy.lookahead, explored)
        return (*gains, clear_ahead(flt, 1, policy.lookahead), clear_ahead(flt, -1, policy.lookahead, at=0.0))

    out = benchmark.pedantic(decide, rounds=20, iterations=1, warmup_rounds=2)  # type: ignore[no-untyped-call,unused-ignore]
    assert all(math.isfinite(v) for v in out)
    benchmark.extra_info.update({"bound_ms": 20.0, "modes": len(belief.modes)})
