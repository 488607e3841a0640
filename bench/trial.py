"""One simulated trial of a study: what it needs (picklable, sent to worker processes) and which finger's
trial runs it (:mod:`bench.straight_trial`, :mod:`bench.wheel_trial`)."""

from __future__ import annotations

from typing import Any

from .trial_draw import TrialSpec

__all__ = ["run_trial"]


def run_trial(spec: TrialSpec) -> dict[str, Any]:
    """One simulated localization: calibrate, pick a start, roll, localize, score. Never raises.

    With the straight jaw (:mod:`bench.straight_trial`) the start is drawn where the fixed rolls can run;
    with a wheel (:mod:`bench.wheel_trial`) over the whole boundary instead; a study that names its finger
    gets the :data:`bench.columns.FINGER_COLUMNS` too.
    """
    if spec.study.level_jaw(spec.level).startswith("wheel"):
        from .wheel_trial import run_wheel_trial

        return run_wheel_trial(spec)
    from .straight_trial import run_straight_trial

    return run_straight_trial(spec)
