"""Two-roll queries on the shipped drawings (the likelihood rule's sum over every path, and the paper's
rule with its χ² fit test), at the CLI's default ``sd_length`` of 0.5 mm (target: ≤ 0.2 s a query).

In the same run, the same chain's sums with every way weighed in logarithms (``exact``), the reference
the fast sums are tested against; ``before_s`` is the query's fastest time in numpy, before the sums were
compiled (commit 8b9ee9b, this machine, 2026-12-05).

Run: ``pytest bench/benchmarks/test_chain.py --benchmark-only``.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

import numpy as np
import pytest

from bench.benchmarks.baselines import PARTS_DIR
from localizer import load_outline, localize
from localizer.chain import chain_forward

if TYPE_CHECKING:
    from pytest_benchmark.fixture import BenchmarkFixture

    from localizer import Localization

#: (drawing, start arc mm, two roll lengths mm): on the bracket a start before a fillet and a corner (one
#: place), on the profile along a face (a continuum of some forty candidates)
CHAINS = {"bracket": ("bracket.dxf", 75.0, (20.0, 15.0)), "profile": ("profile.svg", 40.0, (20.0, 15.0))}
BEFORE_S = {
    ("bracket", "likelihood"): 1.98,
    ("bracket", "paper"): 1.95,
    ("profile", "likelihood"): 1.03,
    ("profile", "paper"): 1.03,
}


@pytest.mark.parametrize("rule", ["likelihood", "paper"])
@pytest.mark.parametrize("name", list(CHAINS))
def test_two_roll_query_on_a_drawing(benchmark: BenchmarkFixture, name: str, rule: str) -> None:
    path, start, lengths = CHAINS[name]
    outline = load_outline(PARTS_DIR / path)
    pos = start + np.cumsum(np.r_[0.0, lengths])
    turns = np.diff(outline.tangent_angle_at_arc(pos))
    chain = tuple((float(L), float(w)) for L, w in zip(lengths, turns))
    localize(outline, chain, rule=rule, sd_length=0.5)  # compile (or load) the kernels
    got: Localization = benchmark.pedantic(  # type: ignore[no-untyped-call,unused-ignore]
        localize, args=(outline, chain), kwargs={"rule": rule, "sd_length": 0.5}, rounds=5, iterations=1
    )
    P = outline.perimeter
    assert min(abs((c.end_arc - pos[-1] + 0.5 * P) % P - 0.5 * P) for c in got.candidates) < 1.0  # the truth is kept
    t0 = time.perf_counter()
    chain_forward(outline, chain, 1.0, 0.5, math.radians(0.03), exact=True)
    benchmark.extra_info.update(
        {
            "before_s": BEFORE_S[name, rule],
            "sums_in_logarithms_s": round(time.perf_counter() - t0, 3),
            "candidates": len(got.candidates),
        }
    )
