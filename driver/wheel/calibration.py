"""Calibrating a wheel finger by rolling it on anything it fits, the part itself included (docs/wheel.md,
calibration): its effective radius and the wrist channels' mounting rotation."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from localizer import Finger, Outline, Part, WheelJaw, wheel_reach_for

from ..jaw import PRESS, Calibration, PressSettings
from ..rig import Rig, RigError
from .disc import WHEEL_POLICY, WheelCalibration, WheelDisc, WheelPolicy, axle_travel, corner_pivot, kappa_band

__all__ = ["calibrate_wheel", "load_calibration", "check_calibration", "wheel_calibration_arc", "CALIBRATION_LENGTH"]

#: Axle travel of a wheel's calibration (mm): the radius's error falls as its inverse.
CALIBRATION_LENGTH = 40.0


def calibrate_wheel(
    rig: Rig,
    wheel: WheelJaw,
    approach_pose: Iterable[float],
    *,
    part: Part | Outline | None = None,
    length: float = CALIBRATION_LENGTH,
    policy: WheelPolicy = WHEEL_POLICY,
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
    disc = WheelDisc(rig, WheelCalibration.nominal(wheel), policy, pressing, band, pivot)
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
    path = axle_travel(st[:-1].T, st[1:].T, zero)
    a = np.diff(psi) + np.diff(phi)
    b = np.diff(phi + alpha)
    # the ratio of the sums: each reading's encoder error telescopes (a fit step by step would count
    # the 12-bit encoder's quantization once per step, 0.006 mm at r = 10)
    radius = float((path.sum() + disc.depth * b.sum()) / a.sum())
    residual = float(np.sqrt(np.mean((path - radius * a + disc.depth * b) ** 2)))
    return WheelCalibration(
        jaw=str(wheel), radius=radius, direction_zero=zero, depth=disc.depth, residual=residual, steps=len(path)
    )


def load_calibration(path: str | os.PathLike[str]) -> Calibration | WheelCalibration:
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


def check_calibration(calibration: Calibration | WheelCalibration, finger: Finger) -> None:
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
