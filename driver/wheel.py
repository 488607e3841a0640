"""Rolling a wheel finger and localizing with it (the physics in docs/wheel.md).

The hand pose (x, y, φ) is the axle's place and the hand's angle; the hand's axis m = (−sin φ, cos φ)
points at the part, as the straight jaw's normal does, so :func:`driver.procedures.press` presses a
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

:func:`localize_with_wheel` rolls one way, turning round at a jump, and gives the readings to a
:class:`localizer.WheelFilter` until it is sure (or the budget is spent). When nothing on the part fits
what was read (a jam that reads as rolling in a concave arc of the wheel's own radius), it retraces
its poses back to where that segment of rolling started and starts afresh there: away from the
segment's last jump when it had one (a jam wedges the disc at a mouth it then jumps across, so the way
the wheel turned to after that jump), else the other way.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from localizer import Belief, Outline, Part, WheelFilter, WheelJaw, wheel_reach_for

from .procedures import PRESS, Calibration, Hand, PressSettings, delta_voltages, press, zero
from .reactive import CONFIDENCE, MAX_ROTATION
from .rig import GroundTruth, Rig, RigError

__all__ = [
    "AxleEncoder",
    "WheelCalibration",
    "WheelPolicy",
    "WheelRun",
    "localize_with_wheel",
    "calibrate_wheel",
    "load_calibration",
    "check_calibration",
    "kappa_band",
    "corner_pivot",
    "wheel_calibration_arc",
    "CALIBRATION_LENGTH",
    "MAX_RESTARTS",
    "JUMP_FLOOR",
    "JUMP_MISMATCH",
    "WheelSlip",
]

#: A step's change of turn outside the part's turning over the rolled arc by this (rad) is a jump: 0.5°,
#: twenty times the wrist's residual direction.
JUMP_FLOOR = math.radians(0.5)
#: Times the rolling may start afresh after nothing fit its readings, before it stops "blocked".
MAX_RESTARTS = 2
#: Axle travel of a wheel's calibration (mm): the radius's error falls as its inverse.
CALIBRATION_LENGTH = 40.0
#: A step whose axle path and encoders disagree by more than this fraction of the step is a jump (slip
#: is gradual: a rim that loses this much in one step has lost the contact).
JUMP_MISMATCH = 0.25


class WheelSlip(RigError):
    """The wheel's rim slipped on the part beyond the policy's limit: its L readings are not the part's arc."""


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

    def as_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in asdict(self).items()}

    def save(self, path) -> None:
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


@dataclass(frozen=True)
class WheelRun:
    """Result of :func:`localize_with_wheel`.

    Attributes
    ----------
    belief : Belief
    rotation : float, rad
        The hand's turning, both ways counted.
    arc : float, mm
        Arc rolled, both ways counted.
    steps : int
    stopped : str
        "confident", "max_rotation", "max_arc", "blocked" (jumps both ways at one place, or again where the
        wheel jumped the same way before: enclosed) or "mismatch" (a stretch of the readings fits no probable
        place, or nothing fits after :data:`MAX_RESTARTS` fresh starts: the part is not its model,
        ``belief.mismatch`` says where when it can); slip beyond the policy's limit raises
        :class:`WheelSlip` instead.
    reversals, jumps : int
    slip : float, mm
        The rim's slip summed over the run (module notes, step 5).
    depth : float, mm
        The wrist's give at the target force (measured at the first press).
    history : tuple of (rotation rad, map_arc mm, mass, true_arc mm)
    lengths, turns, true_arcs : tuple of float
        Every reading's L (mm) and Ω (rad) since its segment's start, and the true contact (NaN on a
        real rig).
    segments : tuple of int
        Each reading's segment: the rolling retraces the last segment and starts afresh (a new
        segment, from (0, 0)) when nothing on the part fits its readings
        (:attr:`localizer.Belief.consistent`).
    """

    belief: Belief
    rotation: float
    arc: float
    steps: int
    stopped: str
    reversals: int
    jumps: int
    slip: float
    depth: float
    history: tuple = field(repr=False, default=())
    lengths: tuple = field(repr=False, default=())
    turns: tuple = field(repr=False, default=())
    true_arcs: tuple = field(repr=False, default=())
    segments: tuple = field(repr=False, default=())

    @property
    def restarts(self) -> int:
        """Times the rolling started afresh (module notes)."""
        return int(self.segments[-1]) if self.segments else 0

    @property
    def estimate_arc(self) -> float:
        return self.belief.map_arc


