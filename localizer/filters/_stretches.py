"""A part that is not its model: the stretches of readings a belief must not rest on, the fit test's
settings, and what it reports (the straight jaw's :class:`~localizer.ContactFilter` and the wheel's
:class:`~localizer.WheelFilter`; docs/filter.md and docs/robustness.md)."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._types import FloatArray, IntArray

__all__ = [
    "DEFECT_WINDOW",
    "UNEXPLAINED",
    "FIT_WIDTH",
    "JUMP_READING",
    "FIT_MIN_READINGS",
    "FIT_EVERY",
    "FIT_RATIO",
    "FIT_STARTS",
    "MAX_QUARANTINE",
    "NOISE_FIT_LIMIT",
    "Misfit",
    "stretch_windows",
]

#: The rolled arc, mm, of a stretch of readings the belief must not rest on alone, and of the stretches
#: the fit test judges (docs/filter.md, "A part that is not its model"): the straight jaw reads a burr's
#: crest or a dent's rims over a few millimetres (it jumps across the rest); longer costs clean parts
#: their sure stops (docs/filter.md, "How the settings were chosen").
DEFECT_WINDOW = 6.0
#: A bridge the belief gave less than this probability when it came is one the part's model does not
#: explain (:meth:`ContactFilter.bridged`).
UNEXPLAINED = 0.01
#: The stretches the fit test judges and quarantines, in units of ``defect_window``: a burr's misfit
#: goes on past its crest (the slope term and the offset carry it a little), which a stretch twice the
#: envelope's takes whole.
FIT_WIDTH = 2.0
#: A reading whose arc moved more than this (mm) beyond what the model's radius there makes of the turn
#: since the one before came after a jump: the fit test leaves it out (a face crossed in one step, a dip
#: bridged: the model's approximation of the jump).
JUMP_READING = 1.0
#: Readings a fit test needs outside the stretch it judges (fewer cannot tell misfit from noise).
FIT_MIN_READINGS = 20
#: Readings between two fit tests while the belief is not sure (a test before every sure stop too).
FIT_EVERY = 25
#: How many times the rest's misfit per reading (against its expectation) a stretch's must be to count
#: as not fitting: above what clean machined parts at the `paper` preset show (docs/filter.md).
FIT_RATIO = 6.0
#: The most probable starts a fit test judges the readings under (besides each strong mode's best): a
#: misfit is the part's only if none of them fits.
FIT_STARTS = 8
#: How many stretches that do not fit a filter takes out of its likelihood (one burr and the edge of
#: another, or both rims of a dent); it stops testing after that.
MAX_QUARANTINE = 3
#: The noise scale (the factor on the noise settings the readings say, :meth:`ContactFilter.noise_scale`)
#: beyond which they say nothing of where the contact is: the belief states no probability. The fit test is
#: a ratio of a stretch's misfit to the rest's and passes readings that misfit a start all along, which a
#: wrong start can then explain by noise many times the rig's (a corner's pivot, after a burr under the
#: start ruled the true one out). Twice the largest untold noise the filter is meant to meet (four times the
#: noise model); the tuning family at ×5.6 reaches at most 6.9 (docs/robustness.md, "Readings that fit
#: only as noise").
NOISE_FIT_LIMIT = 8.0


class Misfit(NamedTuple):
    """Where the readings stopped fitting the part (:meth:`ContactFilter.fit_test`).

    Attributes
    ----------
    arcs : (float, float), mm
        The stretch on the model, from the first to the last arc position (counter-clockwise), of the
        contact under the most probable start over the readings that do not fit.
    travel : (float, float), mm
        The same stretch in the rolled arc the readings were given with.
    p_value : float
        How likely a misfit this large is from readings that do fit (before the correction for the
        number of stretches tried).
    start : float, mm
        The start of the rolling under which it was judged.
    rows : tuple of int
        The readings of the stretch (in the order given, 0 the first). In :attr:`ContactFilter.misfits`, the
        readings taken out of the likelihood for it: the stretch whose absence lets some start fit best, or
        this one's own where the test found the same stretch before.
    rms_mm : float, mm
        How far off the model the stretch's readings are, root mean square (as the noise the filter was
        told would put them).
    """

    arcs: tuple[float, float]
    travel: tuple[float, float]
    p_value: float
    start: float
    rows: tuple[int, ...] = ()
    rms_mm: float = math.nan


def stretch_windows(arcs: FloatArray, width: float) -> list[tuple[float, IntArray]]:
    """The stretches of ``width`` mm of rolled arc over readings at rolled arcs ``arcs`` (mm), overlapping by
    three quarters, so that a stretch up to three quarters of ``width`` lies inside one: (where each
    begins, mm, and the positions of its readings in ``arcs``), each set of readings once."""
    arcs = np.asarray(arcs, dtype=float)
    out, seen = [], set()
    for a in np.arange(float(arcs.min()) - 0.75 * width, float(arcs.max()) + 1e-9, 0.25 * width):
        inside = np.flatnonzero((arcs >= a) & (arcs <= a + width))
        key = (int(inside[0]), int(inside[-1])) if inside.size else (-1, -1)
        if inside.size and key not in seen:
            seen.add(key)
            out.append((float(a), inside))
    return out
