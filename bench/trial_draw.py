"""What every Monte Carlo trial draws first, from (seed, level, trial) alone: its generator, its part and
its noise model, and the head of its row. One place, so that the straight jaw's and the wheel's trials
draw the same part for the same seeds."""

from __future__ import annotations

from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from .part_cache import cached_part

__all__ = ["TrialDraw", "draw_trial"]


class TrialDraw(NamedTuple):
    """A trial's generator (the rest of its draws continue from it), its part file and part, its level's
    noise model, and the row's first columns."""

    rng: np.random.Generator
    part_file: str
    part: Any
    noise: Any
    row: dict


def draw_trial(spec) -> TrialDraw:
    """The first draws of trial ``spec`` (a :class:`bench.study.TrialSpec`): the generator
    ``SeedSequence([seed, level, trial])``, then the part."""
    s = spec.study
    rng = np.random.default_rng(np.random.SeedSequence([s.seed, spec.level, spec.trial]))
    part_file = s.parts[int(rng.integers(len(s.parts)))]
    row = {
        "level": spec.level,
        "trial": spec.trial,
        "parameter": s.parameter or "",
        "value": s.level_label(spec.level),
        "part": Path(part_file).name,
    }
    return TrialDraw(rng, part_file, cached_part(part_file), s.level_noise(spec.level), row)
