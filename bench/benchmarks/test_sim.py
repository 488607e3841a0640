"""Simulated rolling: pymunk steps per second, and a whole rolling step on each engine.

Run: ``pytest bench --benchmark-only``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, cast

import pytest

from bench.benchmarks.baselines import PARTS_DIR
from driver.jaw import Calibration, establish_contact, roll
from localizer import load_part
from sim2d import SimRig
from sim2d.pymunk_world import PymunkWorld

if TYPE_CHECKING:
    from pytest_benchmark.fixture import BenchmarkFixture
    from pytest_benchmark.stats import Metadata

    from driver.jaw import RollResult
    from localizer import Part
    from sim2d.world import Contact

STEP = math.radians(0.2)
#: Before the pymunk world settled until the jaw was still and polygonised at 1 µm (commit 8b9ee9b, this
#: machine, 2026-12-05, fastest round, s).
BEFORE_MIN_S = {"steps_2000": 0.07815, "rolling_step_pymunk": 0.01248, "rolling_step_kinematic": 0.00023}


@pytest.fixture(scope="module")
def part() -> Part:
    return cast("Part", load_part(PARTS_DIR / "cam.json"))


@pytest.fixture(scope="module")
def calibration() -> Calibration:
    # the wrist's exact ratio line: this benchmark measures rolling, not calibration
    positions = tuple(float(d) for d in range(-50, 51, 10))
    return Calibration(positions, tuple(-d / (32 * 25.0) for d in positions))


def test_pymunk_steps_per_second(benchmark: BenchmarkFixture, part: Part) -> None:
    w = PymunkWorld(part)
    arc = 40.0
    t = part.param_at_arc(arc)
    c, phi = part.point(t), float(part.tangent_angle(t))
    e, m = (math.cos(phi), math.sin(phi)), (-math.sin(phi), math.cos(phi))
    w.set_hand(c[0] + 20 * e[0] + 0.5 * m[0], c[1] + 20 * e[1] + 0.5 * m[1], phi)

    def run(n: int = 2000) -> Contact:
        for _ in range(n):
            w.step()
        return w.contact()

    contact: Contact = benchmark.pedantic(run, rounds=5, iterations=1)  # type: ignore[no-untyped-call,unused-ignore]
    assert contact.force > 0
    if not benchmark.disabled:
        benchmark.extra_info["steps_per_second"] = 2000 / cast("Metadata", benchmark.stats).stats.mean
    benchmark.extra_info["before_min_s"] = BEFORE_MIN_S["steps_2000"]


@pytest.mark.parametrize("engine", ["kinematic", "pymunk"])
def test_rolling_step(benchmark: BenchmarkFixture, part: Part, calibration: Calibration, engine: str) -> None:
    rig = SimRig(part, engine=engine)
    hand, base, _ = establish_contact(rig, rig.approach_pose(30.0, jaw_position=-40.0, standoff=1.0))

    def one_step() -> RollResult:
        return roll(rig, hand, base, calibration, STEP, step=STEP, offset=1.0)

    # rounds spread over a second or two: the machine's speed drifts over seconds (docs/contributing.md)
    r: RollResult = benchmark.pedantic(  # type: ignore[no-untyped-call,unused-ignore]
        one_step, rounds=600 if engine == "kinematic" else 60, iterations=1, warmup_rounds=2
    )
    assert r.length > 0
    if not benchmark.disabled:
        benchmark.extra_info["rolling_steps_per_second"] = 1 / cast("Metadata", benchmark.stats).stats.mean
    benchmark.extra_info["before_min_s"] = BEFORE_MIN_S[f"rolling_step_{engine}"]
