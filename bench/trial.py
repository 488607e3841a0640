"""One simulated trial of a study, down the floors once: draw its context (:mod:`bench.trial_context`),
roll with its finger (:mod:`bench.straight_trial` or :mod:`bench.wheel_trial`), score its methods
(:mod:`bench.methods`), and write its row (:mod:`bench.columns`)."""

from __future__ import annotations

import time
from typing import Any

from driver import one_blas_thread

from .columns import trial_row
from .methods import score_trial
from .straight_trial import roll_straight
from .trial_context import TrialSpec, draw_trial
from .wheel_trial import roll_wheel

__all__ = ["TrialSpec", "run_trial"]


def run_trial(spec: TrialSpec) -> dict[str, Any]:
    """One simulated localization: calibrate, pick a start, roll, localize, score; its trials.csv row.
    Never raises: a failure is the row's ``failure``.

    With the straight jaw (:func:`bench.straight_trial.roll_straight`) the start is drawn where the fixed
    rolls can run; with a wheel (:func:`bench.wheel_trial.roll_wheel`) over the whole boundary instead.
    """
    t0 = time.perf_counter()
    with one_blas_thread():  # in whichever process runs it: a pool's or a Dask worker
        ctx = draw_trial(spec)
        rolled = roll_wheel(ctx) if ctx.jaw.startswith("wheel") else roll_straight(ctx)
        scored = score_trial(ctx, rolled)
    return trial_row(ctx.head, rolled, scored, time.perf_counter() - t0, world=ctx.world is not None)
