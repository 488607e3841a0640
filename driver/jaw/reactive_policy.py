"""Reactive localization's rules and its result: how the jaw rolls, turns round, regrasps and stops.

Jia (2005, §V) names "reactive localization which conducts sensing and movement
simultaneously" as the way forward. :func:`driver.jaw.reactive.localize_reactively` does it with
:class:`localizer.ContactFilter`:

1. establish contact and measure the wrist's give (the edge offset);
2. rotate one step, press back to the force, read the contact's location on the
   jaw; turn the step's jaw travel into signed arc (second-order inversion)
   and give the filter the cumulative arc and the arm's measured net rotation;
3. every ``check_every`` steps: stop when the probability within the success
   radius has reached ``confidence`` at ``confirm`` checks in a row (default 1:
   the first crossing; why not two: docs/filter.md, "How the settings were chosen"). When the
   rotation budget runs out between two checks, the
   readings since the last one are judged as a check would judge them;
4. the direction rule: while the belief has two or more modes, turn round when the other way is
   expected to raise the probability of the right place more per radian of rolling, the way back to
   its unexplored edge counted (:func:`information_by_direction`: each probable start's predicted
   travel, a face crossed or a corner pivoted on included, weighed against the others'). The jaw
   then rolls towards what tells the places apart: past a fillet's end onto the face whose length
   differs between two look-alike fillets, rather than back and forth over the fillets themselves,
   which read the same. The baseline (``seek=False``) compares how much the next ``lookahead`` of
   *unexplored* rotation each way separates the two leading modes (their radii of curvature's
   difference over it, integrated), and turns round when the way ahead cannot separate them (below
   ``min_spread``) and the other way clearly can (above three times that);
5. when most of the belief says the contact will leave its convex stretch
   within ``lookahead``, turn round before the jaw bridges the concavity; a
   step that jumps along the jaw all the same has bridged it: it is undone (the
   jaw rolls back one step), its reading is dropped, and the direction flips.
   Rules 4 and 5 turn round only towards a way that is clear for ``lookahead``
   beyond what has been rolled there; otherwise the jaw rolls on (a bridge is
   safe: it is detected and undone). Without this the two rules can turn the
   jaw back and forth at every check and roll in place;
6. at the end of the jaw's calibrated span the jaw is lifted, slid along
   itself and put back on the same point (a regrasp; the filter starts a new
   segment with its own offset), and rolling goes on the same way;
7. stop at ``max_rotation`` of rolled rotation, sure or not;
8. a part that is not its model: a reading whose contact jumped more than ``reread_jump``
   is read twice more and the middle of the three kept (a spike of the wrist's DAQ is one reading),
   as are the readings every step after counts from; when both ways are blocked and a jump was one no
   probable place of the model predicted (the jaw sits on a burr, or between a dent's rims), the jaw
   rolls through that jump once and the filter starts afresh from where it lands (spline parts: a
   drawing's corners and faces jump of their own). The jump is the last one met, unless it lands beyond
   the jaw's calibrated span where the other way's landed on it and sliding the jaw along itself does not
   hold: then the jaw rolls back and leaves through the other way's jump. Where nothing on the part fits
   the readings any more (a defect's readings ruled the true start out before the fit test found them), the
   filter starts again once from the present contact. Blocked both ways within ``BOXED_ROTATION`` of where
   the filter started, by jumps the model explains, the jaw leaves as from a burr all the same (no run
   on a part that is its model is boxed in so soon). Blocked both ways and not sure, in a run that met
   something its model does not have, with ``MOVE_BUDGET`` of the budget left, the jaw moves on once:
   through the jump away from what it met (the way it left, or away from the stretch that stopped
   fitting; rolling back to that jump first), and the filter starts afresh beyond it (where the move
   fails the jaw is put back and the run ends as if it had not tried); what it met is reported from
   where the jaw took off, placed by the belief it ends with. A run that met something the model does
   not have (a stretch the filter quarantined, a jump rolled through, one the final place does not
   explain) ends "mismatch", saying where, never "confident".

Works on any :class:`driver.rig.Rig` (simulated or serial).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from localizer import (
    BRIDGE_JUMP,
    CONFIDENCE,
    ROLL_STEP,
    Belief,
    ContactFilter,
    most_probable,
)

from ..rig import RigError

__all__ = [
    "CONFIRM",
    "MAX_LEAVES",
    "MAX_RESTARTS",
    "BOXED_ROTATION",
    "MAX_MOVES",
    "MOVE_BUDGET",
    "MAX_ROTATION",
    "ReactiveRun",
    "spread_by_direction",
    "information_by_direction",
    "clear_ahead",
    "SEEK_HYPOTHESES",
    "ReactivePolicy",
    "REACTIVE_POLICY",
]


#: Checks in a row at which the belief must reach the confidence before the rolling stops (step 3).
CONFIRM = 1


#: How many times a run rolls through such a jump to leave what the jaw sat on (rule 8 above):
#: once, off the thing under the start; a second would be a real concavity the belief misjudged.
MAX_LEAVES = 1

#: How many times a run starts its filter again where nothing on the part fits the readings (rule 8): once,
#: past the defect whose readings ruled the true start out; a second time the part is not its model at all.
MAX_RESTARTS = 1

#: Boxed in: blocked both ways, by jumps the model explains, within this much rolled rotation of where the
#: filter started (rad). The jaw then leaves as from a burr (rule 8), and the run never ends "confident".
BOXED_ROTATION = math.radians(45.0)

#: Blocked both ways, not sure, in a run that met something its model does not have, with at least
#: ``MOVE_BUDGET`` of the rotation budget left: the jaw moves on once, through the jump away from what it
#: met, and the filter starts afresh there (rule 8); the run stays "mismatch", never "confident".
MAX_MOVES = 1
MOVE_BUDGET = math.radians(60.0)


#: Budget of rolled rotation, both directions counted, rad (the command line's and the studies' too).
MAX_ROTATION = math.radians(240.0)


@dataclass(frozen=True)
class ReactiveRun:
    """Result of :func:`driver.jaw.localize_reactively`.

    Attributes
    ----------
    belief : Belief
        The final belief over the present contact.
    rotation : float, rad
        Total rotation rolled (both directions counted).
    steps : int
        Rolling steps that updated the filter.
    stopped : str
        "confident", "max_rotation", "blocked" (concavities both ways), "lost" (the contact
        could not be read back after a bridge) or "mismatch" (the readings do not fit the part: a
        burr, a dent, debris, a part that is not its model; ``belief.mismatch`` says where).
    reversals : int
        Direction changes (a concavity ahead or bridged, or the direction rule).
    regrasps : int
        Times the jaw was lifted and slid along itself at the end of its span.
    bridges : int
        Steps that bridged a concavity (or were refused) and were undone.
    history : tuple of (rotation rad, map_arc mm, mass, true_arc mm)
        The belief at every check, with the truth where the rig knows it.
    arcs, turns : tuple of float
        The cumulative signed arc (mm) and net rotation (rad) given to the filter.
    true_arcs : tuple of float
        The true contact (mm) at the same readings (NaN on a real rig).
    segments : tuple of int
        The contact segment of each reading (a regrasp or a bridge starts a new one).
    """

    belief: Belief
    rotation: float
    steps: int
    stopped: str
    reversals: int
    regrasps: int = 0
    bridges: int = 0
    history: tuple[tuple[float, float, float, float], ...] = field(repr=False, default=())
    arcs: tuple[float, ...] = field(repr=False, default=())
    turns: tuple[float, ...] = field(repr=False, default=())
    true_arcs: tuple[float, ...] = field(repr=False, default=())
    segments: tuple[int, ...] = field(repr=False, default=())

    @property
    def estimate_arc(self) -> float:
        return self.belief.map_arc


def spread_by_direction(
    flt: ContactFilter,
    lookahead: float,
    explored: tuple[float, ...] = (0.0, 0.0),
    starts: Sequence[float] | None = None,
) -> tuple[float, ...]:
    """(spread ccw, spread cw) in mm: how far apart hypotheses' predicted arcs move over the next
    ``lookahead`` rad of *unexplored* rotation each way.

    ``starts`` are the hypotheses (start arcs, mm), equally weighted; default: the two
    most probable modes of the belief. For two modes the spread is half the difference
    of their predicted travel: their radii of curvature's difference over the window,
    integrated. ``explored`` is the (lowest, highest) net rotation rolled so far: rolling
    back over it measures the same curvature again, so each way's window starts where
    the rolled range ends. A hypothesis that would have to bridge a concavity that way
    counts as not moving.
    """
    if starts is None:
        starts = [m.start_arc for m in flt.belief().modes[:2]]
    idx = flt.tracks.node_at(starts)
    return tuple(float(np.std(moved)) for moved, _ in _windows(flt, idx, lookahead, explored))


def _windows(
    flt: ContactFilter, idx: NDArray[np.intp], lookahead: float, explored: tuple[float, ...]
) -> list[tuple[NDArray[np.float64], float]]:
    """Counter-clockwise, then clockwise: each start's contact travel over the next ``lookahead`` rad of
    unexplored rotation that way (0 where it would bridge a concavity), and where that window starts (rad)."""
    jaw = _jaw_now(flt, idx)
    out = []
    for sign, edge in ((1.0, explored[1]), (-1.0, explored[0])):
        a, ok_a = flt.tracks.roll(idx, edge, **jaw)
        b, ok_b = flt.tracks.roll(idx, edge + sign * lookahead, **jaw)
        out.append((np.where(ok_a & ok_b, b - a, 0.0), edge))
    return out


#: How many of the most probable starts the information-seeking rule weighs (:func:`information_by_direction`):
#: beyond a few dozen the rest carry too little of the belief to change which way is better.
SEEK_HYPOTHESES = 64


def information_by_direction(
    flt: ContactFilter,
    lookahead: float,
    explored: tuple[float, ...] = (0.0, 0.0),
    hypotheses: int = SEEK_HYPOTHESES,
) -> tuple[float, ...]:
    """(ccw, cw): how much the next unexplored stretch each way is expected to raise the probability of
    the right place, per radian of rolling.

    Over the most probable ``hypotheses`` starts, weighted by the posterior: each start predicts the
    contact's travel over the next ``lookahead`` rad of *unexplored* rotation that way. Were start i the
    truth, the readings would show its travel, and the belief would weigh each start j by its weight times
    the likelihood of that travel, exp(−Δ²/4σ²) (Δ the two travels' difference, σ the filter's reading
    noise times its noise scale: a travel is the difference of two readings); the probability it then puts
    on i's *place* (the starts whose present contacts are within the filter's radius of i's) is what the
    belief would know. Its expectation over i, less what the belief puts on the right place now, is the
    gain; it is divided by the rotation it costs: the way back to that way's unexplored edge, then
    ``lookahead``. Telling two starts apart that sit at the same place gains nothing, nor does telling
    apart the offsets within two places that stay alike (a symmetric part's twin places). A start that
    cannot roll that way without bridging a concavity counts as not moving (as :func:`spread_by_direction`).

    Returns
    -------
    tuple of float, per rad
        Expected gain in the probability of the right place per radian of rolling counter-clockwise,
        clockwise.
    """
    w = flt.posterior()
    top = most_probable(w, max(int(hypotheses), 2))  # equal weights by index, on every machine
    top = top[w[top] > 0]
    if top.size < 2:
        return (0.0, 0.0)
    wt = w[top] / w[top].sum()
    present = flt.present()[top]
    same = np.abs(flt.part.arc_offset(present[:, None], present[None, :])) <= flt.radius
    now = float(wt @ (same @ wt))
    variance = 2.0 * (flt.sd_position * flt.noise_scale()) ** 2
    out: list[float] = []
    for moved, edge in _windows(flt, top, lookahead, explored):
        # row i: the belief over starts j were i the truth and its travel read
        after = wt[None, :] * np.exp(-((moved[:, None] - moved[None, :]) ** 2) / (2.0 * variance))
        after /= after.sum(axis=1, keepdims=True)
        right = float(wt @ np.sum(after * same, axis=1))
        out.append(max(right - now, 0.0) / (abs(edge - flt.turn) + lookahead))
    return tuple(out)


def clear_ahead(flt: ContactFilter, direction: int, lookahead: float, at: float | None = None) -> float:
    """Probability that the jaw can roll ``lookahead`` rad further ``direction``-wise without the
    contact leaving its convex stretch (over every hypothesis with weight).

    ``at`` is the net rotation (rad) to roll on from (default: the present one).
    """
    w = flt.posterior()
    top = np.flatnonzero(w > 1e-9 * w.max())
    _, ok = flt.tracks.roll(top, (flt.turn if at is None else at) + direction * lookahead, **_jaw_now(flt, top))
    return float(np.sum(w[top][ok]) / np.sum(w[top]))


def _jaw_now(flt: ContactFilter, idx: NDArray[np.intp]) -> dict[str, Any]:
    """Where the jaw touches now, as :meth:`localizer.ModeTracks.roll` takes it (nothing before a reading)."""
    if not math.isfinite(flt.jaw_position):
        return {}
    return {"jaw": flt.jaw_position, "at": flt.current[idx]}


@dataclass(frozen=True)
class ReactivePolicy:
    """How the reactive method rolls and when it stops (module notes, rules 1–7).

    Attributes
    ----------
    step : float, rad
        Rolling step (paper: 0.2°, :data:`localizer.ROLL_STEP`).
    n : int
        Samples averaged per reading.
    confidence : float
        Probability within the success radius that stops the rolling.
    max_rotation : float, rad
        Budget of rolled rotation, both directions counted.
    direction : {1, -1, None}
        First rolling direction (counter-clockwise is 1; None: 1).
    check_every : int
        Steps between checks of the stopping and direction rules.
    lookahead : float, rad
        Rotation over which the direction rule compares the two ways.
    bridge_jump : float, mm
        A step whose contact moves more than this on the jaw has bridged a concavity.
    end_margin : float, mm
        The contact is kept this far inside the calibrated span of the jaw; there the jaw
        is lifted by ``backoff`` mm, slid along itself and put back (a regrasp).
    backoff : float, mm
        How far the jaw is lifted off for a regrasp or after a bridge.
    min_spread : float, mm
        The baseline direction rule (``seek=False``) turns round when the window ahead separates the
        two leading modes' predicted arcs by less than this and the other way's window by more than
        three times this (0: never turn round by choice).
    confirm : int
        Checks in a row at which the belief must reach ``confidence`` before the rolling stops.
    reread_jump : float, mm
        A reading whose contact moved more than this on the jaw in one step is read twice more and the
        middle of the three kept (a spike of the wrist's DAQ is one reading; a real jump reads the same).
    seek : bool
        The direction rule seeks information (the default): while the belief has two or more modes, turn
        round when the other way is expected to raise the probability of the right place more per radian of
        rolling, the way back to it included, by the factor ``seek_margin`` (:func:`information_by_direction`).
        False: the baseline, the two leading modes' spread rule (``min_spread``).
    seek_margin : float
        How much more the other way must be expected to gain, per radian, before the jaw turns round
        (at least 1; above, so that two ways about as good do not rock the jaw).
    """

    step: float = ROLL_STEP
    n: int = 32
    confidence: float = CONFIDENCE
    max_rotation: float = MAX_ROTATION
    direction: int | None = None
    check_every: int = 5
    lookahead: float = math.radians(15.0)
    bridge_jump: float = BRIDGE_JUMP
    end_margin: float = 5.0
    backoff: float = 2.0
    min_spread: float = 0.05
    confirm: int = CONFIRM
    reread_jump: float = 1.0
    seek: bool = True
    seek_margin: float = 1.5

    def __post_init__(self) -> None:
        if not (math.isfinite(self.step) and self.step > 0):
            raise RigError(f"step={self.step!r} rad must be positive")
        if not (math.isfinite(self.max_rotation) and self.max_rotation > 0):
            raise RigError(f"max_rotation={self.max_rotation!r} rad must be positive")
        if self.direction not in (1, -1, None):
            raise RigError(f"direction={self.direction!r}: use 1 (counter-clockwise), -1 or None")
        if not 0 < self.confidence < 1:
            raise RigError(f"confidence={self.confidence!r} must be in (0, 1)")
        if not (math.isfinite(self.seek_margin) and self.seek_margin >= 1):
            raise RigError(f"seek_margin={self.seek_margin!r} must be at least 1")
        for name in ("confirm", "check_every", "n"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise RigError(f"{name}={value!r} must be a whole number ≥ 1")


#: The default policy (the studies' and the command line's unless they say otherwise).
REACTIVE_POLICY = ReactivePolicy()
