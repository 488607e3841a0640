"""Where a reactive run says the part differs from its model: the filter's misfit, a jump the jaw rolled through
to leave what it sat on, a stretch before the filter started again, or a jump the final place does not explain."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from localizer import Belief, Boundary, ContactFilter, mass_within

from .reactive_policy import ReactivePolicy

__all__ = ["Unfit", "Moved", "PLACE_RADIUS", "holds_place", "takeoff_arc", "behind_jump", "Verdict"]


class Unfit(NamedTuple):
    """Where the readings stopped fitting under a filter that ruled out every start, kept when the filter
    starts again."""

    lo: float  #: rolled arc from where the filter started again, mm (the stretch's first end)
    hi: float  #: ... its second end, mm
    mm: float  #: how far off the model the readings were there (RMS), mm; NaN when not known
    leaves: int  #: how many jumps the jaw had rolled through to leave what it sat on, by then


class Moved(NamedTuple):
    """What a run met before it moved on (:mod:`driver.jaw.reactive_moves`), measured from where the jaw rolled
    through the jump it moved on by, to be placed by the belief it ends with."""

    lo: float  #: rolled arc from where the jaw took off, mm (the stretch's first end)
    hi: float  #: ... its second end, mm
    mm: float  #: how far off the model it was, mm; NaN when not known
    direction: int  #: the way the jaw rolled through the jump
    jump: float  #: the jump on the jaw, mm
    restarts: int  #: how many times the filter had started again where nothing fit, by then


#: How near the jaw's line at the landing the point it took off from must lie, mm, and how far the distance
#: along that line may be from the jump the jaw read, mm (a 0.2° step turns the line by 3.5 mrad: 0.1 mm over
#: 30 mm; the jump read is the places on the jaw of two presses), and a most probable landing a little off the
#: true one tilts the line by up to ``TAKEOFF_TILT`` rad more, either way (a line the model crosses further out,
#: or passes further in, is not the jaw's)
TAKEOFF_OFF = 0.5
TAKEOFF_ALONG = 3.0
TAKEOFF_TILT = math.radians(5.0)


#: What a run met is placed under its most probable start where the belief holds at least half its mass within
#: this of that start, mm: the place is claimed to within it (the mass within the success radius, 0.3 mm, asks how
#: near, not which place)
PLACE_RADIUS = 2.0


def holds_place(part: Boundary, grid: npt.NDArray[np.float64], weights: npt.NDArray[np.float64], at: int) -> bool:
    """Whether the belief ``weights`` over starts ``grid`` (model arc, mm; summing to 1) holds at least half its
    mass within :data:`PLACE_RADIUS` of start ``at`` (a grid index): which place is known, to place what a run
    met under it."""
    return mass_within(part, grid, weights, float(grid[at]), PLACE_RADIUS) >= 0.5


def takeoff_arc(part: Boundary, landing: float, direction: int, jump: float) -> float | None:
    """Where on ``part`` the jaw took off (arc, mm) when, rolling ``direction`` (+1: arc increasing), it jumped
    ``jump`` mm along itself to land at arc ``landing``: the point behind the landing on the jaw's line there
    (the tangent at the landing), about ``|jump|`` mm from it along the line, where the line touches the model.
    None where the model does not touch that line so far along it (within ``TAKEOFF_OFF`` and the tilt of
    ``TAKEOFF_TILT`` over the jump: the landing is not where the model has such a jump)."""
    P = part.perimeter
    theta = float(part.tangent_angle_at_arc(landing))
    tangent = np.array([math.cos(theta), math.sin(theta)])
    outward = np.array([tangent[1], -tangent[0]])  # counter-clockwise outline: the outside on the right
    back = landing - direction * np.arange(0.25, 0.5 * P, 0.05)
    rel = np.asarray(part.point_at_arc(part.wrap_arc(back))) - np.asarray(part.point_at_arc(landing))
    along, off = rel @ tangent, rel @ outward
    near = np.flatnonzero((np.abs(np.abs(along) - abs(jump)) <= TAKEOFF_ALONG) & (along * direction < 0))
    if near.size == 0:
        return None
    best = near[np.argmax(off[near])]
    # the line touches the model there (the nearest of the points about it, not the nearest of a stretch the
    # line only cuts: a convex stretch behind the landing falls away from the line further back)
    touches = best - 1 in near and best + 1 in near
    if not (touches and abs(off[best]) <= TAKEOFF_OFF + abs(jump) * math.tan(TAKEOFF_TILT)):
        return None
    return float(part.wrap_arc(back[best]))


def behind_jump(direction: int, jump: float) -> tuple[float, float]:
    """The stretch a jaw rolling ``direction`` left by a jump of ``jump`` mm along itself: rolled arc from where it
    landed, mm (the lesser end first), the jump and a millimetre (the contact moves on the part about as far as on
    the jaw across a burr)."""
    back = -direction * (abs(jump) + 1.0)
    return min(back, 0.0), max(back, 0.0)


class Verdict:
    """The verdict of a reactive run (:class:`driver.jaw.reactive` rolls with it) from what it met."""

    flt: ContactFilter
    policy: ReactivePolicy
    # the jumps rolled through to leave what the jaw sat on (direction, jump on the jaw mm)
    left: list[tuple[int, float]]
    found: list[Unfit]  # where the readings stopped fitting, each time the filter started again
    boxed: bool  # the jaw left a place boxed in by jumps the model explains (never sure after)
    unexplained: bool  # a jump no place of the model explains since the filter last started
    moved_from: tuple[tuple[float, float], float] | None  # what it met, before it moved on (see reactive)
    moved: Moved | None  # ... measured from where the jaw took off when it moved on
    judges_jumps: bool  # a spline part: a drawing's corners and faces make jumps of their own

    def _verdict(self, belief: Belief) -> tuple[tuple[float, float], float] | None:
        """Where the part seems to differ from its model and by how much (mm), or None: the filter's misfit,
        the stretch a filter that ruled out every start did not fit (from where the present one started), the
        stretch the jaw left (behind where the present filter started, by the jump), or a jump the most
        probable start does not explain (ahead of its contact then). NaN ends where it cannot be told (the
        belief has no place holding half of it)."""
        flt = self.flt
        if belief.mismatch is not None or not belief.consistent or flt.ruled_out:
            return None if belief.mismatch is None else (belief.mismatch, belief.mismatch_mm)
        start = int(np.argmax(flt.posterior()))
        part = flt.part
        if self.moved_from is not None:
            # what it met before it moved on: from where the jaw took off, under the belief it ends with, where that
            # places it; else where the belief before the move put it
            m = self.moved
            # the present filter started where the jaw landed (not again, past a stretch nothing fit)
            if m is None or m.restarts != len(self.found) or not self._placed(start):
                return self.moved_from
            landing = float(flt.grid[start])
            takeoff = takeoff_arc(part, landing, m.direction, m.jump)
            if takeoff is None:
                if all(math.isfinite(a) for a in self.moved_from[0]):
                    return self.moved_from
                # nor did the belief before the move place it: the model has no such jump there (it was what the
                # jaw met), and the contact moved on the part about as far as on the jaw (:func:`behind_jump`)
                takeoff = landing - m.direction * abs(m.jump)
            ends = part.wrap_arc(np.array([takeoff + m.lo, takeoff + m.hi]))
            return (float(ends[0]), float(ends[1])), m.mm
        if self.found:
            lo, hi, mm, leaves = self.found[0]
            if leaves == len(self.left):  # measured from where the present filter started
                if not self._placed(start):  # not localized since: where it did not fit is not known
                    return (math.nan, math.nan), mm
                s0 = float(flt.grid[start])
                return (float(part.wrap_arc(s0 + lo)), float(part.wrap_arc(s0 + hi))), mm
            # the jaw left what it sat on since: the jump it rolled through is measured from the present start,
            # that stretch is not; a run that ruled out every start is never sure all the same
            return self._left(belief, start) or ((math.nan, math.nan), mm)
        if self.left:
            # left a place boxed in by jumps the model explains: never sure, where it left if it can be told
            return self._left(belief, start) or (((math.nan, math.nan), math.nan) if self.boxed else None)
        missed = flt.unexplained_bridges(start)
        if not self.judges_jumps:
            missed = []
        elif self.unexplained and belief.mass < 0.5:
            # jumps nothing on the model explains, and no place known well enough to say where
            return (math.nan, math.nan), math.nan
        if missed and belief.mass >= 0.5:
            before, turn, _, jump = missed[0]
            at = float(flt.tracks.step(np.array([start]), before)[0][0])
            width = abs(self.policy.bridge_jump) + 2.0
            lo = at if turn > before else at - width
            return (float(part.wrap_arc(lo)), float(part.wrap_arc(lo + width))), math.nan
        return None

    def _placed(self, start: int) -> bool:
        """Whether the belief holds at least half its mass within :data:`PLACE_RADIUS` of start ``start`` (a grid
        index, :func:`holds_place`)."""
        return holds_place(self.flt.part, np.asarray(self.flt.grid), np.asarray(self.flt.posterior()), start)

    def _left(self, belief: Belief, start: int) -> tuple[tuple[float, float], float] | None:
        """The stretch the jaw left by its last jump, behind where the present filter started (most probable
        start ``start``, a grid index), or None where a concavity of the model there explains the jump."""
        flt, part = self.flt, self.flt.part
        direction, jump = self.left[-1]
        a, b = behind_jump(direction, jump)
        lo, width = float(flt.grid[start]) + a, b - a
        # the jump it rolled through, seen from where the rolling went on: a concavity of the model there
        # explains it (a bridge the belief of the time misjudged), a convex stretch does not
        between = flt.tracks.node_at(np.linspace(lo, lo + width, 32))
        explained = not bool(np.all(flt.tracks.convex[between]))
        if belief.mass >= 0.5 and explained:
            return None
        if explained or not self._placed(start):
            # left, but not localized since (or only about where, and a concavity there would explain the jump):
            # where it left is not known
            return (math.nan, math.nan), abs(jump)
        return (float(part.wrap_arc(lo)), float(part.wrap_arc(lo + width))), abs(jump)
