"""The localizer's compiled kernels compiled once, after an install, rather than by the first commands.

numba compiles a kernel the first time it is called and keeps the machine code in its cache beside
the module (``__pycache__``); until then the first reactive run on a drawing waits 2.3 s for it (5.9 s
instead of 3.6 s), and each process of a test run or a study compiles what it needs by itself.
:func:`compile_kernels` runs a small instance of every computation that calls a kernel, with the
argument types the package uses, so that later processes load them from the cache. ``make`` does it
once when it sets up the environment.
"""

from __future__ import annotations

import math
import time

import numpy as np

from localizer import (
    ContactFilter,
    CubicBezier,
    Line,
    WheelJaw,
    feasible_segments,
    localize,
    outline_from_pieces,
    part_from_points,
    reach_for,
    wheel_reach_for,
)
from localizer.chain import chain_forward

__all__ = ["compile_kernels"]


def compile_kernels() -> float:
    """Compile (or load from numba's cache) every kernel of the localizer; the seconds it took (17.6 s
    compiling on this 2-core machine, 1.3 s loading)."""
    t0 = time.perf_counter()
    a = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    cam = part_from_points(np.c_[40.0 * np.cos(a) + 3.0 * np.cos(2.0 * a), 30.0 * np.sin(a)], name="warm-up cam")
    # the exact solver on a spline (its cell pass, roots and polish)
    feasible_segments(cam, 20.0, 0.5)
    # the straight jaw's reach and tracks, and the filter's sums and noise scales
    reach_for(cam)
    flt = ContactFilter(cam, spacing=0.5)
    turns = -0.01 * np.arange(1, 40)
    at = 10.0 + np.cumsum(np.full(turns.size, 0.3))
    for z, turn in zip(at - at[0], turns, strict=True):
        flt.update(float(-z), float(turn), 0.0)
    flt.belief()
    wheel_reach_for(cam, WheelJaw(5.0))
    # a drawing with a Bézier and corners: the arc inversion, the two-roll rules' sums (the fast ones and
    # the ones in logarithms)
    bezier = CubicBezier((60.0, 0.0), (75.0, 15.0), (75.0, 35.0), (60.0, 50.0))
    plate = outline_from_pieces(
        [Line((0.0, 0.0), (60.0, 0.0)), bezier, Line((60.0, 50.0), (0.0, 50.0)), Line((0.0, 50.0), (0.0, 0.0))],
        name="warm-up plate",
    )
    s = np.array([20.0, 45.0, 70.0])
    turns_plate = np.diff(plate.tangent_angle_at_arc(s))
    chain = tuple((25.0, float(w)) for w in turns_plate)
    localize(plate, chain, sd_length=0.5)
    chain_forward(plate, chain, 1.0, 0.5, math.radians(0.03), exact=True)
    return time.perf_counter() - t0
