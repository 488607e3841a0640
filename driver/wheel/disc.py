"""A wheel finger pressed on the part: its servo and one checked rolling step (the physics in docs/wheel.md).

The hand pose (x, y, φ) is the axle's place and the hand's angle; the hand's axis m = (−sin φ, cos φ)
points at the part, as the straight jaw's normal does, so :func:`driver.jaw.press` presses a
wheel too. Each rolling step:

1. moves the axle ``step`` mm along the hand's tangent e = (cos φ, sin φ) (times the direction);
2. servos the hand to the contact: reads the wrist's force direction α relative to the hand axis
   (atan2 of the two channels against their clear values, less the calibrated direction zero), turns
   the hand by α and moves the axle along the contact's direction until the force is back at the
   target, a few times, until |α| and the force error are small;
3. reads the arm's angle φ, the wrist's residual α and the axle encoder ψ_e. Since the start the
   part's tangent has turned by Ω = Δφ + Δα and the contact has travelled L = r·(Δψ_e − Δα) on the
   part (the encoder reads relative to the hand; r the calibrated radius);
4. checks the step: rolling on the part, the turn changes by κ times the arc rolled, κ within the
   curvatures of the stretches the wheel reaches (widened by half way to −1/r on the concave side,
   where a disc jammed between two walls reads exactly −1/r, and by half on the convex side), and on a
   drawing a turn the rolling way by up to the largest convex corner's jump the wheel reaches
   (:func:`corner_pivot`: it pivots there, L standing still). Outside that is the disc straddling a
   pocket or a concave corner it cannot enter, or jammed in one: a **jump**, undone (the hand goes back
   to the step's start, the filter told) and the direction turned round;
5. checks for **slip**: under pure rolling the commanded axle, pressed δ into the wrist, runs along
   the part's offset at r − δ, so its travel along the contact's tangent between two steps is
   L + (r − δ)·Ω of that step (along the tangent: the servo's force corrections move it along the
   normal too). A step
   that breaks this by a quarter of the step is a jump too (step 4); smaller differences summed over
   the run are the rim's slip (reported; beyond :attr:`WheelPolicy.max_slip` the rolling stops with
   :class:`WheelSlip`, as the L readings are no longer the part's arc).

:class:`WheelDisc` is that step, :class:`WheelPolicy` its settings and the rolling's, :class:`WheelCalibration`
the calibrated constants that turn its readings into (L, Ω) (:mod:`driver.wheel.calibration` finds them),
and :func:`localize_with_wheel` (:mod:`driver.wheel`) rolls with it.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Protocol, cast, overload, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from localizer import CONFIDENCE, Outline, Part, WheelJaw, wheel_reach_for

from ..jaw import MAX_ROTATION, Hand, PressSettings, delta_voltages, press, zero
from ..rig import GroundTruth, Rig, RigError

__all__ = [
    "AxleEncoder",
    "WheelCalibration",
    "WheelPolicy",
    "WHEEL_POLICY",
    "WheelDisc",
    "axle_travel",
    "kappa_band",
    "corner_pivot",
    "JUMP_FLOOR",
    "JUMP_MISMATCH",
]

#: A step's change of turn outside the part's turning over the rolled arc by this (rad) is a jump: 0.5°,
#: twenty times the wrist's residual direction.
JUMP_FLOOR = math.radians(0.5)
#: A step whose axle path and encoders disagree by more than this fraction of the step is a jump (slip
#: is gradual: a rim that loses this much in one step has lost the contact).
JUMP_MISMATCH = 0.25
#: How far the hand lifts the wheel off the part along the contact normal to press it again (mm): clear of
#: the wrist's give at the target force (about 1 mm) with room to zero the wrist.
RESEAT_LIFT = 3.0


@runtime_checkable
class AxleEncoder(Rig, Protocol):
    """A rig with a wheel finger: it also reads the disc's angle on its axle."""

    def axle(self) -> float:
        """The axle encoder: the disc's angle relative to the hand, rad (counting, not wrapped)."""
        ...


