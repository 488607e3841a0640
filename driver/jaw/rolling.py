"""Rolling the straight jaw on the part and localizing from the rolls (paper §III-C): rotate the jaw by a
small angle about the tool axis, press back to the force, read the contact's place on the jaw; a jump
along the jaw is a bridge across a concavity. The pipeline: establish contact, roll, localize.

Angles are radians, lengths mm, voltages V."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from typing import Any, cast

import numpy as np

from localizer import (
    BRIDGE_JUMP,
    ROLL_STEP,
    SD_LENGTH,
    SD_TURN,
    Boundary,
    Outline,
    Part,
    arc_from_jaw_positions,
    localize,
)

from ..rig import (
    DEVICE_FAULTS,
    Clocked,
    GroundTruth,
    ImplausibleReading,
    ProtocolError,
    Reading,
    Rig,
    RigError,
    SampleLog,
    Truth,
)
from .calibration import Calibration, calibrate
from .hand import (
    PRESS,
    Hand,
    PressSettings,
    delta_voltages,
    edge_offset,
    establish_contact,
    press,
)
from .roll_result import RollingRun, RollResult

__all__ = [
    "MAX_ROLL_STEPS",
    "STEP_RANGE_DEG",
    "laid_off",
    "read_location",
    "roll",
    "FACE_ANGLE_TOL",
    "FACE_JUMP_TOL",
    "crossed_face",
    "roll_sequence",
    "localize_by_rolling",
    "run_from_here",
]


#: The most rolling steps one roll may take (at the paper's 0.2° step, 4000° of rolling): a step of
#: 1e-7° would otherwise roll for days.
MAX_ROLL_STEPS = 20_000


#: The rolling steps a command or a study may ask for, degrees: from a third of the arm encoder's 0.03°
#: count to 5° (beyond, the contact jumps past the readings the estimate needs).
STEP_RANGE_DEG = (0.01, 5.0)


def laid_off(part: Boundary, first_contact: float, start: float, tolerance: float = 1.0) -> bool:
    """Whether a jaw laid at arc ``start`` (mm) on ``part`` first touched it elsewhere: at ``first_contact``
    (mm, a simulated rig's truth; NaN: not known) more than ``tolerance`` mm away. A straight jaw laid on a
    start off the convex hull touches the hull instead."""
    return math.isfinite(first_contact) and abs(float(part.arc_offset(first_contact, start))) > tolerance


def _clock(rig: Rig) -> float:
    """The rig's clock (s): a simulated rig's own time, else the process's monotonic clock."""
    return float(rig.time) if isinstance(rig, Clocked) else time.monotonic()


def read_location(
    rig: Rig,
    baseline: tuple[float, float],
    calibration: Calibration,
    n: int,
    readings: list[Reading] | None = None,
    truth: list[Truth] | None = None,
    hand: Hand | None = None,
) -> float:
    """Contact location on the jaw (mm) from one averaged reading; logs the reading."""
    dv1, dv2 = delta_voltages(rig, baseline, n)
    if readings is not None:
        x, y, phi_cmd = hand.pose if hand is not None else (math.nan,) * 3
        phi = hand.measured_angle() if hand is not None else rig.pose()[2]
        readings.append(Reading(dv1, dv2, phi, _clock(rig), x, y, phi_cmd))
        t = rig.truth() if isinstance(rig, GroundTruth) else {}
        cast("list[Truth]", truth).append(Truth(t.get("contact_arc", math.nan), t.get("jaw_position", math.nan)))
    if dv1 <= 0.1 * calibration.target:
        raise RigError(f"lost contact while rolling (Δv1 = {dv1:.4g} V)")
    return calibration.position(dv2 / dv1)


def roll(
    rig: Rig,
    hand: Hand,
    baseline: tuple[float, float],
    calibration: Calibration,
    angle: float,
    *,
    step: float = ROLL_STEP,
    n: int = 32,
    offset: float | None = None,
    bridge_jump: float | None = BRIDGE_JUMP,
    observer: Callable[[dict[str, Any]], object] | None = None,
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
    (``event="reading"``), as they happen (see :mod:`driver.records.runlog`); ``index``
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

    def observe(j: int) -> None:
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

    d = [read_location(rig, baseline, calibration, n, readings, truth, hand)]
    observe(0)
    phis = [hand.measured_angle()]
    for j in range(k):
        hand.rotate_by(angle / k)
        press(rig, hand, baseline, target=calibration.target, n=n, pressing=pressing)
        try:
            d.append(read_location(rig, baseline, calibration, n, readings, truth, hand))
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


#: A face is crossed in a step whose jaw angles reach within this of the face's angle, rad (the arm
#: encoder's steps and the jaw's twist under load).
FACE_ANGLE_TOL = math.radians(0.1)


#: ... and whose jump matches the face's length within this, mm (the rolling on the fillets either side
#: in that step, the reading's error).
FACE_JUMP_TOL = 0.5


def crossed_face(
    faces: Iterable[tuple[float, float]], phi_from: float, phi_to: float, jump: float, first: bool
) -> bool:
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
    rolls: Iterable[float],
    *,
    calibration: Calibration,
    approach_pose: Iterable[float],
    step: float = ROLL_STEP,
    n: int = 32,
    bridge_jump: float = BRIDGE_JUMP,
    observer: Callable[[dict[str, Any]], object] | None = None,
    pressing: PressSettings = PRESS,
    faces: tuple[tuple[float, float], ...] = (),
) -> tuple[RollResult, ...]:
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
    results: list[RollResult] = []
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
    rolls: Iterable[float],
    *,
    calibration: Calibration,
    approach_pose: Iterable[float],
    step: float = ROLL_STEP,
    n: int = 32,
    bridge_jump: float = BRIDGE_JUMP,
    rule: str = "likelihood",
    sd_length: float = SD_LENGTH,
    sd_turn: float = SD_TURN,
    observer: Callable[[dict[str, Any]], object] | None = None,
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
    rolls: Iterable[float],
    *,
    calibration: Calibration | None = None,
    slide: float = 40.0,
    observer: Callable[[dict[str, Any]], object] | None = None,
    **options: Any,
) -> tuple[RollingRun, Calibration]:
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
