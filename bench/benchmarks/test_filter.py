"""The sequential filters' cost per rolling step (target: well under 1 ms on a 100-knot part).

Run: ``pytest bench/benchmarks/test_filter.py --benchmark-only``. Each benchmark feeds a filter a
25° roll first (checking the belief every 5 steps, as the reactive procedure does, which
prunes hypotheses 40 nats below the best), so that it is timed in the state it has
mid-localization.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any, TypeAlias, cast

import numpy as np
import pytest

from bench.benchmarks.baselines import PARTS_DIR, per_second
from localizer import ContactFilter, ParticleFilter, WheelFilter, WheelJaw, load_part, part_from_points

if TYPE_CHECKING:
    import numpy.typing as npt
    from pytest_benchmark.fixture import BenchmarkFixture
    from pytest_benchmark.stats import Metadata

    from localizer import Belief, Part

    FloatArray: TypeAlias = npt.NDArray[np.float64]

STEP = math.radians(0.2)

#: The wheel's benchmarks before its filter interpolated the start grid's angles (commit 21fce76, this
#: machine, 2026-12-05, fastest round, ms): the roll in pytest-benchmark, the used reading by perf_counter.
WHEEL_BEFORE_MS = {"test_wheel_filter_roll": 249.3, "test_wheel_filter_used_reading": 9.8}


@pytest.fixture(scope="module")
def part100() -> Part:
    """A smooth convex 100-knot part (an egg with a few lobes), about 240 mm round."""
    a = np.linspace(0, 2 * np.pi, 100, endpoint=False)
    r = 38 + 4 * np.cos(a) + 2.0 * np.cos(3 * a + 0.4) + 0.8 * np.sin(5 * a)
    return part_from_points(np.c_[r * np.cos(a), r * np.sin(a)], name="egg100")


def _roll(flt: ContactFilter, part: Part, start: float = 40.0, steps: int = 125) -> tuple[float, float]:
    i = int(round(start / flt.tracks.h))
    turns = cast("FloatArray", STEP * np.arange(1, steps + 1))
    arcs, ok = flt.tracks.advance(np.full(steps, i), turns)
    assert ok.all()
    for k, (a, t) in enumerate(zip(arcs - flt.grid[i], turns)):
        flt.update(float(a), float(t))
        if isinstance(flt, ContactFilter) and k % 5 == 4:
            flt.belief()  # as the reactive procedure checks every 5 steps (and prunes)
    return float(arcs[-1] - flt.grid[i]), float(turns[-1])


def test_grid_filter_update(benchmark: BenchmarkFixture, part100: Part) -> None:
    flt = ContactFilter(part100)
    z, turn = _roll(flt, part100)
    benchmark.extra_info.update({"part": "egg100 (100 knots)", "hypotheses": int(flt.grid.size)})
    benchmark(flt.update, z, turn)
    per_second(benchmark, "updates_per_second")


def test_grid_filter_belief(benchmark: BenchmarkFixture, part100: Part) -> None:
    flt = ContactFilter(part100)
    _roll(flt, part100)
    b = benchmark(flt.belief)
    per_second(benchmark, "beliefs_per_second")
    assert abs(part100.arc_offset(b.map_arc, flt.current[int(round(40.0 / flt.tracks.h))])) < 0.05


@pytest.mark.parametrize("particles", [2000, 20000, 200000])
def test_particle_filter_update(benchmark: BenchmarkFixture, part100: Part, particles: int) -> None:
    pf = ParticleFilter(part100, particles=particles, seed=1)
    grid = ContactFilter(part100)
    z, turn = _roll(grid, part100)
    benchmark.extra_info.update({"particles": particles})
    benchmark(pf.update, z, turn)
    per_second(benchmark, "updates_per_second")


@pytest.mark.parametrize("scales", ["weighed", "told"])
def test_grid_filter_roll(benchmark: BenchmarkFixture, part100: Part, scales: str) -> None:
    """A whole 25° roll, 125 readings with a belief every 5: what weighing the noise scale out costs
    (``weighed``: the default grid of 25 factors; ``told``: the settings taken at their word)."""
    kwargs: dict[str, Any] = {} if scales == "weighed" else {"noise_scales": (1.0,)}
    i = int(round(40.0 / ContactFilter(part100).tracks.h))
    turns = cast("FloatArray", STEP * np.arange(1, 126))

    def roll() -> ContactFilter:
        flt = ContactFilter(part100, **kwargs)
        arcs, _ = flt.tracks.advance(np.full(turns.size, i), turns)
        flt.touch(-40.0)
        for k, (a, t) in enumerate(zip(arcs - flt.grid[i], turns)):
            flt.update(float(a), float(t), jaw=-40.0 + float(a))
            if k % 5 == 4:
                flt.belief()
        return flt

    flt: ContactFilter = benchmark.pedantic(roll, rounds=5, iterations=1, warmup_rounds=1)  # type: ignore[no-untyped-call,unused-ignore]
    assert abs(part100.arc_offset(flt.belief().map_arc, flt.current[i])) < 0.05
    benchmark.extra_info.update({"scales": len(flt.noise_scales), "readings": int(turns.size)})
    if not benchmark.disabled:
        benchmark.extra_info["per_reading_ms"] = cast("Metadata", benchmark.stats).stats.min / turns.size * 1e3


@pytest.mark.parametrize("name", ["egg100", "heldout-a star-16"])
def test_reach_build(benchmark: BenchmarkFixture, part100: Part, name: str) -> None:
    """Building a part's reach for the 100 mm jaw (once per part; shared by every filter after)."""
    from pathlib import Path

    from localizer import Reach, load_part

    part = (
        part100
        if name == "egg100"
        else load_part(Path(__file__).resolve().parents[1] / "parts" / "heldout-a" / "star-16.json")
    )
    r: Reach = benchmark.pedantic(Reach, args=(part,), rounds=3, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    benchmark.extra_info.update({"perimeter_mm": round(part.perimeter, 1), "grid": int(r.sigma.size)})
    per_second(benchmark, "grid_points_per_second", r.sigma.size)


#: Where the wheel's benchmark rolls start on the kidney: inside its concave waist, mm.
WHEEL_START = 66.0


def _kidney_wheel_roll(step: float) -> tuple[Part, WheelFilter, FloatArray, FloatArray]:
    """The kidney, a 5 mm wheel's filter on it, and a noise-free 20 mm roll from :data:`WHEEL_START` read
    every ``step`` mm: (part, filter, lengths mm, turns rad)."""
    part = cast("Part", load_part(PARTS_DIR / "kidney.csv"))
    lengths = cast("FloatArray", np.arange(step, 20.01, step))
    theta = part.tangent_angle(part.param_at_arc(WHEEL_START + np.r_[0.0, lengths]))
    return part, WheelFilter(part, WheelJaw(5.0)), lengths, cast("FloatArray", theta[1:] - theta[0])


def _filtered_roll(flt: WheelFilter, lengths: FloatArray, turns: FloatArray) -> Belief:
    """The roll's readings through ``flt`` from a reset, a belief every 4 (as
    :func:`driver.wheel.localize_with_wheel`): the last belief."""
    flt.reset()
    for k, (L, om) in enumerate(zip(lengths, turns)):
        flt.update(float(L), float(om))
        if k % 4 == 3:
            b = flt.belief()
    return b


def test_wheel_filter_roll(benchmark: BenchmarkFixture) -> None:
    """A 5 mm wheel's filter over a 20 mm roll from inside the kidney's waist: 80 readings 0.25 mm apart
    (one a millimetre used by the likelihood), a belief every 4, as :func:`driver.wheel.localize_with_wheel`;
    the filter's defaults (the part's scale carried)."""
    part, flt, lengths, turns = _kidney_wheel_roll(0.25)
    b: Belief = benchmark.pedantic(_filtered_roll, args=(flt, lengths, turns), rounds=5, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    assert abs(float(part.arc_offset(b.map_arc, WHEEL_START + lengths[-1]))) < 0.3
    benchmark.extra_info.update(
        {
            "starts": int(flt.grid.size),
            "readings": int(lengths.size),
            "before_ms": WHEEL_BEFORE_MS["test_wheel_filter_roll"],
        }
    )
    per_second(benchmark, "readings_per_second", lengths.size)


def test_wheel_filter_roll_at_the_models_size(benchmark: BenchmarkFixture) -> None:
    """:func:`test_wheel_filter_roll` with the part taken at its model's size (``off_scale`` 0; the default carries
    its scale, localizer.OFF_SCALE): each used reading whitens the residuals alone, a belief weighs one size."""
    part, _, lengths, turns = _kidney_wheel_roll(0.25)
    flt = WheelFilter(part, WheelJaw(5.0), off_scale=0.0)
    b: Belief = benchmark.pedantic(_filtered_roll, args=(flt, lengths, turns), rounds=5, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    assert abs(float(part.arc_offset(b.map_arc, WHEEL_START + lengths[-1]))) < 0.3
    benchmark.extra_info.update({"starts": int(flt.grid.size), "readings": int(lengths.size)})
    per_second(benchmark, "readings_per_second", lengths.size)


def test_wheel_filter_used_reading(benchmark: BenchmarkFixture) -> None:
    """One reading the wheel's likelihood uses (the 20th of a roll on the kidney, its start grid 11724 wide),
    and in the same run the cost of the model's angles at every start evaluated on the spline itself (what
    the filter did before it interpolated the start grid's, 10 ms a reading here)."""
    from localizer.contact import ShiftedGrid

    part, flt, lengths, turns = _kidney_wheel_roll(1.0)

    def nineteen() -> tuple[tuple[float, float], dict[str, Any]]:
        flt.reset()
        for L, om in zip(lengths[:-1], turns[:-1]):
            flt.update(float(L), float(om))
        return (float(lengths[-1]), float(turns[-1])), {}

    benchmark.pedantic(flt.update, setup=nineteen, rounds=10, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    assert len(flt.L_used) == lengths.size
    times = {}
    for name, exact in (("interpolated", False), ("spline", True)):
        table = ShiftedGrid(part, flt.grid.size, exact=exact)
        best = math.inf
        for _ in range(5):
            t0 = time.perf_counter()
            table.at(float(lengths[-1]))
            best = min(best, time.perf_counter() - t0)
        times[name] = best
    benchmark.extra_info.update(
        {
            "starts": int(flt.grid.size),
            "before_ms": WHEEL_BEFORE_MS["test_wheel_filter_used_reading"],
            "angles_interpolated_ms": round(times["interpolated"] * 1e3, 3),
            "angles_on_the_spline_ms": round(times["spline"] * 1e3, 3),
        }
    )
