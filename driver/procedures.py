"""Calibration, contact, rolling and the localization pipeline, written once against ``Rig``.

Paper §III-B (calibration without weights: 11 taps from -50 to 50 mm on the
jaw, Δv1 held constant by feedback, a cubic spline of the ratio Δv2/Δv1
against contact location, read back by intersecting it) and §III-C (rolling:
rotate the jaw by a small angle about the tool axis, then translate along the
jaw normal until Δv1 is back at about 0.4 V).

Angles are radians, lengths mm, voltages V. Poses are (x, y, φ) as in
:class:`driver.rig.Rig`: pressing means moving along m = (-sin φ, cos φ).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from localizer import (
    BRIDGE_JUMP,
    ROLL_STEP,
    SD_LENGTH,
    SD_TURN,
    Boundary,
    Localization,
    Outline,
    Part,
    arc_from_jaw_positions,
    localize,
)

from .rig import (
    DEVICE_FAULTS,
    Clocked,
    ForceServo,
    GroundTruth,
    ImplausibleReading,
    ProtocolError,
    Reading,
    Rig,
    RigError,
    SampleLog,
    Truth,
)

__all__ = [
    "hold_force",
    "Calibration",
    "Hand",
    "RollResult",
    "RollingRun",
    "zero",
    "delta_voltages",
    "press",
    "establish_contact",
    "calibrate",
    "calibrate_simulated",
    "laid_off",
    "edge_offset",
    "roll",
    "roll_sequence",
    "localize_by_rolling",
    "ANGLE_SLACK",
    "MAX_ROLL_STEPS",
    "STEP_RANGE_DEG",
]


#: The most rolling steps one roll may take (at the paper's 0.2° step, 4000° of rolling): a step of
#: 1e-7° would otherwise roll for days.
MAX_ROLL_STEPS = 20_000
#: The rolling steps a command or a study may ask for, degrees: from a third of the arm encoder's 0.03°
#: count to 5° (beyond, the contact jumps past the readings the estimate needs).
STEP_RANGE_DEG = (0.01, 5.0)
#: How far the arm's reported jaw angle may be from the commanded one, rad: its encoder reads to 0.03°
#: and the arm settles within a step or two; a stuck encoder is off by 0.5° after three 0.2° steps.
ANGLE_SLACK = math.radians(0.5)


# ------------------------------------------------------------------ hand
class Hand:
    """The commanded hand pose, moved in the jaw's own frame.

    The arm's reading (``rig.pose()``) is quantized; commands are built from
    the commanded pose so that quantization does not accumulate.
    """

    def __init__(self, rig: Rig, pose):
        self.rig = rig
        self.pose = tuple(float(v) for v in pose)
        rig.move(*self.pose)

    def go(self, x, y, phi) -> None:
        self.pose = (float(x), float(y), float(phi))
        self.rig.move(*self.pose)

    def press_by(self, s: float) -> None:
        """Translate by ``s`` mm along the jaw normal towards the part."""
        x, y, phi = self.pose
        self.go(x - s * math.sin(phi), y + s * math.cos(phi), phi)

    def slide_by(self, s: float) -> None:
        """Translate by ``s`` mm along the jaw."""
        x, y, phi = self.pose
        self.go(x + s * math.cos(phi), y + s * math.sin(phi), phi)

    def rotate_by(self, angle: float) -> None:
        """Rotate by ``angle`` rad about the tool axis (the wrist's axis)."""
        x, y, phi = self.pose
        self.go(x, y, phi + angle)

    def measured_angle(self) -> float:
        """The arm's reported jaw angle, rad, checked against the commanded one: a stuck or misread
        encoder (or a reply of 1e308°) would otherwise be taken as the jaw's rotation and localize,
        confidently, somewhere else. Backs the jaw off and raises :class:`RigError` when they differ by
        more than :data:`ANGLE_SLACK`."""
        phi = float(self.rig.pose()[2])
        commanded = self.pose[2]
        if not (math.isfinite(phi) and abs(phi - commanded) <= ANGLE_SLACK):
            try:
                self.press_by(-5.0)
                backed = "the jaw was backed off 5 mm"
            except RigError as exc:
                backed = f"backing the jaw off failed too ({exc})"
            raise ImplausibleReading(
                f"the arm reports the jaw at {math.degrees(phi):.6g}° where {math.degrees(commanded):.6g}° was "
                f"commanded (more than {math.degrees(ANGLE_SLACK):g}° apart): its encoder is stuck or misread. "
                f"The roll was stopped and {backed}; check the arm before localizing"
            )
        return phi


# ------------------------------------------------------------ settings
@dataclass(frozen=True)
class ServoSettings:
    """Hold the force with the arm's own servo after every press (:func:`hold_force`).

    Attributes
    ----------
    gain : float
        Force-error gain (N/N).
    guard : bool
        With the passivity observer/controller on the servo's port.
    duration : float, s
        How long the servo holds.
    max_std : float or None, V
        Refuse a loop whose held Δv1 varies more than this (a ringing loop).
    """

    gain: float
    guard: bool = True
    duration: float = 0.3
    max_std: float | None = 0.05

    def __post_init__(self):
        if not (math.isfinite(self.gain) and self.gain > 0):
            raise RigError(f"servo gain={self.gain!r} must be a positive number")
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise RigError(f"servo duration={self.duration!r} s must be positive")


@dataclass(frozen=True)
class PressSettings:
    """How a press finds the force: translate along the jaw normal until Δv1 is at the target
    (paper §III-C). Every procedure that presses takes one (``pressing``).

    Attributes
    ----------
    tol : float, V
        Δv1 within this of the target ends the press.
    slope : float, V/mm
        First guess of dΔv1/d(press); refined from the readings (secant).
    search_step : float, mm
        Advance per reading while there is no contact yet.
    max_travel : float, mm
        Give up (RigError) after pressing this far without contact.
    overload : float, V
        Δv1 above this backs the jaw off and stops the run (wrist protection).
    max_steps : int
        Moves allowed to settle.
    servo : ServoSettings or None
        When given, the arm's own force servo then holds the target.
    """

    tol: float = 0.01
    slope: float = 0.4
    search_step: float = 0.25
    max_travel: float = 15.0
    overload: float = 2.0
    max_steps: int = 60
    servo: ServoSettings | None = None

    def __post_init__(self):
        for name in ("tol", "slope", "search_step", "max_travel", "overload"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise RigError(f"press {name}={value!r} must be a positive number")
        if self.max_steps < 1:
            raise RigError(f"press max_steps={self.max_steps!r} must be at least 1")


#: The paper's press: Δv1 back within 0.01 V of the target, no servo.
PRESS = PressSettings()


# ---------------------------------------------------------------- sensing
def zero(rig: Rig, n: int = 256) -> tuple:
    """The default readings (v1, v2) with the jaw clear of everything, V: the middle of three readings of
    ``n`` samples each, channel by channel, so that one spike of the DAQ does not shift every place read
    after it."""
    three = np.array([rig.read(n) for _ in range(3)], dtype=float)
    return float(np.median(three[:, 0])), float(np.median(three[:, 1]))


def delta_voltages(rig: Rig, baseline, n: int) -> tuple:
    """(Δv1, Δv2), V: the wrist's two channels averaged over ``n`` samples, against their ``baseline``
    (the jaw clear, :func:`zero`)."""
    v1, v2 = rig.read(n)
    return v1 - baseline[0], v2 - baseline[1]


def press(
    rig: Rig,
    hand: Hand,
    baseline,
    *,
    target: float = 0.4,
    n: int = 32,
    pressing: PressSettings = PRESS,
) -> tuple:
    """Translate along the jaw normal until Δv1 = ``target`` ± ``pressing.tol`` V (the paper's feedback).

    Parameters
    ----------
    rig : Rig
    hand : Hand
        The commanded pose, moved along the jaw normal.
    baseline : (float, float), V
        The wrist's readings with the jaw clear (:func:`zero`).
    target : float, V
        The Δv1 to reach.
    n : int
        Samples averaged per reading.
    pressing : PressSettings
        Tolerance, search, limits and the optional servo hold.

    Returns
    -------
    (dv1, dv2) : the last reading, V, relative to ``baseline``.
    """
    tol, slope, search_step = pressing.tol, pressing.slope, pressing.search_step
    max_travel, overload, max_steps, servo = pressing.max_travel, pressing.overload, pressing.max_steps, pressing.servo
    dv1, dv2 = delta_voltages(rig, baseline, n)
    travelled = 0.0
    threshold = 0.1 * target
    seen = {(dv1, dv2)}
    while dv1 < threshold:
        if travelled >= max_travel:
            dead = ""
            if len(seen) == 1:
                # a simulated wrist without noise reads exactly the same too, so this is a hint, not a
                # verdict; a dead sensor may have let the jaw into the part, so it goes back out
                hand.press_by(-travelled)
                dead = (
                    f". The wrist read exactly the same at all {round(travelled / search_step) + 1} readings while "
                    f"the jaw moved, and the jaw was moved back {travelled:.1f} mm: a real sensor's noise changes "
                    "every reading, so on a rig its DAQ or strain-gauge amplifier is not reading (check its wiring)"
                )
            raise RigError(
                f"no contact after pressing {travelled:.1f} mm along the jaw normal "
                f"(Δv1 = {dv1:.4g} V); start closer to the part{dead}"
            )
        hand.press_by(search_step)
        travelled += search_step
        dv1, dv2 = delta_voltages(rig, baseline, n)
        seen.add((dv1, dv2))
    prev = None
    for _ in range(max_steps):
        if dv1 > overload:
            hand.press_by(-max_travel)
            raise RigError(f"Δv1 = {dv1:.4g} V exceeds the overload limit {overload} V: backed off")
        if abs(dv1 - target) <= tol:
            if servo is not None:
                hold_force(
                    rig,
                    target=target,
                    gain=servo.gain,
                    guard=servo.guard,
                    duration=servo.duration,
                    max_std=servo.max_std,
                )
                dv1, dv2 = delta_voltages(rig, baseline, n)
            return dv1, dv2
        if prev is not None and abs(dv1 - prev[1]) > 4 * tol and prev[0] != 0:
            slope = max((dv1 - prev[1]) / prev[0], 0.05 * slope)
        move = float(np.clip((target - dv1) / slope, -1.0, 1.0))
        if dv1 < threshold:  # lost the contact: search forward again
            move = search_step
        hand.press_by(move)
        prev = (move, dv1)
        dv1, dv2 = delta_voltages(rig, baseline, n)
    raise RigError(f"Δv1 did not settle at {target} ± {tol} V in {max_steps} moves (last {dv1:.4g} V)")


def hold_force(
    rig: Rig,
    *,
    target: float = 0.4,
    gain: float = 2.0,
    guard: bool = True,
    duration: float = 0.5,
    max_std: float | None = None,
) -> dict:
    """Hold Δv1 = ``target`` V with the arm's own sampled force servo, optionally passivity-guarded.

    The paper's feedback (translate along the normal until Δv1 ≈ 0.4 V) as a
    1 kHz loop in the arm's controller rather than move-and-read steps from the
    host. On a stiff contact a high ``gain`` makes the bare loop ring or lose
    the part; ``guard`` puts the passivity observer/controller with both
    low-velocity fixes on the loop's port (docs/passivity.md).

    Parameters
    ----------
    target : float, V
    gain : float
        Force-error gain of the servo (N/N).
    guard : bool
    duration : float, s
    max_std : float or None, V
        Raise RigError when the held Δv1's standard deviation exceeds this (a ringing loop).

    Returns
    -------
    dict
        The rig's report: ``dv1``, ``dv1_std``, ``contact_lost``, ``min_energy``, ``guard``.
    """
    if not isinstance(rig, ForceServo):
        raise RigError(f"{type(rig).__name__} has no force servo; use press() (move-and-read)")
    report = rig.servo(target, gain, guard=guard, duration=duration)
    if report["contact_lost"] > 0:
        raise RigError(
            f"the force servo lost the part for {report['contact_lost']} samples at gain {gain:g} "
            f"(guard {'on' if guard else 'off'}); lower the gain or switch the guard on"
        )
    if max_std is not None and report["dv1_std"] > max_std:
        raise RigError(f"the force servo rings: Δv1 std {report['dv1_std']:.4f} V > {max_std} V at gain {gain:g}")
    return report


def establish_contact(
    rig: Rig, approach_pose, *, baseline=None, target: float = 0.4, n: int = 32, pressing: PressSettings = PRESS
):
    """Move to ``approach_pose`` (clear of the part), zero the sensor unless a ``baseline`` is given, press
    until Δv1 ≈ ``target`` V (``n`` samples a reading, as ``pressing`` says).

    Returns (hand, baseline, (dv1, dv2)).
    """
    hand = Hand(rig, approach_pose)
    if baseline is None:
        baseline = zero(rig)
    reading = press(rig, hand, baseline, target=target, n=n, pressing=pressing)
    return hand, baseline, reading


# ------------------------------------------------------------ calibration
@dataclass(frozen=True)
class Calibration:
    """Contact location on the jaw from the ratio Δv2/Δv1 (paper §III-B, Fig. 6a).

    Attributes
    ----------
    positions : tuple of float, mm
        Jaw positions of the taps.
    ratios : tuple of float
        Measured Δv2/Δv1 at each tap.
    target : float, V
        Δv1 held during the taps.
    jaw : str
        The finger calibrated (the paper's 100 mm jaw): refused for another.

    Examples
    --------
    A sensor whose ratio grows linearly along the jaw:

    >>> cal = Calibration(positions=(-50.0, -25.0, 0.0, 25.0, 50.0), ratios=(0.5, 0.75, 1.0, 1.25, 1.5))
    >>> round(cal.position(1.1), 6)
    10.0
    """

    positions: tuple
    ratios: tuple
    target: float = 0.4
    jaw: str = "straight:100"
    _r: np.ndarray = field(init=False, repr=False, compare=False)  # the ratios, ascending
    _d: np.ndarray = field(init=False, repr=False, compare=False)  # the positions in that order, mm

    def __post_init__(self):
        d = np.asarray(self.positions, float)
        r = np.asarray(self.ratios, float)
        if d.size < 4 or d.size != r.size or not np.all(np.isfinite(r)):
            raise RigError(f"calibration needs >= 4 finite (position, ratio) pairs, got {d.size} and {r.size}")
        if np.any(np.diff(d) <= 0):
            raise RigError("calibration positions must increase")
        grid = np.linspace(d[0], d[-1], 2001)
        rg = CubicSpline(d, r)(grid)
        steps = np.diff(rg)
        if not (np.all(steps < 0) or np.all(steps > 0)):
            k = int(np.argmax(np.sign(steps) != np.sign(steps[0])))
            raise RigError(
                f"calibration is not monotone near {grid[k]:.1f} mm on the jaw: a ratio there "
                "matches two contact locations; recalibrate with more averaging"
            )
        order = np.argsort(rg)
        object.__setattr__(self, "_r", rg[order])
        object.__setattr__(self, "_d", grid[order])

    def position(self, ratio: float) -> float:
        """Contact location (mm) for a ratio Δv2/Δv1, by intersecting the spline."""
        r = float(ratio)
        lo, hi = self._r[0], self._r[-1]
        margin = 0.02 * (hi - lo)
        if not (lo - margin <= r <= hi + margin):
            raise RigError(
                f"ratio Δv2/Δv1 = {r:.5f} is outside the calibrated range [{lo:.5f}, {hi:.5f}]: "
                f"the contact is beyond the calibrated span {self.positions[0]:.0f}..{self.positions[-1]:.0f} mm"
            )
        if r < lo or r > hi:  # a little beyond the ends: extrapolate the end slope
            j = (0, 1) if r < lo else (-2, -1)
            return float(
                self._d[j[0]] + (r - self._r[j[0]]) * (self._d[j[1]] - self._d[j[0]]) / (self._r[j[1]] - self._r[j[0]])
            )
        return float(np.interp(r, self._r, self._d))

    def save(self, path) -> None:
        """Write as JSON."""
        doc = {"jaw": self.jaw, "positions": list(self.positions), "ratios": list(self.ratios), "target": self.target}
        Path(path).write_text(json.dumps(doc, indent=2) + "\n")

    @classmethod
    def load(cls, path) -> Calibration:
        """Read a calibration written by :meth:`save`."""
        try:
            data = json.loads(Path(path).read_text())
            jaw = str(data.get("jaw", "straight:100"))  # files from before fingers were named: the paper's jaw
            if not jaw.startswith("straight"):
                raise ValueError(f"it is a calibration of a {jaw} finger, not of a straight jaw")
            return cls(tuple(data["positions"]), tuple(data["ratios"]), float(data.get("target", 0.4)), jaw)
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise RigError(f"calibration file {path}: {exc}") from None


def calibrate(
    rig: Rig,
    approach_pose,
    *,
    taps: int = 11,
    span: float = 50.0,
    target: float = 0.4,
    n: int = 256,
    backoff: float = 2.0,
    pressing: PressSettings = PRESS,
) -> Calibration:
    """Tap an immobilized object at ``taps`` jaw positions from -span to +span mm (paper §III-B).

    ``approach_pose`` faces the object's contact point with jaw position 0, clear of it.
    Before each tap the jaw slides along itself so that the same object point meets the
    jaw ``span/5`` mm further on; Δv1 is held at ``target`` by feedback while Δv2 is read.
    """
    x0, y0, phi = (float(v) for v in approach_pose)
    Hand(rig, (x0, y0, phi))
    baseline = zero(rig)  # clear of the object
    positions = np.linspace(-span, span, taps)
    ratios = []
    for d in positions:
        hand = Hand(rig, (x0 - d * math.cos(phi), y0 - d * math.sin(phi), phi))
        press(rig, hand, baseline, target=target, pressing=pressing)
        dv1, dv2 = delta_voltages(rig, baseline, n)
        ratios.append(dv2 / dv1)
        hand.press_by(-backoff - 1.0)
    return Calibration(tuple(float(v) for v in positions), tuple(float(v) for v in ratios), target)


def calibrate_simulated(part: Part | Outline, noise="none", *, seed: int = 0, engine: str = "kinematic") -> Calibration:
    """Calibrate a simulated wrist as the real one is calibrated (paper §III-B): a simulated rig of its own,
    seeded ``seed``, with the ``noise`` model and ``engine`` of :class:`sim2d.SimRig`, taps ``part`` at its
    most curved point that the whole jaw reaches (:func:`localizer.calibration_arc`)."""
    from sim2d import SimRig

    rig = SimRig(part, noise=noise, seed=seed, engine=engine)
    return calibrate(rig, rig.calibration_pose())


def laid_off(part: Boundary, first_contact: float, start: float, tolerance: float = 1.0) -> bool:
    """Whether a jaw laid at arc ``start`` (mm) on ``part`` first touched it elsewhere: at ``first_contact``
    (mm, a simulated rig's truth; NaN: not known) more than ``tolerance`` mm away. A straight jaw laid on a
    start off the convex hull touches the hull instead."""
    return math.isfinite(first_contact) and abs(float(part.arc_offset(first_contact, start))) > tolerance


# --------------------------------------------------------------- rolling
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
        at the working force, measured by :func:`edge_offset`); see below.
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
    positions: tuple
    angles: tuple
    largest_jump: float
    jaw_travel: float = 0.0
    offset: float = 0.0
    step: float = 0.0
    readings: tuple = ()
    truth: tuple = ()


def edge_offset(rig: Rig, hand: Hand, baseline, *, probe: float = 0.1, n: int = 64) -> float:
    """How far the wrist has given at the present force, mm: Δv1 over dΔv1/d(press).

    Presses ``probe`` mm in and out around the present pose (Δv1 is
    proportional to the give of a linear wrist) and returns to it.
    """
    here = delta_voltages(rig, baseline, n)[0]
    hand.press_by(probe)
    deeper = delta_voltages(rig, baseline, n)[0]
    hand.press_by(-2 * probe)
    shallower = delta_voltages(rig, baseline, n)[0]
    hand.press_by(probe)
    slope = (deeper - shallower) / (2 * probe)
    if not slope > 0:
        raise RigError(f"Δv1 did not grow when pressing (slope {slope:.4f} V/mm): no stable contact")
    return here / slope


def _clock(rig) -> float:
    """The rig's clock (s): a simulated rig's own time, else the process's monotonic clock."""
    return float(rig.time) if isinstance(rig, Clocked) else time.monotonic()


def _location(rig, baseline, calibration, n, readings=None, truth=None, hand=None):
    """Contact location on the jaw (mm) from one averaged reading; logs the reading."""
    dv1, dv2 = delta_voltages(rig, baseline, n)
    if readings is not None:
        x, y, phi_cmd = hand.pose if hand is not None else (math.nan,) * 3
        phi = hand.measured_angle() if hand is not None else rig.pose()[2]
        readings.append(Reading(dv1, dv2, phi, _clock(rig), x, y, phi_cmd))
        t = rig.truth() if isinstance(rig, GroundTruth) else {}
        truth.append(Truth(t.get("contact_arc", math.nan), t.get("jaw_position", math.nan)))
    if dv1 <= 0.1 * calibration.target:
        raise RigError(f"lost contact while rolling (Δv1 = {dv1:.4g} V)")
    return calibration.position(dv2 / dv1)


def roll(
    rig: Rig,
    hand: Hand,
    baseline,
    calibration: Calibration,
    angle: float,
    *,
    step: float = ROLL_STEP,
    n: int = 32,
    offset: float | None = None,
    bridge_jump: float | None = BRIDGE_JUMP,
    observer=None,
    index: int = 0,
    pressing: PressSettings = PRESS,
    faces: tuple[tuple[float, float], ...] = (),
) -> RollResult:
    """Roll by ``angle`` rad (positive: counter-clockwise) in steps of about ``step`` (paper §III-C).

    Each step rotates the jaw about the tool axis, then presses along the jaw
    normal until Δv1 is back at the calibration's level. ``offset`` (mm) is
    the tool axis's distance from the pressed edge (measured with
    :func:`edge_offset` when None; 0 gives the paper's estimate).

    A straight jaw cannot follow a concave stretch: it bridges it, the
    contact jumping along the jaw while the jaw does not turn. Such a roll
    measures the part's convex hull, not the part, so a step whose contact
    moves more than ``bridge_jump`` mm on the jaw stops the roll with
    :class:`RigError` (None: no check). On a part drawn with flat faces the jaw tipping over a face
    jumps as well: ``faces``, the part's (tangent angle rad, length mm) pairs
    (:attr:`localizer.Outline.faces`), tell it from a bridge (:func:`crossed_face`).

    ``observer``, if given, is called with a dict for the roll's start
    (``event="roll"``) and for every contact-location reading
    (``event="reading"``), as they happen (see :mod:`driver.runlog`); ``index``
    numbers the roll in those events.
    """
    if not (math.isfinite(angle) and angle != 0):
        raise RigError(f"roll angle {angle!r} rad must be finite and nonzero")
    if not step > 0:
        raise RigError(f"roll step {step!r} rad must be positive")
    k = max(1, int(round(abs(angle) / step)))
    if k > MAX_ROLL_STEPS:
        raise RigError(
            f"a roll of {math.degrees(angle):g}° in steps of {math.degrees(step):g}° is {k} steps, more than "
            f"{MAX_ROLL_STEPS}: use a larger step (refused before moving)"
        )
    if offset is None:
        offset = edge_offset(rig, hand, baseline)
    readings: list[Reading] = []
    truth: list[Truth] = []
    k_steps = k
    if observer is not None:
        observer(
            {
                "event": "roll",
                "roll": index,
                "angle": angle,
                "step": angle / k_steps,
                "steps": k_steps,
                "offset": float(offset),
            }
        )

    def observe(j):
        if observer is not None:
            r, t = readings[-1], truth[-1]
            observer(
                {
                    "event": "reading",
                    "roll": index,
                    "step": j,
                    "time": r.time,
                    "x": r.x,
                    "y": r.y,
                    "phi_command": r.phi_commanded,
                    "phi": r.phi,
                    "dv1": r.dv1,
                    "dv2": r.dv2,
                    "jaw_position": d[-1],
                    "true_arc": t.contact_arc,
                    "true_jaw_position": t.jaw_position,
                    "steps": k_steps,
                }
            )

    d = [_location(rig, baseline, calibration, n, readings, truth, hand)]
    observe(0)
    phis = [hand.measured_angle()]
    for j in range(k):
        hand.rotate_by(angle / k)
        press(rig, hand, baseline, target=calibration.target, n=n, pressing=pressing)
        try:
            d.append(_location(rig, baseline, calibration, n, readings, truth, hand))
        except DEVICE_FAULTS:
            raise  # a device fault, not a bridge
        except RigError:
            if bridge_jump is not None and j > 0:  # left the calibrated span in one jump
                hand.press_by(-5.0)
                raise RigError(
                    f"step {j + 1} of the roll bridged a concave stretch: the contact left the "
                    f"calibrated span from {d[-1]:.1f} mm in one step. A straight jaw touches the "
                    "convex hull there; start where the rolls stay on convex stretches"
                ) from None
            raise
        phis.append(hand.measured_angle())
        observe(j + 1)
        jump = abs(d[-1] - d[-2])
        if bridge_jump is not None and jump > bridge_jump and not crossed_face(faces, phis[-2], phis[-1], jump, j == 0):
            hand.press_by(-5.0)
            raise RigError(
                f"step {j + 1} of the roll bridged a concave stretch: the contact jumped "
                f"{abs(d[-1] - d[-2]):.1f} mm on the jaw (limit {bridge_jump} mm). A straight jaw "
                "touches the convex hull there; start where the rolls stay on convex stretches"
            )
    sign = 1.0 if angle > 0 else -1.0
    du = np.diff(d)
    return RollResult(
        length=arc_from_jaw_positions(d, angle / k, offset),
        turn=phis[-1] - phis[0],
        positions=tuple(d),
        angles=tuple(phis),
        largest_jump=float(np.abs(du).max()),
        jaw_travel=float(sign * (d[-1] - d[0])),
        offset=float(offset),
        step=angle / k,
        readings=tuple(readings),
        truth=tuple(truth),
    )


@dataclass(frozen=True)
class RollingRun:
    """Result of :func:`localize_by_rolling`.

    Attributes
    ----------
    rolls : tuple of RollResult
    estimates : tuple of (float, float)
        (L mm, Ω rad) of each roll, as given to the localizer.
    localization : Localization
    samples : list of dict
        The rig's log of readings (with ground truth on a simulated rig), if it keeps one.
    """

    rolls: tuple
    estimates: tuple
    localization: Localization
    samples: list = field(default_factory=list, repr=False)

    @property
    def estimate_arc(self) -> float:
        """The present contact's arc position on the part, mm (the best candidate's end)."""
        best = self.localization.best
        return float("nan") if best is None else best.end_arc

    def as_dict(self) -> dict:
        return {
            "estimates": [list(e) for e in self.estimates],
            "rolls": [asdict(r) for r in self.rolls],
            "estimate_arc": self.estimate_arc,
            "ambiguous": self.localization.ambiguous,
            "candidates": [c.as_dict() for c in self.localization.candidates],
        }


#: A face is crossed in a step whose jaw angles reach within this of the face's angle, rad (the arm
#: encoder's steps and the jaw's twist under load).
FACE_ANGLE_TOL = math.radians(0.1)
#: ... and whose jump matches the face's length within this, mm (the rolling on the fillets either side
#: in that step, the reading's error).
FACE_JUMP_TOL = 0.5


def crossed_face(faces, phi_from: float, phi_to: float, jump: float, first: bool) -> bool:
    """Whether a jump of ``jump`` mm along the jaw, in a step that turned it from ``phi_from`` to
    ``phi_to`` (rad), is the jaw tipping over one of ``faces`` ((tangent angle rad, length mm) pairs).

    The jaw lies flush on a face when its angle passes the face's: the contact then jumps the face's
    length (from where the piece before it ends to where the one after begins), or, in a roll's first
    step from a start laid flush on the face, at most that length. A bridge across a concavity jumps
    at other angles or by other lengths (over a notch between two collinear faces, by both and the
    notch).
    """
    span = phi_to - phi_from
    for angle, length in faces:
        off = (angle - phi_from + math.pi) % (2 * math.pi) - math.pi
        lo, hi = min(0.0, span), max(0.0, span)
        if not (lo - FACE_ANGLE_TOL <= off <= hi + FACE_ANGLE_TOL):
            continue
        if (jump <= length + FACE_JUMP_TOL) if first else (abs(jump - length) <= FACE_JUMP_TOL):
            return True
    return False


def roll_sequence(
    rig: Rig,
    rolls,
    *,
    calibration: Calibration,
    approach_pose,
    step: float = ROLL_STEP,
    n: int = 32,
    bridge_jump: float = BRIDGE_JUMP,
    observer=None,
    pressing: PressSettings = PRESS,
    faces: tuple[tuple[float, float], ...] = (),
) -> tuple:
    """Establish contact and roll by each angle of ``rolls`` (rad), all the same way; no localization.

    Returns the tuple of :class:`RollResult`. A roll that bridges a concave stretch is
    refused (:func:`roll`, ``bridge_jump``) with :class:`RigError` naming the roll; one that tips
    over one of ``faces`` is not.
    """
    rolls = [float(a) for a in rolls]
    if not rolls:
        raise RigError("rolls is empty: give at least one roll angle")
    if len({a > 0 for a in rolls}) != 1:
        raise RigError(f"rolls {rolls!r} must all turn the same way")
    hand, baseline, _ = establish_contact(rig, approach_pose, target=calibration.target, n=n, pressing=pressing)
    results = []
    for k, angle in enumerate(rolls):
        try:
            results.append(
                roll(
                    rig,
                    hand,
                    baseline,
                    calibration,
                    angle,
                    step=step,
                    n=n,
                    bridge_jump=bridge_jump,
                    observer=observer,
                    index=k,
                    pressing=pressing,
                    faces=faces,
                )
            )
        except RigError as exc:
            raise _in_roll(exc, k) from None
    return tuple(results)


def _in_roll(exc: RigError, k: int) -> RigError:
    """``exc`` said of roll ``k`` (0-based), of the same class (a device's refusal stays a
    :class:`ProtocolError`, an implausible reading an :class:`ImplausibleReading`)."""
    if isinstance(exc, ProtocolError):
        out: RigError = ProtocolError(exc.code, f"roll {k + 1}: {exc.message}", exc.seq)
    else:
        out = type(exc)(f"roll {k + 1}: {exc}")
    for note in getattr(exc, "__notes__", []):
        out.add_note(note)
    return out


def localize_by_rolling(
    rig: Rig,
    part: Part | Outline,
    rolls,
    *,
    calibration: Calibration,
    approach_pose,
    step: float = ROLL_STEP,
    n: int = 32,
    bridge_jump: float = BRIDGE_JUMP,
    rule: str = "likelihood",
    sd_length: float = SD_LENGTH,
    sd_turn: float = SD_TURN,
    observer=None,
    pressing: PressSettings = PRESS,
) -> RollingRun:
    """Establish contact, roll by each angle of ``rolls`` (rad), estimate (L, Ω), localize.

    All rolls turn the same way. Rolls that bridge a concave stretch are
    refused (:func:`roll`, ``bridge_jump``): the pipeline localizes on the part,
    never on its convex hull. On a drawing, rolls that tip over its faces are measured across them.
    """
    results = roll_sequence(
        rig,
        rolls,
        calibration=calibration,
        approach_pose=approach_pose,
        step=step,
        n=n,
        bridge_jump=bridge_jump,
        observer=observer,
        pressing=pressing,
        faces=part.faces if isinstance(part, Outline) else (),
    )
    estimates = tuple((r.length, r.turn) for r in results)
    for k, (length, turn) in enumerate(estimates):
        if not (math.isfinite(length) and length > 0):
            raise ImplausibleReading(
                f"roll {k + 1} measured a contact travel of {length:.4g} mm for a rotation of "
                f"{math.degrees(turn):+.3f}°: the contact cannot move against the rolling, so the wrist's zero "
                "drifted or its calibration is off; recalibrate (rolltouch calibrate) and roll again"
            )
    direction = "ccw" if results[0].step > 0 else "cw"
    loc = localize(part, estimates, rule=rule, direction=direction, sd_length=sd_length, sd_turn=sd_turn)
    return RollingRun(
        rolls=results,
        estimates=estimates,
        localization=loc,
        samples=list(rig.samples) if isinstance(rig, SampleLog) else [],
    )


def run_from_here(
    rig: Rig,
    part: Part | Outline,
    rolls,
    *,
    calibration: Calibration | None = None,
    slide: float = 40.0,
    observer=None,
    **options,
):
    """The whole job from the arm's present pose, as ``rolltouch run`` does it.

    The operator has jogged the jaw's centre to face the start point on the
    part, clear of it. Without a calibration the jaw first calibrates there
    (the part's own start point as the immobilized object, §III-B). Then the
    jaw slides ``slide`` mm along itself so that the contact starts near the
    end it rolls away from, establishes contact, rolls and localizes.

    Returns (RollingRun, Calibration).
    """
    rolls = [float(a) for a in rolls]
    if not rolls:
        raise RigError("rolls is empty: give at least one roll angle")
    here = tuple(rig.pose())
    if calibration is None:
        calibration = calibrate(rig, here)
        if observer is not None:
            observer(
                {
                    "event": "calibration",
                    "positions": list(calibration.positions),
                    "ratios": list(calibration.ratios),
                    "target": calibration.target,
                }
            )
        Hand(rig, here)
    x, y, phi = here
    s = slide if rolls[0] > 0 else -slide
    start = (x + s * math.cos(phi), y + s * math.sin(phi), phi)
    run = localize_by_rolling(
        rig, part, rolls, calibration=calibration, approach_pose=start, observer=observer, **options
    )
    return run, calibration
