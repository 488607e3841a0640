"""What a Monte Carlo trial draws first and every floor of it reads: the trial's spec (picklable, sent to
worker processes) and its context, drawn from (seed, level, trial) alone."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .columns import TrialHead

if TYPE_CHECKING:
    from localizer import ContactFilter, Outline, Part
    from sim2d import NoiseModel, WorldSpec

    from .study import Study


__all__ = ["TrialSpec", "TrialContext", "cached_part", "draw_trial"]


@functools.cache
def cached_part(path: str) -> Part | Outline:
    """The part file at ``path``, read once per worker process (every trial of a study asks), its tables kept
    with it."""
    from localizer import load_part

    return load_part(path)


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


@dataclass(frozen=True)
class TrialContext:
    """What a trial draws first, from (seed, level, trial) alone, and every floor below reads.

    Attributes
    ----------
    spec : TrialSpec
    study : Study
        ``spec.study``.
    rng : numpy.random.Generator
        ``SeedSequence([seed, level, trial])`` after the part was drawn: the finger's draws continue it.
    part_file, part : str, Part or Outline
        The part drawn, and its index in the study's ``parts`` (its world part's index too).
    part_index : int
    noise : sim2d.NoiseModel
        The level's noise model.
    jaw : str
        The level's finger (:func:`localizer.parse_jaw`).
    world : sim2d.WorldSpec or None
        The study's ``[world]`` table (None: the world is the model).
    world_rng : numpy.random.Generator
        ``SeedSequence([seed, level, trial, 2])``: the world's own stream, so that a study with a
        ``[world]`` table runs the same trials as one without.
    head : TrialHead
        The row's first cells.
    """

    spec: TrialSpec
    study: Study
    rng: np.random.Generator
    part_file: str
    part_index: int
    part: Part | Outline
    noise: NoiseModel
    jaw: str
    world: WorldSpec | None
    world_rng: np.random.Generator
    head: TrialHead


def draw_trial(spec: TrialSpec) -> TrialContext:
    """The first draws of trial ``spec``: the generator ``SeedSequence([seed, level, trial])``, then the
    part; the straight jaw's and the wheel's trials draw the same part for the same seeds."""
    s = spec.study
    rng = np.random.default_rng(np.random.SeedSequence([s.seed, spec.level, spec.trial]))
    index = int(rng.integers(len(s.parts)))
    part_file = s.parts[index]
    part = cached_part(part_file)
    label, noise, jaw = s.level_label(spec.level), s.level_noise(spec.level), s.level_jaw(spec.level)
    head: TrialHead = {
        "level": spec.level,
        "trial": spec.trial,
        "parameter": s.parameter or "",
        "value": label,
        "part": Path(part_file).name,
    }
    return TrialContext(
        spec=spec,
        study=s,
        rng=rng,
        part_file=part_file,
        part_index=index,
        part=part,
        noise=noise,
        jaw=jaw,
        world=s.world,
        world_rng=np.random.default_rng(np.random.SeedSequence([s.seed, spec.level, spec.trial, 2])),
        head=head,
    )
