"""Reference costs the benchmarks compare against."""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeAlias, cast

import numpy as np

if TYPE_CHECKING:
    import numpy.typing as npt
    from pytest_benchmark.fixture import BenchmarkFixture

    from localizer import Part

    FloatArray: TypeAlias = npt.NDArray[np.float64]

__all__ = ["trapezoid_perimeter", "trefoil_part", "PARTS_DIR", "per_second", "random_outline", "traced_outline"]

from pathlib import Path

PARTS_DIR = Path(__file__).resolve().parents[2] / "parts"


def trapezoid_perimeter(part: Part, h: float = 1e-5, chunk: int = 1_000_000) -> float:
    """Perimeter by the trapezoid rule at step ``h`` in the parameter domain, mm.

    The paper's unit of cost (§II-B: "acquiring the perimeter of α by
    integration requires τ/h numerical steps"), vectorized in chunks so the
    baseline is as fast as numpy allows.
    """
    n = int(round(part.n_knots / h))
    total = 0.0
    for i in range(0, n, chunk):
        t = np.arange(i, min(i + chunk, n) + 1) * h
        v = part.speed(t)
        total += h * (v.sum() - 0.5 * (v[0] + v[-1]))
    return float(total)


def trefoil_part() -> Part:
    """The 90-knot non-convex benchmark part."""
    from localizer import load_part

    return cast("Part", load_part(PARTS_DIR / "trefoil.json"))


def random_outline(rng: np.random.Generator, n: int = 40, amplitude: float = 3.0, radius: float = 40.0) -> FloatArray:
    """A random smooth star-shaped outline (simple by construction), mm.

    ``radius`` plus harmonics 2..5 of total size ``amplitude``: about 1.5 mm and
    below gives convex parts at radius 40, about 4 mm and above non-convex ones.
    """
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = np.full(n, float(radius))
    for k in range(2, 6):
        r += amplitude / k * rng.uniform(-1, 1) * np.cos(k * a + rng.uniform(0, 2 * np.pi))
    return cast("FloatArray", np.c_[r * np.cos(a), r * np.sin(a)])


def traced_outline(
    rng: np.random.Generator, n: int = 90, radius: float = 40.0, harmonics: int = 24, pixel: float = 0.5
) -> FloatArray:
    """A random outline as if traced from a silhouette: ``n`` points, mm.

    A star-shaped shape with harmonics 2..``harmonics`` of amplitude 6 mm / k (a rough outline, not
    a smooth cam), each point then moved radially by up to half a ``pixel`` (the tracing's
    quantization). The spline through it needs 8 times the trefoil's table cells to reach 1e-9 rad
    and its |dκ/dσ| reaches 0.24–0.33 /mm² (seeds 0–5) against the trefoil's 0.010: curvature that
    changes 25–30 times faster.
    """
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = np.full(n, float(radius))
    for k in range(2, harmonics + 1):
        r += 6.0 / k * rng.uniform(-1, 1) * np.cos(k * a + rng.uniform(0, 2 * np.pi))
    r += rng.uniform(-0.5, 0.5, n) * pixel
    return cast("FloatArray", np.c_[r * np.cos(a), r * np.sin(a)])


def per_second(benchmark: BenchmarkFixture, key: str, count: float = 1.0) -> None:
    """Put the benchmark's figure of merit in its ``extra_info``: ``count`` units per second of its fastest
    round (nothing when the benchmark is disabled, as in the test run's smoke pass)."""
    stats = getattr(benchmark, "stats", None)
    if benchmark.disabled or stats is None:
        return
    benchmark.extra_info[key] = float(count) / float(stats.stats.min)
