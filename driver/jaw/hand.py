"""The straight jaw's hand: moving it, pressing it on the part to the working force and holding it there,
and the wrist's voltages against their unloaded baseline (paper §III-B, §III-C).

Angles are radians, lengths mm, voltages V. Poses are (x, y, φ) as in :class:`driver.rig.Rig`: pressing
means moving along m = (-sin φ, cos φ)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..rig import (
    ForceServo,
    ImplausibleReading,
    Rig,
    RigError,
)

__all__ = [
    "ANGLE_SLACK",
    "Hand",
    "ServoSettings",
    "PressSettings",
    "PRESS",
    "zero",
    "delta_voltages",
    "press",
    "hold_force",
    "establish_contact",
    "edge_offset",
]


#: How far the arm's reported jaw angle may be from the commanded one, rad: its encoder reads to 0.03°
#: and the arm settles within a step or two; a stuck encoder is off by 0.5° after three 0.2° steps.
ANGLE_SLACK = math.radians(0.5)


class Hand:
    """The commanded hand pose, moved in the jaw's own frame.

    The arm's reading (``rig.pose()``) is quantized; commands are built from
    the commanded pose so that quantization does not accumulate.
    """

    def __init__(self, rig: Rig, pose: Iterable[float]) -> None:
        self.rig = rig
        self.pose: tuple[float, ...] = tuple(float(v) for v in pose)
        rig.move(*self.pose)

    def go(self, x: float, y: float, phi: float) -> None:
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

    def __post_init__(self) -> None:
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

    def __post_init__(self) -> None:
        for name in ("tol", "slope", "search_step", "max_travel", "overload"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise RigError(f"press {name}={value!r} must be a positive number")
        if self.max_steps < 1:
            raise RigError(f"press max_steps={self.max_steps!r} must be at least 1")


#: The paper's press: Δv1 back within 0.01 V of the target, no servo.
PRESS = PressSettings()


def zero(rig: Rig, n: int = 256) -> tuple[float, float]:
    """The default readings (v1, v2) with the jaw clear of everything, V: the middle of three readings of
    ``n`` samples each, channel by channel, so that one spike of the DAQ does not shift every place read
    after it."""
    three = np.array([rig.read(n) for _ in range(3)], dtype=float)
    return float(np.median(three[:, 0])), float(np.median(three[:, 1]))


def delta_voltages(rig: Rig, baseline: tuple[float, float], n: int) -> tuple[float, float]:
    """(Δv1, Δv2), V: the wrist's two channels averaged over ``n`` samples, against their ``baseline``
    (the jaw clear, :func:`zero`)."""
    v1, v2 = rig.read(n)
    return v1 - baseline[0], v2 - baseline[1]


def press(
    rig: Rig,
    hand: Hand,
    baseline: tuple[float, float],
    *,
    target: float = 0.4,
    n: int = 32,
    pressing: PressSettings = PRESS,
) -> tuple[float, float]:
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
) -> dict[str, Any]:
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
    rig: Rig,
    approach_pose: Iterable[float],
    *,
    baseline: tuple[float, float] | None = None,
    target: float = 0.4,
    n: int = 32,
    pressing: PressSettings = PRESS,
) -> tuple[Hand, tuple[float, float], tuple[float, float]]:
    """Move to ``approach_pose`` (clear of the part), zero the sensor unless a ``baseline`` is given, press
    until Δv1 ≈ ``target`` V (``n`` samples a reading, as ``pressing`` says).

    Returns (hand, baseline, (dv1, dv2)).
    """
    hand = Hand(rig, approach_pose)
    if baseline is None:
        baseline = zero(rig)
    reading = press(rig, hand, baseline, target=target, n=n, pressing=pressing)
    return hand, baseline, reading


def edge_offset(rig: Rig, hand: Hand, baseline: tuple[float, float], *, probe: float = 0.1, n: int = 64) -> float:
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
