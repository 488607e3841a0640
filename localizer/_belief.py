"""What a sequential filter believes about the present contact: the records it reports."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Belief", "Mode"]


@dataclass(frozen=True)
class Mode:
    """One separate mode of the belief over the present contact.

    Attributes
    ----------
    arc : float, mm
        Most probable present contact in the mode.
    mass : float
        Probability of the mode.
    start_arc : float, mm
        The corresponding start of the rolling.
    """

    arc: float
    mass: float
    start_arc: float


@dataclass(frozen=True)
class Belief:
    """What the filter believes about the present contact.

    Attributes
    ----------
    map_arc : float, mm
        The most probable present contact.
    mass : float
        Probability that the contact is within ``radius`` of ``map_arc``.
    radius : float, mm
    modes : tuple of Mode
        Separate modes, most probable first.
    ambiguous : bool
        More than one mode holds at least ``mode_floor`` of the probability and the
        first does not reach the confidence: the data cannot tell them apart (yet).
    informative : bool
        False when the posterior is as flat as the prior (e.g. on a circle).
    steps : int
        Updates so far.
    """

    map_arc: float
    mass: float
    radius: float
    modes: tuple[Mode, ...]
    ambiguous: bool
    informative: bool
    steps: int
