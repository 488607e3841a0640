"""How a reactive run moves the jaw other than by a roll step: the regrasp at the end of the jaw's span, a slide
along itself, rolling through a jump to leave what the jaw sat on, moving on when it is blocked both ways after
meeting something its model does not have, and starting the filter afresh (rule 8 of
:mod:`driver.jaw.reactive_policy`)."""

from __future__ import annotations

import math

from localizer import Belief

from ..rig import DEVICE_FAULTS, RigError
from .reactive_policy import MAX_MOVES, MOVE_BUDGET
from .reactive_sensing import JawReadings
from .reactive_verdict import Moved, Unfit, Verdict, behind_jump

__all__ = ["JawMoves"]


class JawMoves(JawReadings, Verdict):
    """The jaw's moves of a reactive run (:class:`driver.jaw.reactive` rolls with them) and the state they keep."""

    jaw_limit: float  # the largest place on the jaw the calibration reads, less the policy's margin, mm
    d_prev: float  # the contact's place on the jaw at the last reading, mm
    z: float  # arc rolled since the present filter started, mm
    turn: float  # net rotation at the last reading, rad
    rotation: float  # rolled rotation so far, both ways counted, rad
    rotation_at_start: float  # ... when the present filter started, rad
    direction: int
    reversals: int
    regrasps: int
    explored: list[float]  # the least and largest net rotation reached since the filter started, rad
    blocked: dict[int, bool]
    landed: dict[int, tuple[float, float]]
    rolling_back: bool
    belief: Belief | None
    sure: int
    # the records a run returns, and the first of the present filter's
    arcs: list[float]
    turns: list[float]
    true_arcs: list[float]
    segments: list[int]
    segment_base: int
    since: int
    moves: int  # times the jaw moved on (:meth:`_move_on`)
    away: int  # the way it is moving on (+1, -1), 0 when it is not

    def _slid(self, slide: float) -> float:
        """Lift the jaw by the policy's backoff, slide it ``slide`` mm along itself, press it back and read
        where the contact is on it (mm; inf when the press was refused or the place cannot be read)."""
        self.hand.press_by(-self.policy.backoff)
        self.hand.slide_by(slide)
        try:
            return self.read_base() if self.pressed() else math.inf
        except DEVICE_FAULTS:
            raise
        except RigError:
            return math.inf

    def _regrasp(self, d: float) -> tuple[float, bool, bool]:
        """The contact reached the end of the jaw's span: lift, slide the jaw along itself so that the
        contact comes back near the other end, put it back on the same point. Returns (the new place
        on the jaw, regrasped, slid off: the slid jaw found another point, a bridge)."""
        p = self.policy
        target_d = -math.copysign(self.jaw_limit - 2 * p.end_margin, d)
        slide = d - target_d
        d_new = self._slid(slide)
        if abs(d_new - target_d) <= p.bridge_jump:
            self.turn = self.turn_now()
            self.flt.regrasp(self.z, self.turn, d_new)
            self.regrasps += 1
            return d_new, True, False
        # the longer reach of the slid jaw found another point: the stretch ends here on the hull;
        # put the jaw back and treat it as a bridge
        self.hand.press_by(-p.backoff)
        self.hand.slide_by(-slide)
        self.pressed()
        return d, False, True

    def _move_on(self, s: float, d: float) -> str | None:
        """Blocked both ways after a step of ``s`` rad whose contact landed ``d`` mm on the jaw: "blocked", or,
        in a run that met something its model does not have and is not sure, with budget left, the jaw moves
        on once through the jump away from what it met (rolling back there first) and localizes afresh."""
        p = self.policy
        if self.away:
            if self.direction != self.away or not math.isfinite(d):
                return "blocked"
            self.away = 0
            return self._leave(s, d - self.d_prev, moving=True)
        met = bool(self.left or self.found or self.flt.misfits)
        belief = self.flt.belief()
        sure = belief.mass >= p.confidence
        if not (self.judges_jumps and met and self.moves < MAX_MOVES and belief.consistent) or sure:
            return "blocked"
        if self.left:
            away = self.left[-1][0]
        else:  # away from the stretch that stopped fitting: the present filter's, else the one it started again past
            lo, hi = self.flt.misfits[-1].travel if self.flt.misfits else self.found[-1][:2]
            away = 1 if self.z >= 0.5 * (lo + hi) else -1
        # the budget left when it decides (the way back to the other way's jump not counted: on the tuning family
        # counting it stopped two runs that were wrong, and were right after moving on)
        if p.max_rotation - self.rotation < MOVE_BUDGET or (away == self.direction and not math.isfinite(d)):
            return "blocked"
        self.moves += 1
        self.moved_from = self._verdict(belief) or ((math.nan, math.nan), math.nan)
        if away == self.direction:
            return self._leave(s, d - self.d_prev, moving=True)
        self.away = away
        self.direction = away
        self.rolling_back = False  # heading for that jump, not back from it
        self.reversals += 1
        return None

    def _leave(self, s: float, jump: float, moving: bool = False) -> str | None:
        """Blocked both ways by jumps the model does not explain (the jaw sits on a burr, or between a dent's
        rims): roll through the jump of ``jump`` mm on the jaw and localize afresh from where it lands. The
        readings so far came from something that is not the part's model; the filter starts again there,
        and the run ends "mismatch" whatever it finds (:meth:`_verdict`). ``moving``: the jaw moves on
        (:meth:`_move_on`), and where that fails it is put back where it was blocked ("blocked")."""
        p = self.policy
        blocked_at = self.hand.pose
        if abs(self.d_prev + jump) > self.jaw_limit:
            # the contact would land beyond the jaw's calibrated span: slide the jaw along itself first. On a
            # burr's crest the slid jaw's longer reach may touch the part beyond it instead (the slide is then
            # undone): roll through as it is, and slide the jaw from where the contact lands
            d_new, regrasped, _ = self._regrasp(self.d_prev)
            if regrasped:
                self.d_prev = d_new
        self.hand.rotate_by(s)
        self.rotation += p.step
        try:
            if not self.pressed():
                raise RigError("the press beyond the jump was refused")
            d = self.read_base()
        except DEVICE_FAULTS:
            raise
        except RigError:
            return self._put_back(blocked_at) if moving else "lost"
        if abs(d) > self.jaw_limit:
            # landed at the jaw's end (its tip may be what touches): slide the jaw along itself and start
            # afresh from whatever point of the part it then touches (the filter starts again anyway)
            target = -math.copysign(self.jaw_limit - 2 * p.end_margin, d)
            d = self._slid(d - target)
            if not abs(d) <= self.jaw_limit:
                return self._put_back(blocked_at) if moving else "lost"
            # the contact moved on along the part by about as much as it moved from the target on the jaw:
            # where the jaw left the model behind is that much further back
            jump = math.copysign(abs(jump) + abs(d - target), jump)
        if moving:
            met = self._met()
            if met is not None:
                self.moved = Moved(
                    met[0] - self.z, met[1] - self.z, met[2], self.direction, float(jump), len(self.found)
                )
        self.left.append((self.direction, float(jump)))
        self._afresh(d)
        return None

    def _met(self) -> tuple[float, float, float] | None:
        """What the run met, in the present filter's rolled arc (mm, its two ends) and how far off the model (mm,
        NaN when not known), in the order the verdict reports it: the stretch the fit test found, the stretch
        the filter started again past, the stretch behind the jump the jaw left by; None when none."""
        if self.flt.misfits:
            misfit = self.flt.misfits[0]
            inside = self._rolled_in(misfit.travel)
            return min(inside), max(inside), misfit.rms_mm
        if self.found and self.found[-1].leaves == len(self.left):
            return self.found[-1].lo, self.found[-1].hi, self.found[-1].mm
        if self.left:
            direction, jump = self.left[-1]
            return (*behind_jump(direction, jump), abs(jump))
        return None

    def _rolled_in(self, travel: tuple[float, float]) -> list[float]:
        """The present filter's readings' rolled arcs (mm) within ``travel`` (a stretch the fit test found), or
        its two ends where the jaw took no reading in it."""
        t0, t1 = travel
        return [a for a in self.arcs[self.since :] if t0 <= a <= t1] or [t0, t1]

    def _put_back(self, pose: tuple[float, ...]) -> str:
        """Moving on failed: lift the jaw, put it back at ``pose`` (where it was blocked both ways) and press;
        the run ends "blocked" on the belief it had there, as it would have without trying ("lost" where that
        press is refused too)."""
        self.moved_from = self.moved = None  # it did not move on: the run ends as it would have without trying
        self.hand.press_by(-self.policy.backoff)
        self.hand.go(*pose)
        self.rotation += self.policy.step  # the turn the leave made, back
        try:
            if not self.pressed():
                return "lost"
            self.d_prev = self.read_base()
        except DEVICE_FAULTS:
            raise
        except RigError:
            return "lost"
        self.flt.regrasp(self.z, self.turn_now(), self.d_prev)
        return "blocked"

    def _afresh(self, d: float) -> None:
        """Start the filter again from the present contact, ``d`` mm on the jaw: what came before is not
        the part's model (the jaw rolled through a jump it does not explain, or nothing on it fits)."""
        flt = self.flt
        self.segment_base += flt.segment + 1
        flt.reset()
        flt.touch(d)
        self.phi0 = self.hand.measured_angle()
        self.z = self.turn = 0.0
        self.d_prev = d
        self.explored = [0.0, 0.0]
        self.blocked = {1: False, -1: False}
        self.landed = {}
        self.rolling_back = False
        self.away = 0  # whatever moved the jaw on, it left: a move that was heading for its jump is done
        self.unexplained = False
        self.belief = None
        self.sure = 0
        self.since = len(self.arcs)
        self.rotation_at_start = self.rotation
        self.arcs.append(self.z)
        self.turns.append(self.turn)
        self.true_arcs.append(self.true_arc())
        self.segments.append(self.segment_base)

    def _start_again(self) -> None:
        """Nothing on the part fits the readings (the true start pruned by a defect's readings before the fit
        test found them): localize afresh from the present contact, and keep where the readings stopped
        fitting for the verdict."""
        # the last stretch found (the readings that then ruled every start out came over it or just after), as
        # far as the jaw rolled in it; else all that was rolled. In rolled arc from here: the new filter's start
        # places it on the model
        misfits = self.flt.misfits
        mm = misfits[-1].rms_mm if misfits else math.nan
        rolled = self._rolled_in(misfits[-1].travel) if misfits else self.arcs[self.since :]
        self.found.append(Unfit(min(rolled) - self.z, max(rolled) - self.z, mm, len(self.left)))
        self._afresh(self.d_prev)
