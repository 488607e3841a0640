"""Reactive localization: roll step by step, update the belief at every step, stop when sure.

Jia (2005, §V) names "reactive localization which conducts sensing and movement simultaneously" as
the way forward. :func:`localize_reactively` does it with :class:`localizer.ContactFilter`, by the
rules of :class:`driver.jaw.reactive_policy.ReactivePolicy` (listed in :mod:`driver.jaw.reactive_policy`).

Works on any :class:`driver.rig.Rig` (simulated or serial).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import replace
from typing import Any

import numpy as np

from localizer import (
    UNEXPLAINED,
    Belief,
    Boundary,
    ContactFilter,
    arc_from_jaw_positions,
)

from ..rig import DEVICE_FAULTS, Reading, Rig, RigError, Truth
from .calibration import Calibration
from .hand import PRESS, PressSettings, edge_offset, establish_contact
from .reactive_moves import JawMoves
from .reactive_policy import (
    BOXED_ROTATION,
    MAX_LEAVES,
    MAX_RESTARTS,
    REACTIVE_POLICY,
    ReactivePolicy,
    ReactiveRun,
    clear_ahead,
    information_by_direction,
    spread_by_direction,
)
from .reactive_verdict import Moved, Unfit

__all__ = ["localize_reactively"]


def localize_reactively(
    rig: Rig,
    part: Boundary,
    *,
    calibration: Calibration,
    approach_pose: Iterable[float],
    filter: ContactFilter | None = None,
    policy: ReactivePolicy = REACTIVE_POLICY,
    pressing: PressSettings = PRESS,
    observer: Callable[[dict[str, Any]], object] | None = None,
) -> ReactiveRun:
    """Roll until the contact is known within the filter's radius with the ``policy``'s confidence (the
    rules: :mod:`driver.jaw.reactive_policy`).

    Parameters
    ----------
    rig : Rig
    part : Part or Outline
        The part's model.
    calibration : Calibration
        The wrist's calibration (contact place on the jaw from Δv2/Δv1).
    approach_pose : (x mm, y mm, φ rad)
        Where the hand starts, clear of the part, facing the first contact.
    filter : ContactFilter, optional
        The belief to update (reset first); default: ``ContactFilter(part)``.
    policy : ReactivePolicy
        How it rolls and when it stops.
    pressing : PressSettings
        How every press finds the force (and the optional servo hold).
    observer : callable, optional
        Called with ``{"event": "belief", ...}`` at every check.
    """
    flt = filter if filter is not None else ContactFilter(part)
    return _Roller(rig, flt, calibration, policy, pressing, observer).run(approach_pose)


class _Roller(JawMoves):
    """One reactive localization: the hand, the filter, the counters and the traces it returns.

    :meth:`run` rolls step by step (:meth:`_step`); a step at the end of the jaw's span is a
    regrasp (:meth:`_regrasp`), a step that bridges a concavity is undone (:meth:`_undo_bridge`),
    and every ``check_every`` steps the belief is checked (:meth:`_check`).
    """

    def __init__(
        self,
        rig: Rig,
        flt: ContactFilter,
        calibration: Calibration,
        policy: ReactivePolicy,
        pressing: PressSettings,
        observer: Callable[[dict[str, Any]], object] | None,
    ) -> None:
        self.rig, self.flt, self.calibration, self.policy = rig, flt, calibration, policy
        self.pressing, self.observer = pressing, observer
        self.readings: list[Reading] = []
        self.truth: list[Truth] = []
        self.z = self.rotation = 0.0
        self.turn = 0.0  # net rotation at the last reading, rad
        self.steps = self.reversals = self.regrasps = self.bridges = 0
        self.explored = [0.0, 0.0]
        self.blocked = {1: False, -1: False}
        self.arcs: list[float] = [0.0]
        self.turns: list[float] = [0.0]
        self.history: list[tuple[float, float, float, float]] = []
        self.segments: list[int] = [0]
        # nothing is known yet: counter-clockwise, like the paper
        self.direction = 1 if policy.direction is None else policy.direction
        self.belief: Belief | None = None
        self.sure = 0  # checks in a row at or above the confidence
        # a jump no place of the model explains since the filter last started, and the jumps the jaw
        # rolled through to leave what it sat on (direction, jump on the jaw mm): a part not its model
        self.unexplained = False
        self.left: list[tuple[int, float]] = []
        self.found: list[Unfit] = []  # what the verdict reads (:class:`Verdict`)
        # where the last bridge each way landed on the jaw (mm) and at which net rotation (rad); whether the jaw
        # is rolling back to leave through the other way's bridge, whose landing lies on the jaw's span where
        # the last one's did not, and whether it did so once already
        self.landed: dict[int, tuple[float, float]] = {}
        self.rolling_back = self.rolled_back = False
        # a drawing's corners and faces make jumps of their own, which the belief judges less well: jumps
        # are neither left nor reported as a mismatch there
        self.judges_jumps = not (flt.tracks.has_faces or flt.part.corners)
        self.segment_base = 0  # segments of the filters before a restart
        self.since = 0  # the first record of the present filter's (``arcs``, ``turns``, ...)
        self.rotation_at_start = 0.0  # the rolled rotation when the present filter started, rad
        self.boxed = False  # left a place boxed in by jumps the model explains (:class:`Verdict`)
        self.rereads = 0  # readings taken again because one jumped
        self.moved_from: tuple[tuple[float, float], float] | None = None  # what it met, before it moved on
        self.moved: Moved | None = None  # ... measured from where the jaw took off
        self.moves = 0  # times the jaw moved on, blocked both ways after meeting something (:meth:`_move_on`)
        self.away = 0  # the way it is moving on (+1, -1), 0 when it is not

    # ------------------------------------------------------------------ the run
    def run(self, approach_pose: Iterable[float]) -> ReactiveRun:
        """Establish contact at ``approach_pose`` and roll until sure, blocked, lost or out of budget."""
        rig, flt, p = self.rig, self.flt, self.policy
        flt.reset()
        self.hand, self.baseline, _ = establish_contact(
            rig, approach_pose, target=self.calibration.target, n=p.n, pressing=self.pressing
        )
        self.offset = edge_offset(rig, self.hand, self.baseline)
        self.jaw_limit = float(np.max(np.abs(self.calibration.positions))) - p.end_margin
        self.d_prev = self.read_base()
        flt.touch(self.d_prev)  # the first contact's place on the jaw: where the jaw could have been laid
        self.phi0 = self.hand.measured_angle()
        self.true_arcs = [self.true_arc()]
        stopped = "max_rotation"
        while self.rotation < p.max_rotation - 1e-12:
            outcome = self._step()
            if outcome is not None:
                stopped = outcome
                break
        if self.belief is None or self.belief.steps != flt.steps:
            belief = self.belief = flt.belief()
            self.history.append((self.rotation, belief.map_arc, belief.mass, self.true_arc()))
            if stopped == "max_rotation":
                # the budget ran out between two checks: the readings since the last one are judged as a
                # check would judge them (a belief that became sure there is sure)
                stopped = self._decide(belief) or stopped
        belief = self.belief
        if stopped != "mismatch":
            where = self._verdict(belief) if belief.consistent else None
            if where is not None:
                belief = replace(belief, mismatch=where[0], mismatch_mm=where[1])
            if where is not None or not belief.consistent:
                stopped = "mismatch"
        return ReactiveRun(
            belief=belief,
            rotation=self.rotation,
            steps=self.steps,
            stopped=stopped,
            reversals=self.reversals,
            regrasps=self.regrasps,
            bridges=self.bridges,
            history=tuple(self.history),
            arcs=tuple(self.arcs),
            turns=tuple(self.turns),
            true_arcs=tuple(self.true_arcs),
            segments=tuple(self.segments),
        )

    def _step(self) -> str | None:
        """Roll one step and take its reading; the stop reason, or None to roll on."""
        p, flt = self.policy, self.flt
        s = self.direction * p.step
        self.hand.rotate_by(s)
        self.rotation += p.step
        try:
            d = self.read_or_inf() if self.pressed() else math.inf
            if math.isfinite(self.d_prev) and not abs(d - self.d_prev) <= p.reread_jump:
                d = self.read_again(d)
        except DEVICE_FAULTS:
            raise
        except RigError:
            d = math.inf  # the press was refused: treated as a bridge
        bridged = not math.isfinite(d) or (abs(d - self.d_prev) > p.bridge_jump and not self._crossed_face(d, s))
        regrasped = slid_off = False
        if not bridged and abs(d) > self.jaw_limit:
            d, regrasped, slid_off = self._regrasp(d)
            bridged = slid_off
        if bridged:
            return self._undo_bridge(s, slid_off, d)
        if regrasped:
            turn = self.turn
        else:
            turn = self.turn_now()
            self.z += self.direction * arc_from_jaw_positions([self.d_prev, d], s, self.offset)
            flt.update(self.z, turn, d)
        self.turn = turn
        if self.rolling_back and (turn - self.landed[self.direction][1]) * self.direction > 2 * p.step:
            # rolled back past where that way's jump was, and it did not come again (the contact's place on the
            # jaw jumped, not the contact): back to the jump the jaw was leaving, to leave through it after all
            self.rolling_back = False
            self.direction = -self.direction
            self.reversals += 1
        self.explored = [min(self.explored[0], turn), max(self.explored[1], turn)]
        self.arcs.append(self.z)
        self.turns.append(turn)
        self.true_arcs.append(self.true_arc())
        self.segments.append(self.segment_base + flt.segment)
        self.d_prev = d
        self.steps += 1
        if self.steps % p.check_every == 0:
            return self._check()
        return None

    def _crossed_face(self, d: float, s: float) -> bool:
        """Whether a jump of the contact along the jaw, to ``d`` mm after a turn of ``s`` rad, is the jaw
        tipping over a flat face (the contact passes the face at one jaw angle) or a shallow dip the
        rolling model carries it across, rather than a bridge that ends the convex stretch.

        Both are crossed in one step: the jump is then a reading. The belief judges: the
        hypotheses that predict a step of about the measured arc (within 1 mm or 10%) against those
        under which the turn leaves their convex stretch (a bridge). A part with neither has none.
        """
        tracks = self.flt.tracks
        if not (tracks.has_faces or tracks.bridges) or self.flt.ruled_out:
            return False
        arc = self.direction * arc_from_jaw_positions([self.d_prev, d], s, self.offset)
        posterior = self.flt.posterior()
        idx = np.flatnonzero(posterior > 0)
        moved, _, ok = tracks.step(idx, self.turn_now(), jaw=self.d_prev, at=self.flt.current[idx])
        w = posterior[idx]
        step = np.where(ok, moved - self.flt.current[idx], np.nan)
        fits = ok & (np.abs(step - arc) <= max(1.0, 0.1 * abs(arc)))
        return bool(w[fits].sum() > w[~ok].sum())

    def _undo_bridge(self, s: float, slid_off: bool, d: float) -> str | None:
        """The step bridged a concavity: roll back, re-read, and go the other way ("lost" or "blocked"
        when that is not possible). A jump no place of the belief predicted, once both ways are blocked,
        is rolled through instead (:meth:`_leave`): the jaw sits on something the model does not have."""
        p, flt = self.policy, self.flt
        self.bridges += 1
        if not slid_off:
            # evidence: the starts under which this turn keeps the jaw clear are less likely
            predicted = flt.bridged(self.turn_now(), jump=p.bridge_jump)
            if predicted < UNEXPLAINED:
                self.unexplained = True
        self.hand.rotate_by(-s)
        self.rotation += p.step
        try:
            if not self.pressed():
                raise RigError("the press back was refused")
            self.d_prev = self.read_base()
        except DEVICE_FAULTS:
            raise
        except RigError:
            return "lost"
        # the re-read is a new base for the increments: a new segment with its own offset
        flt.regrasp(self.z, self.turn_now(), self.d_prev)
        self.blocked[self.direction] = True
        if math.isfinite(d):
            self.landed[self.direction] = (d, self.turn + s)
        if self.blocked[-self.direction]:
            # both ways blocked, by a jump nothing on the model explains: the jaw sits on something else. Or by
            # jumps it explains, within BOXED_ROTATION of where the filter started: no run on a part that is its
            # model is boxed in that soon, a burr's crest boxes it in often
            boxed = self.rotation - self.rotation_at_start <= BOXED_ROTATION
            leave = self.judges_jumps and (self.unexplained or boxed) and len(self.left) < MAX_LEAVES
            if leave and not self.away and math.isfinite(d):  # (a jaw moving on leaves by its own way)
                self.boxed = self.boxed or not self.unexplained
                other = self.landed.get(-self.direction, (math.inf, 0.0))[0]
                if abs(d) > self.jaw_limit and abs(other) <= self.jaw_limit and not self.rolled_back:
                    # this way lands beyond the jaw's calibrated span (a burr's crest sits near the jaw's end,
                    # the jump carrying the contact outwards), the other way on it. The jaw is slid along
                    # itself first, as the leave does; where the slid jaw's longer reach touches the part
                    # beyond the crest instead, it rolls back and leaves through the other way's bridge
                    jump = d - self.d_prev
                    d_new, regrasped, _ = self._regrasp(self.d_prev)
                    if regrasped:
                        self.d_prev = d_new
                        return self._leave(s, jump)
                    self.rolling_back = self.rolled_back = True
                    self.direction = -self.direction
                    self.reversals += 1
                    return None
                return self._leave(s, d - self.d_prev)
            return self._move_on(s, d)
        self.direction = -self.direction
        self.reversals += 1
        return None

    def _decide(self, belief: Belief) -> str | None:
        """Whether ``belief`` ends the run: "mismatch" (nothing fits, or sure on a part that showed
        something its model does not have), "confident", or None (counts the checks sure in a row)."""
        if not belief.consistent:
            return "mismatch"  # nothing on the part fits the readings: never sure
        self.sure = self.sure + 1 if belief.mass >= self.policy.confidence else 0
        if self.sure >= self.policy.confirm:
            # sure where it is, but never "sure" on a part that showed something its model does not have
            # (a stretch of readings that fit nowhere, a jump the jaw left, or one the belief's place does
            # not explain): that is reported instead, with where
            where = self._verdict(belief)
            if where is not None:
                self.belief = replace(belief, mismatch=where[0], mismatch_mm=where[1])
                return "mismatch"
            return "confident"
        return None

    def _check(self) -> str | None:
        """Look at the belief: "confident" to stop; else the direction rules may turn the jaw round."""
        p, flt = self.policy, self.flt
        belief = self.belief = flt.belief()
        true_arc = self.true_arc()
        self.history.append((self.rotation, belief.map_arc, belief.mass, true_arc))
        if self.observer is not None:
            self.observer(
                {
                    "event": "belief",
                    "rotation": self.rotation,
                    "map_arc": belief.map_arc,
                    "mass": belief.mass,
                    "modes": [(m.arc, m.mass) for m in belief.modes[:4]],
                    "true_arc": true_arc,
                    "direction": self.direction,
                }
            )
        if not belief.consistent and self.judges_jumps and len(self.found) < MAX_RESTARTS:
            # spline parts only, as the leave: a drawing's corners and faces misfit of their own
            self._start_again()
            return None
        decided = self._decide(belief)
        if decided is not None:
            return decided
        direction = self.direction
        # a concavity ahead for most of the belief: turn round before bridging it, if the other way
        # is clear beyond what has been rolled there (else roll on: a bridge is detected and undone
        # all the same, and turning round towards a way that is no better only rocks the jaw in place)
        beyond = self.explored[0] if direction == 1 else self.explored[1]
        if (
            not self.blocked[-direction]
            and clear_ahead(flt, direction, p.lookahead) < 0.5
            and clear_ahead(flt, -direction, p.lookahead, at=beyond) >= 0.5
        ):
            self.direction = -direction
            self.reversals += 1
            return None
        # the direction rule, while two places hold the belief: turn round when the other way tells more of
        # it apart per radian, the way back to its unexplored edge counted, and if that way is clear (else the
        # rule above turns it straight back, and the jaw rocks)
        strong = [m for m in belief.modes if m.mass >= flt.mode_floor]
        if len(strong) < 2 or self.blocked[-direction]:
            return None
        if p.seek:
            ccw, cw = information_by_direction(flt, p.lookahead, tuple(self.explored))
            ahead, behind = (ccw, cw) if direction == 1 else (cw, ccw)
            turn = behind > p.seek_margin * ahead
        else:
            # the baseline: the two leading modes alone, by how much the unexplored curvature each way
            # separates them (it rocks where the modes' places jump about within two look-alike stretches)
            ccw, cw = spread_by_direction(flt, p.lookahead, tuple(self.explored), [m.start_arc for m in strong[:2]])
            ahead, behind = (ccw, cw) if direction == 1 else (cw, ccw)
            turn = ahead < p.min_spread and behind > 3 * p.min_spread
        if turn and clear_ahead(flt, -direction, p.lookahead, at=beyond) >= 0.5:
            self.direction = -direction
            self.reversals += 1
        return None
