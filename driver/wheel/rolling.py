"""Localizing with a wheel finger (the physics in docs/wheel.md; each step of the rolling is a
:class:`~driver.wheel.disc.WheelDisc` step, checked there for jumps and slip).

:func:`localize_with_wheel` rolls one way, turning round at a jump, and gives the readings to a
:class:`localizer.WheelFilter` until it is sure (or the budget is spent). When nothing on the part fits
what was read (a jam that reads as rolling in a concave arc of the wheel's own radius), it retraces
its poses back to where that segment of rolling started and starts afresh there: away from the
segment's last jump when it had one (a jam wedges the disc at a mouth it then jumps across, so the way
the wheel turned to after that jump), else the other way. When that fresh start fails too, the wheel sits on
what the model does not have (pressed onto a bump or into a dent, both ways read the same misfit): it rolls
on through it (:func:`_roll_on`), localizes afresh beyond, and the run ends "mismatch", the stretch that did
not fit placed under the estimate. Likewise where it jumps both ways at once and no place of the model has such
jumps (pressed onto a short bump, or into a narrow dent, whose sides it cannot roll over as the model's curve):
it rolls over this way, jumps and all, and localizes afresh beyond.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from localizer import DEFECT_WINDOW, Belief, Outline, Part, WheelFilter, WheelJaw

from ..jaw import PRESS, PressSettings
from ..rig import Rig, RigError
from .disc import (
    WHEEL_POLICY,
    WheelCalibration,
    WheelDisc,
    WheelPolicy,
    corner_pivot,
    kappa_band,
)

__all__ = ["WheelRun", "WheelSlip", "localize_with_wheel", "MAX_RESTARTS"]

#: Times the rolling may start afresh after nothing fit its readings, before it stops "blocked".
MAX_RESTARTS = 2


class WheelSlip(RigError):
    """The wheel's rim slipped on the part beyond the policy's limit: its L readings are not the part's arc."""


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
        "confident" (the final belief sure, whatever ended the rolling), "max_rotation", "max_arc", "blocked"
        (jumps both ways at one place, or again where the wheel jumped the same way before: enclosed) or
        "mismatch" (a stretch of the readings fits no probable place, or nothing fits after :data:`MAX_RESTARTS`
        fresh starts, or the wheel rolled on through what did not fit (module notes): the part is not its model,
        ``belief.mismatch`` says where when it can); slip beyond the policy's limit raises :class:`WheelSlip`
        instead.
    reversals, jumps : int
    slip : float, mm
        The rim's slip summed over the steps the rolling judged (:mod:`driver.wheel.disc`, step 5; not over a
        roll on past what the model does not have).
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
    history: tuple[tuple[float, float, float, float], ...] = field(repr=False, default=())
    lengths: tuple[float, ...] = field(repr=False, default=())
    turns: tuple[float, ...] = field(repr=False, default=())
    true_arcs: tuple[float, ...] = field(repr=False, default=())
    segments: tuple[int, ...] = field(repr=False, default=())

    @property
    def restarts(self) -> int:
        """Times the rolling started afresh (module notes)."""
        return int(self.segments[-1]) if self.segments else 0

    @property
    def estimate_arc(self) -> float:
        return self.belief.map_arc


def _roll_on(
    disc: WheelDisc, direction: int, length: float, policy: WheelPolicy, through: bool = False
) -> tuple[float, float, float, bool]:
    """Roll ``direction`` until ``length`` mm of arc is rolled, without judging the readings: the hand's turning
    (rad, both ways counted), the arc (signed, mm) and the rim's slip (mm) over it, and whether it got through
    (False: the wheel jumped first, and stays where that step started; or it pivots on a corner where no arc is
    rolled); ``through``: over jumps too (:meth:`WheelDisc.step`)."""
    turned = d_len = slip = 0.0
    for _ in range(int(math.ceil(4 * length / policy.step))):  # a step rolls about policy.step of arc
        moved = disc.step(direction, through)
        if moved is None:
            return turned, d_len, slip, False
        turned, d_len, slip = turned + abs(moved[0]), d_len + moved[1], slip + moved[2]
        if abs(d_len) >= length:
            return turned, d_len, slip, True
    return turned, d_len, slip, False


