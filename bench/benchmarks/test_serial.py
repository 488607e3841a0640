"""The serial rig's reading over the emulator on a local TCP socket: what the driver adds to each reading.

Run: ``pytest bench --benchmark-only``.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import pytest

from bench.benchmarks.baselines import PARTS_DIR
from driver.link import Emulator, SerialRig
from localizer import load_part
from sim2d import SimRig

if TYPE_CHECKING:
    from pytest_benchmark.fixture import BenchmarkFixture

#: Before the rig read what a port holds at once (pyserial's ``read_until``, a byte per call: commit a387d53,
#: this machine, 2026-12-05, fastest round, s).
BEFORE_MIN_S = {"serial_read_tcp": 0.000364}


@pytest.fixture
def rig() -> Iterator[SerialRig]:
    sim = SimRig(load_part(PARTS_DIR / "trefoil.json"), noise="paper", seed=3)
    emulator = Emulator(sim, start_pose=sim.approach_pose(120.0, jaw_position=0.0, standoff=1.0))
    arm, daq = emulator.serve_tcp(0)
    try:
        with SerialRig(arm, daq) as serial_rig:
            yield serial_rig
    finally:
        emulator.close()


def test_serial_read(benchmark: BenchmarkFixture, rig: SerialRig) -> None:
    # READ 32 and its reply: the emulator's sampling is in the figure too, as a real DAQ's would be
    v1, v2 = benchmark.pedantic(rig.read, rounds=300, iterations=1, warmup_rounds=5)  # type: ignore[no-untyped-call,unused-ignore]
    assert abs(v1) < rig.input_range and abs(v2) < rig.input_range
    benchmark.extra_info["before_min_s"] = BEFORE_MIN_S["serial_read_tcp"]
