"""What every Monte Carlo trial draws first, from (seed, level, trial) alone: its generator, its part and
its noise model, and the head of its row. One place, so that the straight jaw's and the wheel's trials
draw the same part for the same seeds."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from .part_cache import cached_part

if TYPE_CHECKING:
    from localizer import ContactFilter, Outline, Part
    from sim2d import NoiseModel, WorldChange

    from .study import Study


__all__ = ["TrialSpec", "TrialDraw", "draw_trial", "draw_world"]


@dataclass(frozen=True)
class TrialSpec:
    """Everything one trial needs (picklable, sent to worker processes): the study, the level and the
    trial's number, and the reactive method's filter class (None: :class:`localizer.ContactFilter`;
    :mod:`bench.replay` records the filter's calls with a subclass of it).
    """

    study: Study
    level: int
    trial: int
    filter_class: type[ContactFilter] | None = None


class TrialDraw(NamedTuple):
    """A trial's generator (the rest of its draws continue from it), its part file and part, its level's
    noise model, and the row's first columns."""

    rng: np.random.Generator
    part_file: str
    part: Part | Outline
    noise: NoiseModel
    row: dict[str, Any]


def draw_trial(spec: TrialSpec) -> TrialDraw:
    """The first draws of trial ``spec`` (a :class:`bench.trial.TrialSpec`): the generator
    ``SeedSequence([seed, level, trial])``, then the part."""
    s = spec.study
    rng = np.random.default_rng(np.random.SeedSequence([s.seed, spec.level, spec.trial]))
    part_file = s.parts[int(rng.integers(len(s.parts)))]
    row: dict[str, Any] = {
        "level": spec.level,
        "trial": spec.trial,
        "parameter": s.parameter or "",
        "value": s.level_label(spec.level),
        "part": Path(part_file).name,
    }
    return TrialDraw(rng, part_file, cached_part(part_file), s.level_noise(spec.level), row)


def draw_world(spec: TrialSpec, part_file: str, part: Part | Outline, start: float) -> WorldChange | None:
    """The world of trial ``spec`` (its study's ``[world]`` table, :meth:`sim2d.WorldSpec.draw`) for a
    rolling that starts at ``start`` mm on ``part``, from a stream of its own
    (``SeedSequence([seed, level, trial, 2])``): the trial's other draws are the same in every world,
    so a study with a ``[world]`` table runs the same trials as one without. None without the table."""
    s = spec.study
    if s.world is None:
        return None
    rng = np.random.default_rng(np.random.SeedSequence([s.seed, spec.level, spec.trial, 2]))
    return s.world.draw(part, start, rng, s.parts.index(part_file))
