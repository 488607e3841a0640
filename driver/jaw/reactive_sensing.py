"""What one reactive localization reads from the rig: the contact's place on the jaw, read again where
one reading jumped (a spike of the wrist's DAQ is one reading), the press back to the force, and the
jaw's turn so far."""

from __future__ import annotations

import math

import numpy as np

from ..rig import DEVICE_FAULTS, Reading, Rig, RigError, Truth
from .calibration import Calibration
from .hand import Hand, PressSettings, press
from .reactive_policy import ReactivePolicy
from .rolling import read_location

__all__ = ["JawReadings"]


class JawReadings:
    """The sensing of a reactive run (:class:`driver.jaw.reactive` rolls with it): the rig, the hand pressed
    on the part, the wrist's baseline and calibration, and every reading taken with its truth."""

    rig: Rig
    hand: Hand
    baseline: tuple[float, float]
    calibration: Calibration
    policy: ReactivePolicy
    pressing: PressSettings
    readings: list[Reading]
    truth: list[Truth]
    rereads: int
    phi0: float

    # ------------------------------------------------------------------ sensing
    def read(self) -> float:
        """The contact's place on the jaw now, mm (logs the reading)."""
        return read_location(
            self.rig, self.baseline, self.calibration, self.policy.n, self.readings, self.truth, self.hand
        )

    def read_or_inf(self) -> float:
        """:meth:`read`, or inf where the place read lies outside the calibrated span (a bridge, or a spike)."""
        try:
            return self.read()
        except DEVICE_FAULTS:
            raise
        except RigError:
            return math.inf

    def read_again(self, d: float) -> float:
        """A reading ``d`` (mm) that jumped (or fell outside the calibrated span: inf): read twice more at the
        same pose and keep the middle of the three, so that one spike of the wrist's DAQ is not taken for the
        contact's move (a real jump reads the same again)."""
        self.rereads += 1
        three = sorted([d, self.read_or_inf(), self.read_or_inf()])
        return float(three[1])

    def read_base(self) -> float:
        """A reading the next steps count from (the first contact, after a regrasp or a bridge undone): read
        twice, and a third time if the two differ by more than ``reread_jump``, keeping the middle, so that
        a spike does not shift every step after it."""
        a, b = self.read(), self.read()
        if abs(a - b) <= self.policy.reread_jump:
            return a
        self.rereads += 1
        return float(np.median([a, b, self.read()]))

    def pressed(self) -> bool:
        """Press back to the force; False when the press was refused (overload, no contact)."""
        try:
            press(
                self.rig,
                self.hand,
                self.baseline,
                target=self.calibration.target,
                n=self.policy.n,
                pressing=self.pressing,
            )
            return True
        except DEVICE_FAULTS:
            raise
        except RigError:
            return False

    def true_arc(self) -> float:
        return self.truth[-1].contact_arc if self.truth else math.nan

    def turn_now(self) -> float:
        return self.hand.measured_angle() - self.phi0
