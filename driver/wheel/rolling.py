"""Localizing with a wheel finger (the physics in docs/wheel.md; each step of the rolling is a
:class:`~driver.wheel.disc.WheelDisc` step, checked there for jumps and slip).

:func:`localize_with_wheel` rolls one way, turning round at a jump, and gives the readings to a
:class:`localizer.WheelFilter` until it is sure (or the budget is spent). When nothing on the part fits
what was read (a jam that reads as rolling in a concave arc of the wheel's own radius), it retraces
its poses back to where that segment of rolling started and starts afresh there: away from the
segment's last jump when it had one (a jam wedges the disc at a mouth it then jumps across, so the way
the wheel turned to after that jump), else the other way; :data:`MAX_RESTARTS` times at the most. When the
last fresh start fails too, the wheel sits on what the model does not have (pressed onto a bump or into a
dent, every way reads the same misfit): it rolls on through it (:func:`_roll_on`), localizes afresh beyond,
and the run ends "mismatch", the stretch that did not fit placed under the estimate where the belief holds
that place (:func:`driver.jaw.holds_place`). Likewise where it is stuck or enclosed by jumps (both ways at one
place, or again where it jumped the same way) and no start of the model has a place it cannot roll over at every
one of them (pressed onto a short bump, or into a dent, whose sides it cannot roll over as the model's curve):
it rolls over this way, jumps and all, and localizes afresh beyond. Beyond, the wheel is pressed again
(:meth:`WheelDisc.press_again`): the first press may have been on what the model does not have. A roll on
that cannot be made retraces its steps and the rolling stops "blocked" as it would have. And where the readings
fit the model but it jumped where no probable start has a place it cannot roll over (:data:`UNEXPLAINED_JUMP`: a
dent it bridged, whose near edge read as a convex corner it pivots on), it retraces the segment to its start,
is pressed again there, and localizes afresh the other way; the run ends "mismatch", the jump placed as above.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from localizer import DEFECT_WINDOW, Belief, Outline, Part, PartScale, WheelFilter, WheelJaw, wheel_reach_for

from ..jaw import PRESS, PressSettings, holds_place
from ..rig import Rig, RigError
from .disc import (
    WHEEL_POLICY,
    WheelCalibration,
    WheelDisc,
    WheelPolicy,
    corner_pivot,
    kappa_band,
)

__all__ = ["WheelRun", "WheelSlip", "localize_with_wheel", "MAX_RESTARTS", "UNEXPLAINED_JUMP"]

#: Times the rolling may retrace and start afresh (after nothing fit its readings, or from a jump the model does
#: not have), before it rolls on through (module notes).
MAX_RESTARTS = 2
#: A jump is one the model does not have when the belief before it gives less than this probability to the
#: starts that explain it (:meth:`localizer.WheelFilter.explains_jump`) while the readings still fit some start
#: under the largest of the filter's noise scales.
UNEXPLAINED_JUMP = 1e-6


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
        fresh starts, or the wheel rolled on through what did not fit, or jumped where the model has no place to
        (module notes): the part is not its model, ``belief.mismatch`` says where when it can); slip beyond the
        policy's limit raises :class:`WheelSlip` instead.
    reversals, jumps : int
    slip : float, mm
        The rim's slip summed over the steps the rolling judged (:mod:`driver.wheel.disc`, step 5; not over a
        roll on past what the model does not have).
    depth : float, mm
        The wrist's give at the target force (measured at the last press: the first, or the press again after
        meeting what the model does not have).
    part_scale : PartScale
        What the last segment's readings say of the part's size against its model's
        (:meth:`localizer.WheelFilter.part_scale`).
    history : tuple of (rotation rad, map_arc mm, mass, true_arc mm)
    lengths, turns, true_arcs : tuple of float
        Every reading's L (mm) and Ω (rad) since its segment's start, and the true contact (NaN on a
        real rig).
    segments : tuple of int
        Each reading's segment: the rolling retraces the last segment and starts afresh (a new
        segment, from (0, 0)) when nothing on the part fits its readings
        (:attr:`localizer.Belief.consistent`), and after meeting what the model does not have (module notes).
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
    part_scale: PartScale = PartScale(0.0, 1.0, 0.0)
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


class _RolledOn(NamedTuple):
    turned: float  # the hand's turning, both ways counted (the way back too, where it went back), rad
    arc: float  # the arc rolled, signed, mm (0 where it went back)
    through: bool  # it rolled the whole length


def _roll_on(disc: WheelDisc, direction: int, length: float, policy: WheelPolicy, through: bool = False) -> _RolledOn:
    """Roll ``direction`` until ``length`` mm of arc is rolled, without judging the readings; ``through``: over
    jumps too (:meth:`WheelDisc.step`). Where it cannot (the wheel jumped first, or pivots on a corner where no
    arc is rolled), it retraces its steps to where it started."""
    turned = d_len = 0.0
    poses = [disc.hand.pose]
    for _ in range(int(math.ceil(4 * length / policy.step))):  # a step rolls about policy.step of arc on a curve
        moved = disc.step(direction, through)
        if moved is None:
            break
        turned, d_len = turned + abs(moved[0]), d_len + moved[1]
        poses.append(disc.hand.pose)
        if abs(d_len) >= length:
            return _RolledOn(turned, d_len, True)
    _retrace(disc, poses)
    return _RolledOn(2 * turned, 0.0, False)


def _retrace(disc: WheelDisc, poses: list[tuple[float, ...]]) -> None:
    """Take the hand back through ``poses`` (the settled poses since a start, the last where it is) to the first,
    last first: a jam unwinds as it was wound."""
    for pose in reversed(poses[:-1]):
        disc.hand.go(*pose)
    disc.state = disc.settled()


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
    bridged: tuple[float, float] | None = None  # where it jumped at what the model does not have
    # the rim's slip (mm) and the arc (mm) it is judged over: since the wheel was last pressed again after meeting
    # what the model does not have (rolling over a bump sharper than the rim reads as slip there)
    judged = [0.0, 0.0]
    # per start, whether every jump of this segment was where the model has a place the wheel cannot roll over,
    # at a contact it can touch (empty: no jump yet)
    explained: list[npt.NDArray[np.bool_]] = []
    reach = wheel_reach_for(part, wheel)

    def afresh(reseat: bool) -> None:
        """Start the filter afresh where the wheel is, as a new segment; ``reseat``: having met what did
        not fit (the rim's slip is judged from here)."""
        nonlocal poses, segment_rotation, start, segment, blocked
        if reseat:
            disc.press_again()  # the wrist zeroed and measured again: the first press may have been on what was met
        poses, segment_rotation = [disc.hand.pose], 0.0
        start, segment = disc.state, segment + 1
        flt.reset()
        flt.update(0.0, 0.0)
        lengths.append(0.0)
        turns.append(0.0)
        truths.append(disc.truth())
        segments.append(segment)
        blocked = []
        explained[:] = []
        if reseat:
            judged[:] = [0.0, 0.0]

    def retrace() -> None:
        """Take the hand back to where this segment started, its turning counted."""
        nonlocal rotation
        _retrace(disc, poses)
        rotation += segment_rotation

    while True:
        moved = disc.step(direction)
        if moved is None:
            # what the model says of the jump is asked only until the run has met what the model does not have
            asked = met is None and bridged is None
            before = flt.posterior() if asked else None
            explains = flt.jumped(direction, margin=1.0 + pol.step)
            if met is None:
                here = explains & np.asarray(reach.touchable(flt.present()))
                explained[:] = [here & explained[0] if explained else here]
            jumps += 1
            if (
                before is not None
                and before[explains].sum() < UNEXPLAINED_JUMP
                and flt.consistent(max(flt.noise_scales))
            ):
                # the readings fit the model at the noise the stated probability allows, and no probable place of it
                # has what the wheel jumped at: it met what the model does not have (a dent it bridged reads as a
                # convex corner it pivots on, then the jump no corner makes; a wheel wedged in a concave corner of
                # the model reads as nothing fits instead). Retrace the segment to its start, and start afresh
                # there away from it
                bridged = (lengths[-1] - 1.0, lengths[-1] + 1.0)  # the segment's start is the next one's
                retrace()
                afresh(reseat=True)
                direction, reversals = -direction, reversals + 1
                continue
            # a jump where the last one was (stuck), or where one the same way was before (the wheel enclosed
            # between two places it cannot pass: rolling on reads the same ground again)
            near = [(d, L) for d, L in blocked if abs(lengths[-1] - L) < 2 * pol.step]
            if near and (near[-1] == blocked[-1] or any(d == direction for d, _ in near)):
                if met is None and not explained[0].any():
                    # stuck or enclosed by jumps no place of the model has (the wheel pressed onto a short bump or
                    # into a dent, whose sides it cannot roll over as the model's curve). Roll over this way, and
                    # localize afresh beyond
                    rolled_on = _roll_on(disc, direction, DEFECT_WINDOW, pol, through=True)
                    rotation += rolled_on.turned
                    arc += abs(rolled_on.arc)
                    if rolled_on.through:
                        met = (-rolled_on.arc - 1.0, -rolled_on.arc + 1.0)  # where it was blocked, from here
                        afresh(reseat=True)
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
                # was wound), and start afresh there, away from its last jump; MAX_RESTARTS times at the most
                if segment >= MAX_RESTARTS:
                    if met is not None:
                        stopped = "blocked"
                        break
                    # every fresh start, from where the first segment started, failed too: rolling either way
                    # (and again) reads what the model does not have there (the wheel was pressed onto a bump or
                    # into a dent). Roll on through it this way, and localize afresh beyond
                    rolled_on = _roll_on(disc, direction, DEFECT_WINDOW, pol)
                    rotation += rolled_on.turned
                    arc += abs(rolled_on.arc)
                    if not rolled_on.through:
                        stopped = "blocked"
                        break
                    # what did not fit (every segment's readings, from that one start), from where the next starts
                    back = lengths[-1] + rolled_on.arc
                    met = (min(lengths) - back, max(lengths) - back)
                    afresh(reseat=True)
                    continue
                retrace()
                # away from the segment's last jump (a jam wedges the disc at a mouth it then jumps across):
                # the way the wheel turned to after that jump, which it keeps; without a jump, the other way
                turn_round = not blocked
                afresh(reseat=False)
                if turn_round:
                    direction, reversals = -direction, reversals + 1
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
    met = met if met is not None else bridged
    if met is not None:
        # the wheel rolled on or over what did not fit, or jumped at it: the run met a part that is not its model,
        # whatever it found since; said where under the most probable start when something fits
        stopped = "mismatch"
        if final.mismatch is None:
            ends = (math.nan, math.nan)
            first = final.map_arc - lengths[-1]  # where the last segment started, under the estimate
            at = int(np.argmin(np.abs(np.asarray(part.arc_offset(flt.grid, first)))))
            if final.consistent and holds_place(part, flt.grid, flt.posterior(), at):
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
        part_scale=flt.part_scale(),
        history=tuple(history),
        lengths=tuple(lengths),
        turns=tuple(turns),
        true_arcs=tuple(truths),
        segments=tuple(segments),
    )