@dataclass(frozen=True)
class WheelCalibration:
    """What turns a wheel rig's readings into (L, Ω) (docs/wheel.md, calibration).

    Attributes
    ----------
    jaw : str
        The finger calibrated (``"wheel:5"``); a calibration is refused for another finger.
    radius : float, mm
        The wheel's effective rolling radius.
    direction_zero : float, rad
        The wrist channels' mounting rotation: subtracted from atan2(Δv2, Δv1).
    depth : float, mm
        The wrist's give at the target force, measured where it was calibrated (NaN: not measured).
    residual : float, mm
        RMS misfit of the axle path's steps to the rolling identity (NaN: not measured).
    steps : int
        Rolling steps the calibration used (0: the wheel's drawing).
    """

    jaw: str
    radius: float
    direction_zero: float = 0.0
    depth: float = math.nan
    residual: float = math.nan
    steps: int = 0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise RigError(f"wheel calibration radius={self.radius!r} mm must be a positive number")
        if not math.isfinite(self.direction_zero):
            raise RigError(f"wheel calibration direction_zero={self.direction_zero!r} rad must be finite")

    @classmethod
    def nominal(cls, wheel: WheelJaw) -> WheelCalibration:
        """The wheel's drawing: its nominal radius, no mounting rotation."""
        return cls(jaw=str(wheel), radius=wheel.radius)

    def check(self, wheel: WheelJaw) -> None:
        """Refuse this calibration for another finger."""
        if self.jaw != str(wheel):
            raise RigError(f"the calibration is for {self.jaw}, the finger is {wheel}: calibrate this finger first")

    def as_dict(self) -> dict[str, Any]:
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in asdict(self).items()}

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write as JSON (the finger named, so that it is refused for another)."""
        Path(path).write_text(json.dumps(self.as_dict(), indent=2) + "\n")


@dataclass(frozen=True)
class WheelPolicy:
    """How the wheel rolls and when it stops.

    Attributes
    ----------
    step : float, mm
        Axle travel per rolling step.
    target : float, V
        Contact force held, as the wrist's |Δv| (the straight jaw's 0.4 V).
    force_tol : float, V
    angle_tol : float, rad
        The servo ends when the force is within ``force_tol`` and |α| within this.
    servo_iterations : int
    check_every : int
        Steps between two looks at the belief.
    confidence : float
        Probability within the filter's radius that stops the rolling.
    max_rotation : float, rad
        Budget of the hand's turning, both ways counted.
    max_arc : float or None, mm
        Budget of rolled arc (default: the part's perimeter, and never more than the filter keeps:
        :attr:`localizer.WheelFilter.max_readings` readings, one every ``thin`` mm).
    max_slip : float, mm
        Summed slip beyond this plus ``max_slip_fraction`` of the arc rolled stops the rolling (the
        readings are no longer the part's arc).
    max_slip_fraction : float
        The part of the slip limit that grows with the arc rolled: the calibrated radius's relative error
        adds to the mismatch in proportion to it (measured up to 0.02% on the kidney and the trefoil at
        `paper` noise, r = 3 to 10 mm, 40 mm of calibration); ten times that is left to it.
    n : int
        Samples averaged per wrist reading.
    """

    step: float = 0.25
    target: float = 0.4
    force_tol: float = 0.02
    angle_tol: float = math.radians(0.005)
    servo_iterations: int = 6
    check_every: int = 4
    confidence: float = CONFIDENCE
    max_rotation: float = MAX_ROTATION
    max_arc: float | None = None
    max_slip: float = 0.1
    max_slip_fraction: float = 0.002
    n: int = 32

    def __post_init__(self) -> None:
        for name in ("step", "target", "force_tol", "angle_tol", "max_rotation", "max_slip"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise RigError(f"wheel policy {name}={v!r} must be a positive number")
        if not (math.isfinite(self.max_slip_fraction) and self.max_slip_fraction >= 0):
            raise RigError(f"wheel policy max_slip_fraction={self.max_slip_fraction!r} must be ≥ 0")
        if not 0 < self.confidence < 1:
            raise RigError(f"wheel policy confidence={self.confidence!r} must be in (0, 1)")
        if self.servo_iterations < 1 or self.check_every < 1 or self.n < 1:
            raise RigError("wheel policy servo_iterations, check_every and n must be at least 1")


#: The rolling as documented on :class:`WheelPolicy`.
WHEEL_POLICY = WheelPolicy()


class WheelDisc:
    """A wheel pressed on the part: the servo, the settled readings and one checked step (module notes)."""

    def __init__(
        self,
        rig: Rig,
        cal: WheelCalibration,
        policy: WheelPolicy,
        pressing: PressSettings,
        kappa_band: tuple[float, float],
        pivot: float = 0.0,
    ) -> None:
        if not isinstance(rig, AxleEncoder):
            raise RigError(f"{type(rig).__name__} has no axle encoder: a wheel finger needs one (docs/wheel.md)")
        self.rig, self.cal, self.policy, self.pressing = rig, cal, policy, pressing
        self.kappa_band, self.pivot = kappa_band, float(pivot)

    def begin(self, approach_pose: Iterable[float]) -> tuple[float, float, float, float, float]:
        """Zero the wrist clear of the part, press from ``approach_pose``, measure the wrist's stiffness along the
        contact's normal; the first settled state (φ, α, ψ_e, x, y)."""
        pol = self.policy
        self.hand = Hand(self.rig, approach_pose)
        self.baseline = zero(self.rig)
        dv1, _ = press(self.rig, self.hand, self.baseline, target=pol.target, n=pol.n, pressing=self.pressing)
        # the wrist's stiffness seen at the contact (V/mm): back off 0.2 mm and read again
        self.hand.press_by(-0.2)
        lighter, _ = self._read()
        self.hand.press_by(0.2)
        self.stiffness = max((dv1 - lighter) / 0.2, 1e-3)
        # and again along the contact's normal, once the servo has turned the hand to it: pressed on a slope (a
        # bump's flank) the hand's axis is not the normal, and the give read along it was 6-33% off, which the
        # axle's path then shows as the rim slipping wherever the hand turns
        _, a = self._settle()
        x, y, phi = self.hand.pose
        self.hand.go(*self._off_part(0.2, a), phi)
        lighter, _ = self._read()
        self.hand.go(x, y, phi)
        pressed, _ = self._read()
        self.stiffness = max((pressed - lighter) / 0.2, 1e-3)
        self.depth = pol.target / self.stiffness
        self.state = self.settled()
        return self.state

    def press_again(self) -> tuple[float, float, float, float, float]:
        """Lift the wheel :data:`RESEAT_LIFT` mm off the part along the contact normal and press it again there
        (:meth:`begin`: the wrist zeroed, its stiffness measured afresh; where the lifted wheel still touches, as it
        was); the settled state. After meeting what the model does not have: the first press may have been on it."""
        x, y, phi = self.hand.pose
        _, a = self._read()
        lifted = (*self._off_part(RESEAT_LIFT, a), phi + a)
        self.hand.go(*lifted)
        if self._read()[0] >= 0.1 * self.policy.target:
            # still touching (a concavity too narrow to lift clear in): the wrist cannot be zeroed here; keep its
            # zero and stiffness, and put the wheel back
            self.hand.go(x, y, phi)
            self.state = self.settled()
            return self.state
        return self.begin(lifted)

    def _off_part(self, distance: float, a: float) -> tuple[float, float]:
        """The axle's place ``distance`` mm farther off the part along the contact's normal (the wrist's force ``a``
        rad off the hand's axis), mm."""
        x, y, phi = self.hand.pose
        beta = phi + a
        return x + distance * math.sin(beta), y - distance * math.cos(beta)

    def _read(self) -> tuple[float, float]:
        """(|Δv| V, α rad) from the wrist."""
        dv1, dv2 = delta_voltages(self.rig, self.baseline, self.policy.n)
        return math.hypot(dv1, dv2), math.atan2(dv2, dv1) - self.cal.direction_zero

    def _settle(self) -> tuple[float, float]:
        """Servo the hand to the contact normal and the force to the target (module notes, step 2)."""
        pol = self.policy
        f, a = self._read()
        for _ in range(pol.servo_iterations):
            if abs(a) <= pol.angle_tol and abs(f - pol.target) <= pol.force_tol:
                break
            x, y, phi = self.hand.pose
            beta = phi + a
            if f < 0.1 * pol.target:  # clear of the part: press back along the hand's axis
                push = self.pressing.search_step
            else:
                push = float(np.clip((pol.target - f) / self.stiffness, -1.0, 1.0))
            self.hand.go(x - push * math.sin(beta), y + push * math.cos(beta), beta)
            f, a = self._read()
        if f < 0.1 * pol.target:
            raise RigError(f"the wheel lost the part (|Δv| = {f:.3g} V after the step): start again closer")
        return f, a

    def settled(self) -> tuple[float, float, float, float, float]:
        """(φ, α, ψ_e, x, y) after servoing the hand to the contact where it is now."""
        _, a = self._settle()
        x, y, _ = self.rig.pose()
        phi = float(self.hand.measured_angle())
        return phi, a, float(self.rig.axle()), float(x), float(y)

    def step(self, direction: int, through: bool = False) -> tuple[float, float, float] | None:
        """Roll one step ``direction`` (+1: counter-clockwise); (ΔΩ rad, ΔL mm, the axle path's mismatch mm),
        or None after a jump, which is undone (the hand back where the step started); ``through``: a jump is
        kept (the wheel rolls over what the model does not have)."""
        pol, r = self.policy, self.cal.radius
        before, prev = self.hand.pose, self.state
        x, y, phi = before
        self.hand.go(x + direction * pol.step * math.cos(phi), y + direction * pol.step * math.sin(phi), phi)
        now = self.settled()
        d_turn = (now[0] + now[1]) - (prev[0] + prev[1])
        d_len = r * ((now[2] - prev[2]) - (now[1] - prev[1]))
        path = axle_travel(prev, now, self.cal.direction_zero)
        mismatch = path - (d_len + (r - self.depth) * d_turn)
        lo, hi = sorted((self.kappa_band[0] * d_len, self.kappa_band[1] * d_len))
        # on a convex corner the hand turns the rolling way with no arc rolled (the wheel pivots)
        if direction > 0:
            hi += self.pivot
        else:
            lo -= self.pivot
        jumped = not (lo - JUMP_FLOOR <= d_turn <= hi + JUMP_FLOOR) or abs(mismatch) > JUMP_MISMATCH * pol.step
        if jumped and not through:
            self.hand.go(*before)
            self.state = self.settled()
            return None
        self.state = now
        return d_turn, d_len, mismatch

    def truth(self) -> float:
        return float(self.rig.truth()["contact_arc"]) if isinstance(self.rig, GroundTruth) else math.nan


@overload
def axle_travel(a: Sequence[float], b: Sequence[float], zero: float = 0.0) -> np.float64: ...
@overload
def axle_travel(a: NDArray[np.float64], b: NDArray[np.float64], zero: float = 0.0) -> NDArray[np.float64]: ...
def axle_travel(
    a: Sequence[float] | NDArray[np.float64], b: Sequence[float] | NDArray[np.float64], zero: float = 0.0
) -> np.float64 | NDArray[np.float64]:
    """The axle's travel from state ``a`` to ``b`` (rows of (φ, α, ψ_e, x, y)) along the contact's mean
    tangent (mm, signed): the servo's force corrections move the axle along the normal too, which a
    chord's length would count (by n²/2t, a bias of a per cent of a step)."""
    beta = 0.5 * (np.asarray(a[0]) + np.asarray(a[1]) + np.asarray(b[0]) + np.asarray(b[1])) + zero
    return cast(
        "np.float64 | NDArray[np.float64]",
        (np.asarray(b[3]) - np.asarray(a[3])) * np.cos(beta) + (np.asarray(b[4]) - np.asarray(a[4])) * np.sin(beta),
    )


def kappa_band(part: Part | Outline, wheel: WheelJaw) -> tuple[float, float]:
    """The curvatures (1/mm) a step of rolling on ``part`` may show: those of the stretches the wheel
    reaches, widened half way to −1/r on the concave side (a disc jammed between two walls reads exactly
    −1/r) and by half on the convex side (module notes, step 4)."""
    reach = wheel_reach_for(part, wheel)
    kappa = np.asarray(part.curvature_at_arc(reach.sigma[reach.reached]), dtype=float)
    lo, hi = float(kappa.min()), float(kappa.max())
    return lo - 0.5 * (lo + 1.0 / wheel.radius), hi + 0.5 * abs(hi)


def corner_pivot(part: Part | Outline, wheel: WheelJaw) -> float:
    """The most one step may turn the hand beyond rolling, the rolling way (rad): the largest jump of a
    convex corner of a drawing that the wheel reaches, on which it pivots (0 on a spline part)."""
    corners = [c for c in getattr(part, "corners", ()) if c.angle > 0]
    if not corners:
        return 0.0
    reach = wheel_reach_for(part, wheel)
    reached = reach.touchable(np.array([c.arc for c in corners]))
    return max((c.angle for c, ok in zip(corners, reached) if ok), default=0.0)