class _Wheel:
    """A wheel pressed on the part: the servo, the settled readings and one checked step (module notes)."""

    def __init__(
        self, rig, cal: WheelCalibration, policy: WheelPolicy, pressing: PressSettings, kappa_band, pivot: float = 0.0
    ):
        if not isinstance(rig, AxleEncoder):
            raise RigError(f"{type(rig).__name__} has no axle encoder: a wheel finger needs one (docs/wheel.md)")
        self.rig, self.cal, self.policy, self.pressing = rig, cal, policy, pressing
        self.kappa_band, self.pivot = kappa_band, float(pivot)

    def begin(self, approach_pose) -> tuple[float, float, float, float, float]:
        """Zero the wrist clear of the part, press from ``approach_pose``, measure the wrist's stiffness;
        the first settled state (φ, α, ψ_e, x, y)."""
        pol = self.policy
        self.hand = Hand(self.rig, approach_pose)
        self.baseline = zero(self.rig)
        dv1, _ = press(self.rig, self.hand, self.baseline, target=pol.target, n=pol.n, pressing=self.pressing)
        # the wrist's stiffness seen at the contact (V/mm): back off 0.2 mm and read again
        self.hand.press_by(-0.2)
        lighter, _ = self._read()
        self.hand.press_by(0.2)
        self.stiffness = max((dv1 - lighter) / 0.2, 1e-3)
        self.depth = pol.target / self.stiffness
        self.state = self.settled()
        return self.state

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

    def step(self, direction: int) -> tuple[float, float, float] | None:
        """Roll one step ``direction`` (+1: counter-clockwise); (ΔΩ rad, ΔL mm, the axle path's mismatch mm),
        or None after a jump, which is undone (the hand back where the step started)."""
        pol, r = self.policy, self.cal.radius
        before, prev = self.hand.pose, self.state
        x, y, phi = before
        self.hand.go(x + direction * pol.step * math.cos(phi), y + direction * pol.step * math.sin(phi), phi)
        now = self.settled()
        d_turn = (now[0] + now[1]) - (prev[0] + prev[1])
        d_len = r * ((now[2] - prev[2]) - (now[1] - prev[1]))
        path = _along(prev, now, self.cal.direction_zero)
        mismatch = path - (d_len + (r - self.depth) * d_turn)
        lo, hi = sorted((self.kappa_band[0] * d_len, self.kappa_band[1] * d_len))
        # on a convex corner the hand turns the rolling way with no arc rolled (the wheel pivots)
        if direction > 0:
            hi += self.pivot
        else:
            lo -= self.pivot
        if not (lo - JUMP_FLOOR <= d_turn <= hi + JUMP_FLOOR) or abs(mismatch) > JUMP_MISMATCH * pol.step:
            self.hand.go(*before)
            self.state = self.settled()
            return None
        self.state = now
        return d_turn, d_len, mismatch

    def truth(self) -> float:
        return float(self.rig.truth()["contact_arc"]) if isinstance(self.rig, GroundTruth) else math.nan