def localize_with_wheel(
    rig: Rig,
    part: Part | Outline,
    wheel: WheelJaw,
    *,
    approach_pose: Iterable[float],
    calibration: WheelCalibration | None = None,
    filter: WheelFilter | None = None,
    policy: WheelPolicy = WHEEL_POLICY,
    pressing: PressSettings = PRESS,
    observer: Callable[[dict[str, Any]], object] | None = None,
) -> WheelRun:
    """Roll the wheel from ``approach_pose`` until the contact is known (module notes).

    Parameters
    ----------
    rig : Rig with an axle encoder (:class:`driver.wheel.AxleEncoder`)
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
    disc = WheelDisc(rig, cal, policy, pressing, kappa_band(part, wheel), corner_pivot(part, wheel))
    flt = filter if filter is not None else WheelFilter(part, wheel)
    flt.reset()
    pol = policy
    max_arc = pol.max_arc if pol.max_arc is not None else float(part.perimeter)
    # the filter keeps a reading every ``thin`` mm rolled, up to its memory's max_readings: stop before
    max_arc = min(max_arc, (flt.max_readings - 1) * flt.thin)
    start = disc.begin(approach_pose)
    history: list[tuple[float, float, float, float]]
    lengths, turns, truths, segments, history = [0.0], [0.0], [disc.truth()], [0], []
    flt.update(0.0, 0.0)
    direction, reversals, jumps, steps, segment = 1, 0, 0, 0, 0
    poses, segment_rotation = [disc.hand.pose], 0.0  # the settled poses of this segment, to retrace
    rotation = arc = slip = 0.0
    blocked: list[tuple[int, float]] = []  # (direction, L mm) of the jumps of this segment
    stopped = "max_rotation"
    met: tuple[float, float] | None = None  # what the wheel rolled on through (:func:`_roll_on`)
    # the rim's slip (mm) and the arc (mm) it is judged over: since the wheel last started afresh beyond what the
    # model does not have (rolling over a bump sharper than the rim reads as slip there)
    judged = [0.0, 0.0]

    def start_beyond() -> None:
        """Localize afresh where the wheel is, having rolled on past what did not fit."""
        nonlocal poses, segment_rotation, start, segment, blocked
        poses, segment_rotation = [disc.hand.pose], 0.0
        start, segment = disc.state, segment + 1
        flt.reset()
        flt.update(0.0, 0.0)
        lengths.append(0.0)
        turns.append(0.0)
        truths.append(disc.truth())
        segments.append(segment)
        blocked = []
        judged[:] = [0.0, 0.0]

    while True:
        moved = disc.step(direction)
        if moved is None:
            margin = 1.0 + pol.step
            flt.jumped(direction, margin=margin)
            jumps += 1
            # a jump where the last one was (stuck), or where one the same way was before (the wheel enclosed
            # between two places it cannot pass: rolling on reads the same ground again)
            near = [(d, L) for d, L in blocked if abs(lengths[-1] - L) < 2 * pol.step]
            if near and (near[-1] == blocked[-1] or any(d == direction for d, _ in near)):
                if met is None and not bool(np.any(flt.explains_jump(1, margin) & flt.explains_jump(-1, margin))):
                    # jumps both ways where no place of the model has them (the wheel pressed onto a short bump
                    # or into a narrow dent, whose sides it cannot roll over as the model's curve): roll over it
                    # this way, and localize afresh beyond
                    turned, d_len, _, through = _roll_on(disc, direction, DEFECT_WINDOW, pol, through=True)
                    rotation += turned
                    arc += abs(d_len)
                    if through:
                        met = (-d_len - 1.0, -d_len + 1.0)  # where it was blocked, from here
                        start_beyond()
                        continue
                stopped = "blocked"
                break
            blocked.append((direction, lengths[-1]))
            direction, reversals = -direction, reversals + 1
            continue
        d_turn, d_len, mismatch = moved
        slip += mismatch
        judged[0] += mismatch
        judged[1] += abs(d_len)
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
        if abs(judged[0]) > pol.max_slip + pol.max_slip_fraction * judged[1]:
            raise WheelSlip(
                f"the wheel's rim slipped {judged[0]:+.3f} mm over {judged[1]:.1f} mm rolled (the axle's path against "
                f"the encoders, more than {pol.max_slip} mm + {pol.max_slip_fraction:.1%} of the arc): its readings "
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
                if segment == MAX_RESTARTS - 1:
                    # the fresh start failed too: from where every segment started, rolling either way (or the
                    # same way again) reads what the model does not have (the wheel started on a bump or in a
                    # dent). Roll on through it instead, and localize afresh beyond
                    here = lengths[-1]
                    rolled = [L for L, g in zip(lengths, segments) if g <= segment]
                    turned, d_len, _, through = _roll_on(disc, direction, DEFECT_WINDOW, pol)
                    rotation += turned
                    arc += abs(d_len)
                    if not through:
                        stopped = "blocked"
                        break
                    # what did not fit, in the rolled arc from where the next segment starts
                    met = (min(rolled) - here - d_len, max(rolled) - here - d_len)
                    start_beyond()
                    continue
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
    if stopped in ("max_rotation", "max_arc", "blocked") and final.sure(pol.confidence):
        # the budget ran out between two checks, or the wheel could roll no further, and the readings since
        # the last check made it sure
        stopped = "confident"
    if stopped != "confident" and (final.mismatch is not None or not final.consistent):
        stopped = "mismatch"
    if met is not None:
        # the wheel rolled on through what did not fit: the run met a part that is not its model, whatever it
        # found beyond; said where under the most probable start when something fits
        stopped = "mismatch"
        if final.mismatch is None:
            ends = (math.nan, math.nan)
            if final.consistent:
                first = final.map_arc - lengths[-1]  # where the last segment started, under the estimate
                ends = (float(part.wrap_arc(first + met[0])), float(part.wrap_arc(first + met[1])))
            final = replace(final, mismatch=ends)
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
