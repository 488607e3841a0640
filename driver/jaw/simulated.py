"""A simulated rig calibrated as the real one is: the conveniences the simulated commands and the studies
share (driver's procedures themselves know only :class:`driver.rig.Rig`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from localizer import (
    Outline,
    Part,
)

from .calibration import Calibration, calibrate

if TYPE_CHECKING:
    from sim2d import NoiseModel

__all__ = ["calibrate_simulated"]


def calibrate_simulated(
    part: Part | Outline, noise: str | Path | NoiseModel = "none", *, seed: int = 0, engine: str = "kinematic"
) -> Calibration:
    """Calibrate a simulated wrist as the real one is calibrated (paper §III-B): a simulated rig of its own,
    seeded ``seed``, with the ``noise`` model and ``engine`` of :class:`sim2d.SimRig`, taps ``part`` at its
    most curved point that the whole jaw reaches (:func:`localizer.calibration_arc`)."""
    from sim2d import SimRig

    rig = SimRig(part, noise=noise, seed=seed, engine=engine)
    return calibrate(rig, rig.calibration_pose())