def calibrate_wheel(
    rig: Rig,
    wheel: WheelJaw,
    approach_pose,
    *,
    part: Part | Outline | None = None,
    length: float = CALIBRATION_LENGTH,
    policy: WheelPolicy = WheelPolicy(),
    pressing: PressSettings = PRESS,
) -> WheelCalibration:
    """Calibrate a wheel by rolling it ``length`` mm on anything smooth it fits (the part, a gauge block).

    What replaces the straight jaw's taps (docs/wheel.md): under pure rolling the commanded axle, pressed
    δ into the wrist, runs along the offset at r − δ, so each step's path (from the arm) is
    r·(Δψ_e + Δφ) − δ·ΔΩ along the surface's tangent, whatever the surface. With δ measured at the
    press (the wrist's stiffness), the summed path over the summed turning of the disc is the
    **effective radius**. The axle path's direction is the
    surface's tangent, so its chords against the force's direction give the channels' **mounting
    rotation** (the direction zero). The axle's place in the hand is taken from the drawing (the
    simulated hand's pose is the axle; not calibrated here).

    Parameters
    ----------
    rig : Rig with an axle encoder
    wheel : WheelJaw
        The finger, its nominal radius the first guess.
    approach_pose : (x mm, y mm, φ rad)
        Clear of a surface the wheel fits along ``length`` mm counter-clockwise (smooth, or with convex
        corners when ``part`` is a drawing).
    part : Part or Outline, optional
        The surface's model, to tell a jump from rolling (default: any curvature from −1/2r up); on a
        drawing the convex corners it reaches are pivoted on.
    length : float, mm
        Axle travel; the radius's error falls as 1/length.
    """
    if not (math.isfinite(length) and length > 0):
        raise RigError(f"calibration length={length!r} mm must be a positive number")
    band = kappa_band(part, wheel) if part is not None else (-0.5 / wheel.radius, math.inf)
    # a drawing's convex corner is pivoted on: path + δ·ΔΩ = r·(Δψ_e + Δφ) holds through it as well
    pivot = corner_pivot(part, wheel) if part is not None else 0.0
    disc = _Wheel(rig, WheelCalibration.nominal(wheel), policy, pressing, band, pivot)
    states = [disc.begin(approach_pose)]
    travelled = 0.0
    while travelled < length:
        if disc.step(+1) is None:
            raise RigError(
                f"the wheel jumped {travelled:.1f} mm into its calibration roll: calibrate on a smooth stretch "
                f"the {wheel} fits for {length:g} mm counter-clockwise"
            )
        travelled += math.hypot(disc.state[3] - states[-1][3], disc.state[4] - states[-1][4])
        states.append(disc.state)
    disc.hand.press_by(-(disc.depth + 2.0))  # off the surface, 2 mm clear
    st = np.asarray(states)
    phi, alpha, psi, x, y = st.T
    # chords of about 2 mm against the mean force direction at their ends
    m = max(1, int(round(2.0 / policy.step)))
    chord = np.arctan2(y[m:] - y[:-m], x[m:] - x[:-m])
    beta = phi + alpha
    mid = 0.5 * (beta[m:] + beta[:-m])
    zero = float(np.angle(np.mean(np.exp(1j * (chord - mid)))))
    path = _along(st[:-1].T, st[1:].T, zero)
    a = np.diff(psi) + np.diff(phi)
    b = np.diff(phi + alpha)
    # the ratio of the sums: each reading's encoder error telescopes (a fit step by step would count
    # the 12-bit encoder's quantization once per step, 0.006 mm at r = 10)
    radius = float((path.sum() + disc.depth * b.sum()) / a.sum())
    residual = float(np.sqrt(np.mean((path - radius * a + disc.depth * b) ** 2)))
    return WheelCalibration(
        jaw=str(wheel), radius=radius, direction_zero=zero, depth=disc.depth, residual=residual, steps=len(path)
    )


def load_calibration(path) -> Calibration | WheelCalibration:
    """Read a calibration file of either finger (:meth:`Calibration.save`, :meth:`WheelCalibration.save`)."""
    try:
        data = json.loads(Path(path).read_text())
        if not isinstance(data, dict):
            raise TypeError("not a JSON object")
        jaw = str(data.get("jaw", "straight:100"))
        if jaw.startswith("wheel"):
            nan = math.nan
            return WheelCalibration(
                jaw=jaw,
                radius=float(data["radius"]),
                direction_zero=float(data.get("direction_zero", 0.0)),
                depth=float(data["depth"]) if data.get("depth") is not None else nan,
                residual=float(data["residual"]) if data.get("residual") is not None else nan,
                steps=int(data.get("steps", 0)),
            )
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise RigError(f"calibration file {path}: {exc}") from None
    return Calibration.load(path)


def check_calibration(calibration: Calibration | WheelCalibration, finger) -> None:
    """Refuse a calibration made for another finger than ``finger`` (a StraightJaw or WheelJaw)."""
    jaw = calibration.jaw
    if jaw != str(finger):
        raise RigError(f"the calibration is for {jaw}, the finger is {finger}: calibrate this finger first")


