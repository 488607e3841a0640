"""What the straight jaw's rolling returns: one roll's estimate (L, Ω) with the readings it was made from,
and a whole rolling run's rolls and localization."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from localizer import (
    Localization,
)

from ..rig import Reading, Truth

__all__ = ["RollResult", "RollingRun"]


@dataclass(frozen=True)
class RollResult:
    """One roll: the estimate (L, Ω) and what it was made from.

    Attributes
    ----------
    length : float, mm
        Contact travel on the jaw (eq. 3), from the calibrated contact locations.
    turn : float, rad
        Jaw rotation from the arm's encoder (eq. 4).
    positions : tuple of float, mm
        Contact location on the jaw before the roll and after each step.
    angles : tuple of float, rad
        The arm's reading of φ at the same moments.
    largest_jump : float, mm
        Largest change of contact location in one step (a bridge across a concavity
        shows as a jump).
    jaw_travel : float, mm
        The contact's travel on the jaw itself, signed in the rolling direction.
    offset : float, mm
        Distance of the tool axis from the pressed jaw edge (the wrist's give
        at the working force, measured by :func:`driver.jaw.edge_offset`); see below.
    step : float, rad
        The signed rotation of each step.
    readings : tuple of Reading
        The reading behind each contact location, with the arm's reading of φ,
        the time and the commanded hand pose.
    truth : tuple of Truth
        Ground truth at each reading (NaN on a real rig).

    Notes
    -----
    ``jaw_travel`` is the paper's estimate of L, the contact's travel on the
    jaw; ``length`` corrects it to second order in the step angle and for the
    tool axis's offset from the edge (:func:`localizer.arc_from_jaw_positions`).
    """

    length: float
    turn: float
    positions: tuple[float, ...]
    angles: tuple[float, ...]
    largest_jump: float
    jaw_travel: float = 0.0
    offset: float = 0.0
    step: float = 0.0
    readings: tuple[Reading, ...] = ()
    truth: tuple[Truth, ...] = ()


@dataclass(frozen=True)
class RollingRun:
    """Result of :func:`driver.jaw.localize_by_rolling`.

    Attributes
    ----------
    rolls : tuple of RollResult
    estimates : tuple of (float, float)
        (L mm, Ω rad) of each roll, as given to the localizer.
    localization : Localization
    samples : list of dict
        The rig's log of readings (with ground truth on a simulated rig), if it keeps one.
    """

    rolls: tuple[RollResult, ...]
    estimates: tuple[tuple[float, float], ...]
    localization: Localization
    samples: list[dict[str, Any]] = field(default_factory=list, repr=False)

    @property
    def estimate_arc(self) -> float:
        """The present contact's arc position on the part, mm (the best candidate's end)."""
        best = self.localization.best
        return float("nan") if best is None else best.end_arc

    def as_dict(self) -> dict[str, Any]:
        return {
            "estimates": [list(e) for e in self.estimates],
            "rolls": [asdict(r) for r in self.rolls],
            "estimate_arc": self.estimate_arc,
            "ambiguous": self.localization.ambiguous,
            "candidates": [c.as_dict() for c in self.localization.candidates],
        }
