"""What the straight jaw's rolling returns: one roll's estimate (L, Ω) with the readings it was made from,
and a whole rolling run's rolls and localization."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from localizer import (
    Localization,
    arc_from_jaw_positions,
)

from ..rig import Reading, Truth

__all__ = ["RollResult", "RollingRun", "step_sequence"]


def step_sequence(rolls: Sequence[tuple[ArrayLike, ArrayLike, float, float]]) -> dict[str, NDArray[np.float64]]:
    """Fixed rolls as one step sequence, as the sequential filters take it.

    ``rolls``: per roll, the contact's places on the jaw before it and after each step (mm), the arm's φ at
    the same moments (rad), its step (rad, signed) and the jaw's edge offset (mm). Returns ``z`` (the
    cumulative signed arc, mm, 0 first), ``turn`` (the net measured turn since the first reading, rad),
    ``steps`` (each step's signed arc, mm) and ``jaw`` (the contact's place on the jaw at each reading, mm).
    """
    first_positions, first_angles = (np.asarray(v, dtype=float) for v in rolls[0][:2])
    z, turns, steps, jaw = [0.0], [0.0], [], [float(first_positions[0])]
    phi0 = float(first_angles[0])
    for positions, angles, step, offset in rolls:
        p, a = np.asarray(positions, dtype=float), np.asarray(angles, dtype=float)
        sign = 1.0 if step > 0 else -1.0
        for i in range(1, len(p)):
            arc = sign * arc_from_jaw_positions(p[i - 1 : i + 1], step, offset)
            steps.append(arc)
            z.append(z[-1] + arc)
            turns.append(float(a[i]) - phi0)
            jaw.append(float(p[i]))
    return {"z": np.array(z), "turn": np.array(turns), "steps": np.array(steps), "jaw": np.array(jaw)}


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