def wheel_calibration_arc(part: Part | Outline, wheel: WheelJaw, length: float = CALIBRATION_LENGTH) -> float:
    """Where to calibrate a wheel on the part itself (mm): within the longest stretch the wheel surely
    reaches, ``length`` mm of it centred (at least 2 mm from its ends), which :func:`calibrate_wheel`
    rolls along counter-clockwise.

    Raises
    ------
    RigError
        No stretch the wheel surely reaches is ``length`` + 4 mm long: calibrate on a gauge block.
    """
    reach = wheel_reach_for(part, wheel)
    sure = np.asarray(reach.sure)
    if sure.all():
        return 0.0
    if not sure.any():
        raise RigError(f"a {wheel} surely touches {part.name} nowhere")
    k = int(np.flatnonzero(~sure)[0])
    rolled = np.roll(sure, -k)  # starts on a point it does not reach, so no run wraps
    starts = np.flatnonzero(~rolled[:-1] & rolled[1:]) + 1
    ends = np.flatnonzero(rolled[:-1] & ~rolled[1:]) + 1
    if rolled[-1]:
        ends = np.append(ends, rolled.size)
    best = int(np.argmax(ends - starts))
    run = (ends[best] - starts[best]) * reach.h
    if run < length + 4.0:
        raise RigError(
            f"the longest stretch of {part.name} a {wheel} surely reaches is {run:.1f} mm, less than the "
            f"calibration's {length:g} mm and 2 mm each side: calibrate on a gauge block"
        )
    return float(part.wrap_arc(reach.sigma[(starts[best] + k) % sure.size] + 0.5 * (run - length)))


def _along(a, b, zero: float = 0.0):
    """The axle's travel from state ``a`` to ``b`` (rows of (φ, α, ψ_e, x, y)) along the contact's mean
    tangent (mm, signed): the servo's force corrections move the axle along the normal too, which a
    chord's length would count (by n²/2t, a bias of a per cent of a step)."""
    beta = 0.5 * (np.asarray(a[0]) + np.asarray(a[1]) + np.asarray(b[0]) + np.asarray(b[1])) + zero
    return (np.asarray(b[3]) - np.asarray(a[3])) * np.cos(beta) + (np.asarray(b[4]) - np.asarray(a[4])) * np.sin(beta)


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


def localize_with_wheel(
    rig: Rig,
    part: Part | Outline,
    wheel: WheelJaw,
    *,
    approach_pose,
    calibration: WheelCalibration | None = None,
    filter: WheelFilter | None = None,
    policy: WheelPolicy = WheelPolicy(),
    pressing: PressSettings = PRESS,
    observer=None,
) -> WheelRun:
    """Roll the wheel from ``approach_pose`` until the contact is known (module notes).

    Parameters
    ----------
    rig : Rig with an axle encoder (:class:`AxleEncoder`)
    part : Part or Outline
        The part's model.
    wheel : WheelJaw
    approach_pose : (x mm, y mm, φ rad)
        Clear of the part, the hand's axis pointing at it.
    calibration : WheelCalibration, optional
        Default: the wheel's nominal radius, no mounting rotation.
    filter : WheelFilter, optional
        Default: ``WheelFilter(part, wheel)``.
    policy : WheelPolicy
    pressing : PressSettings
        The first press.
    observer : callable, optional
        Called with ``{"event": "reading", "length": mm, "turn": rad}`` at every step (the start's
        (0, 0) is implied) and ``{"event": "belief", ...}`` at every check.
    """
    cal = calibration if calibration is not None else WheelCalibration.nominal(wheel)
    cal.check(wheel)
    disc = _Wheel(rig, cal, policy, pressing, kappa_band(part, wheel), corner_pivot(part, wheel))
    flt = filter if filter is not None else WheelFilter(part, wheel)
    flt.reset()
    pol = policy
    max_arc = pol.max_arc if pol.max_arc is not None else float(part.perimeter)
    # the filter keeps a reading every ``thin`` mm rolled, up to its memory's max_readings: stop before
    max_arc = min(max_arc, (flt.max_readings - 1) * flt.thin)
    start = disc.begin(approach_pose)
    lengths, turns, truths, segments, history = [0.0], [0.0], [disc.truth()], [0], []
    flt.update(0.0, 0.0)
    direction, reversals, jumps, steps, segment = 1, 0, 0, 0, 0
    poses, segment_rotation = [disc.hand.pose], 0.0  # the settled poses of this segment, to retrace
    rotation = arc = slip = 0.0
    blocked: list[tuple[int, float]] = []  # (direction, L mm) of the jumps of this segment
    stopped = "max_rotation"
    while True:
        moved = disc.step(direction)
        if moved is None:
            flt.jumped(direction, margin=1.0 + pol.step)
            jumps += 1
            # a jump where the last one was (stuck), or where one the same way was before (the wheel enclosed
            # between two places it cannot pass: rolling on reads the same ground again)
            near = [(d, L) for d, L in blocked if abs(lengths[-1] - L) < 2 * pol.step]
            if near and (near[-1] == blocked[-1] or any(d == direction for d, _ in near)):
                stopped = "blocked"
                break
            blocked.append((direction, lengths[-1]))
            direction, reversals = -direction, reversals + 1
            continue
        d_turn, d_len, mismatch = moved
        slip += mismatch
        rotation += abs(d_turn)
        segment_rotation += abs(d_turn)
        arc += abs(d_len)
        steps += 1
        poses.append(disc.hand.pose)
        now = disc.state
        lengths.append(lengths[-1] + d_len)
        turns.append((now[0] + now[1]) - (start[0] + start[1]))
        truths.append(disc.truth())
        segments.append(segment)
        flt.update(lengths[-1], turns[-1])
        if observer is not None:
            observer({"event": "reading", "length": lengths[-1], "turn": turns[-1], "segment": segment})
        if abs(slip) > pol.max_slip + pol.max_slip_fraction * arc:
            raise WheelSlip(
                f"the wheel's rim slipped {slip:+.3f} mm over {arc:.1f} mm rolled (the axle's path against the "
                f"encoders, more than {pol.max_slip} mm + {pol.max_slip_fraction:.1%} of the arc): its readings "
                "are not the part's arc, so the rolling stopped with the wheel on the part. Clean the rim and "
                "the part, or press harder"
            )
        if steps % pol.check_every == 0:
            belief = flt.belief()
            history.append((rotation, belief.map_arc, belief.mass, truths[-1]))
            if observer is not None:
                observer({"event": "belief", "rotation": rotation, "arc": arc, "belief": belief})
            if belief.mismatch is not None:
                stopped = "mismatch"  # a stretch of the readings fits no probable place: never sure
                break
            if belief.mass >= pol.confidence:
                stopped = "confident"
                break
            if not belief.consistent:
                # nothing fits what was read since the segment's start: the wheel jammed where it read
                # as rolling. Retrace the segment's poses back to its start (the jam unwinds as it
                # was wound), and start afresh there, away from its last jump; twice at the most
                if segment >= MAX_RESTARTS:
                    stopped = "blocked"
                    break
                for pose in reversed(poses[:-1]):
                    disc.hand.go(*pose)
                disc.state = disc.settled()
                rotation += segment_rotation
                poses, segment_rotation = [disc.hand.pose], 0.0
                start, segment = disc.state, segment + 1
                flt.reset()
                flt.update(0.0, 0.0)
                lengths.append(0.0)
                turns.append(0.0)
                truths.append(disc.truth())
                segments.append(segment)
                # away from the segment's last jump (a jam wedges the disc at a mouth it then jumps across):
                # the way the wheel turned to after that jump, which it keeps; without a jump, the other way
                if not blocked:
                    direction, reversals = -direction, reversals + 1
                blocked = []
        if rotation >= pol.max_rotation:
            stopped = "max_rotation"
            break
        if arc >= max_arc:
            stopped = "max_arc"
            break
    final = flt.belief()
    if stopped in ("max_rotation", "max_arc") and final.sure(pol.confidence):
        stopped = "confident"  # the budget ran out between two checks, and the readings since made it sure
    if stopped != "confident" and (final.mismatch is not None or not final.consistent):
        stopped = "mismatch"
    return WheelRun(
        belief=final,
        rotation=rotation,
        arc=arc,
        steps=steps,
        stopped=stopped,
        reversals=reversals,
        jumps=jumps,
        slip=slip,
        depth=disc.depth,
        history=tuple(history),
        lengths=tuple(lengths),
        turns=tuple(turns),
        true_arcs=tuple(truths),
        segments=tuple(segments),
    )
