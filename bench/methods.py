"""Scoring several localization methods on the same Monte Carlo trial (a study's ``methods``).

- ``paper`` / ``likelihood``: the fixed rolls' (L, Ω) and the localizer's rule.
- ``particle``: :class:`localizer.ParticleFilter` over the fixed rolls' step-by-step readings.
- ``grid``: :class:`localizer.ContactFilter` (the reactive method's filter) over the same readings:
  what the filter alone does with the paper's 35°, without the reactive rolling.
- ``reactive``: :func:`driver.jaw.reactive.localize_reactively` on a fresh rig with the same seed (the
  same machined part and noise) from the same start.

Each method also gets a curve: its error (mm) had it stopped after every 5° of rolled rotation,
stored as ``"5:0.412 10:0.108 ..."`` in the ``<method>_curve`` column, and the Cramér–Rao bound of
its final place from the readings it took (``<method>_bound_mm``, :func:`method_bound`). The methods
stand in one registry, :data:`SCORERS`; :func:`score_methods` scores a trial's every method by it, and
:func:`score_trial` a trial's rolling (either finger's) as a whole.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple, cast

import numpy as np
import numpy.typing as npt

from .columns import MethodCells, ScoreCells, Scored
from .reactive_method import reactive_filter, score_reactive, score_wheel
from .scoring import (
    ENCODER_SLACK_DEG,
    MARK_DEG,
    FloatArray,
    MethodResult,
    RuleResult,
    boundary_error,
    broken_trial,
    curve_cell,
    mass_cell,
)
from .straight_trial import StraightRoll
from .wheel_trial import WheelRoll

if TYPE_CHECKING:
    from driver.jaw import Calibration, RollResult
    from localizer import Candidate, ContactFilter, Localization, Outline, Part
    from sim2d import NoiseModel, WorldChange

    from .study import Study
    from .trial_context import TrialContext

__all__ = ["TrialInputs", "Scorer", "SCORERS", "score_trial", "score_methods", "score_rule", "broken_rule"]


def fixed_readings(rolls: Sequence[RollResult], part: Part | Outline) -> dict[str, FloatArray]:
    """The fixed rolls as one step sequence: cumulative signed arc z (mm), net measured turn (rad),
    the true contact (mm), each step's signed arc, and the contact's place on the jaw (mm)."""
    from driver.jaw import step_sequence

    seq = step_sequence([(r.positions, r.angles, r.step, r.offset) for r in rolls])
    truth = [rolls[0].truth[0].contact_arc] + [t.contact_arc for r in rolls for t in r.truth[1 : len(r.positions)]]
    return {**seq, "truth": np.array(truth)}


def reading_noise(seq: dict[str, FloatArray], part: Part | Outline, noise: NoiseModel) -> tuple[float, float]:
    """(sd_position mm, sd_turn rad): one reading's own noise on this trial's rig, for the bound.

    The travel's: the fixed rolls' readings against the truth, first differences (which cancel the
    smooth errors: machining, the calibration's shape, drift, which the bound does not model), over
    √2. The angle's: the encoder's quantization, step/√12 (nan without one: no bound).
    """
    truth = np.asarray(seq["truth"], dtype=float)
    steps = np.diff(truth)
    travel = np.concatenate([[0.0], np.cumsum(steps - part.perimeter * np.round(steps / part.perimeter))])
    residual = np.asarray(seq["z"], dtype=float) - travel
    sd_position = float(np.std(np.diff(residual)) / math.sqrt(2.0)) if residual.size > 2 else math.nan
    sd_turn = noise.encoder_step / math.sqrt(12.0) if noise.encoder_step > 0 else math.nan
    return sd_position, sd_turn


def method_bound(
    part: Part | Outline,
    path: npt.ArrayLike,
    segments: npt.ArrayLike | None,
    sds: tuple[float, float],
    sd_scale: float,
    noise: NoiseModel,
) -> float:
    """The Cramér–Rao bound (mm) of a method's final place from the readings along ``path``
    (:func:`localizer.trial_bound`), with the rig's ``noise`` model's machining deviation as a nuisance;
    nan where the noise has no level to bound with."""
    from localizer import QueryError, TrialNoise, trial_bound

    sd_position, sd_turn = sds
    if not (sd_position > 0 and sd_turn > 0):
        return math.nan
    model = TrialNoise(
        sd_position=sd_position,
        sd_turn=sd_turn,
        sd_scale=sd_scale,
        machining_error=noise.machining_error,
        machining_wavelength=noise.machining_wavelength,
    )
    try:
        return trial_bound(part, path, model, segments=segments)
    except QueryError:  # a path the rig did not know (a real rig's NaN truth)
        return math.nan


def _sd_scale(study: Study) -> float:
    """The scale's prior standard deviation: the study's [reactive] sd_scale, else the filter's default."""
    from localizer import SCALE_SD

    given = study.reactive.sd_scale
    return float(given if given is not None else SCALE_SD)


def _marks(turns: FloatArray) -> list[tuple[float, int]]:
    """(mark deg, index of the first reading at or past it) for every 5° of |turn|.

    A mark counts as reached within the arm encoder's resolution (0.03°): the measured turn of a
    commanded 35° may read 34.98°."""
    rot = np.degrees(np.abs(turns))
    out = []
    mark = MARK_DEG
    while mark <= rot[-1] + ENCODER_SLACK_DEG:
        idx = int(np.argmax(rot >= mark - ENCODER_SLACK_DEG))
        out.append((mark, idx))
        mark += MARK_DEG
    return out


def _localize(
    study: Study,
    part: Part | Outline,
    rolls: Sequence[RollResult],
    rule: str,
    cache: dict[str, Localization | Exception],
) -> Localization | Exception:
    """The localizer's rule on the fixed rolls' (L, Ω), once per trial and rule (a failure is kept too)."""
    from localizer import localize

    if rule not in cache:
        try:
            cache[rule] = localize(
                part,
                [(r.length, r.turn) for r in rolls],
                rule=rule,
                direction="ccw" if rolls[0].step > 0 else "cw",
                sd_length=study.sd_length,
                sd_turn=math.radians(study.sd_turn_deg),
            )
        except Exception as exc:  # noqa: BLE001 - the rule's failure is its result
            cache[rule] = exc
    return cache[rule]


def _mass(part: Part | Outline, candidates: Iterable[Candidate], best: Candidate, radius: float) -> float:
    """Stated probability of the candidates whose present contact is within ``radius`` of the best's."""
    return float(
        sum(c.probability for c in candidates if abs(float(part.arc_offset(c.end_arc, best.end_arc))) < radius)
    )


def broken_rule(text: str) -> RuleResult:
    """The study's own columns of a localizer rule that failed, or had no rolls to take: ``text`` why."""
    return {
        "estimate_arc": math.nan,
        "error_mm": math.inf,
        "candidates": 0,
        "probability": 0.0,
        "ambiguous": 0,
        "mass": "",
        "failure": text,
    }


def score_rule(
    study: Study,
    part: Part | Outline,
    rolls: Sequence[RollResult],
    rule: str,
    true_arc: float,
    cache: dict[str, Localization | Exception],
) -> RuleResult:
    """The localizer's ``rule`` on the fixed rolls: the study's own columns, and a method's cells."""
    loc = _localize(study, part, rolls, rule, cache)
    if isinstance(loc, Exception):
        return broken_rule(f"{type(loc).__name__}: {loc}"[:200])
    best = loc.best
    if best is None:
        return {
            "estimate_arc": math.nan,
            "error_mm": math.inf,
            "candidates": 0,
            "probability": 0.0,
            "ambiguous": int(loc.ambiguous),
            "mass": 0.0,
            "failure": "",
        }
    return {
        "estimate_arc": best.end_arc,
        "error_mm": boundary_error(part, best.end_arc, true_arc),
        "candidates": len(loc.candidates),
        "probability": best.probability,
        "ambiguous": int(loc.ambiguous),
        "mass": _mass(part, loc.candidates, best, study.success_radius),
        "failure": "",
    }


def score_paper(
    study: Study,
    part: Part | Outline,
    rolls: Sequence[RollResult],
    seq: dict[str, FloatArray],
    rule: str,
    cache: dict[str, Localization | Exception],
) -> MethodResult:
    """The fixed rolls under a localizer rule, and the same rule on shorter prefixes."""
    from localizer import localize

    own = score_rule(study, part, rolls, rule, seq["truth"][-1], cache)
    if own["failure"]:
        raise _MethodError(own["failure"])
    share = study.rolls_deg[0] / sum(study.rolls_deg) if len(study.rolls_deg) > 1 else 1.0
    sign = 1.0 if rolls[0].step > 0 else -1.0
    curve, masses = [], []
    for mark, k in _marks(seq["turn"]):
        k1 = max(1, int(round(k * share)))
        segs = [(0, k1)] + ([(k1, k)] if k > k1 else [])
        pieces = [(sign * (seq["z"][b] - seq["z"][a]), seq["turn"][b] - seq["turn"][a]) for a, b in segs]
        try:
            loc = localize(
                part,
                pieces,
                rule=rule,
                direction="ccw" if sign > 0 else "cw",
                sd_length=study.sd_length,
                sd_turn=math.radians(study.sd_turn_deg),
            )
            sub = loc.best
            e = boundary_error(part, sub.end_arc, seq["truth"][k]) if sub is not None else math.inf
            p = _mass(part, loc.candidates, sub, study.success_radius) if sub is not None else 0.0
        except Exception:  # noqa: BLE001 - a prefix the rule cannot take counts as a miss
            e, p = math.inf, math.nan
        curve.append((mark, e))
        masses.append((mark, p))
    return {
        "estimate_arc": own["estimate_arc"],
        "error_mm": own["error_mm"],
        "rotation_deg": float(sum(abs(r) for r in study.rolls_deg)),
        "curve": curve,
        "mass_curve": masses,
        "stopped": "fixed",
        "mass": own["mass"],
    }


class _MethodError(Exception):
    """A method's own failure, its text already formatted."""


def _score_sequential(
    study: Study,
    part: Part | Outline,
    seq: dict[str, FloatArray],
    update: Callable[[float, float, float], object],
    estimate: Callable[[], tuple[float, float]],
) -> MethodResult:
    """A filter fed the fixed rolls' readings one by one, its estimate at every 5° and at the end.

    ``update(z, turn, jaw)``; ``estimate()`` gives (present contact mm, stated mass)."""
    marks = dict((k, m) for m, k in _marks(seq["turn"]))
    curve, masses = [], []
    for j in range(1, len(seq["z"])):
        update(float(seq["z"][j]), float(seq["turn"][j]), float(seq["jaw"][j]))
        if j in marks:
            at, stated = estimate()
            curve.append((marks[j], boundary_error(part, at, seq["truth"][j])))
            masses.append((marks[j], stated))
    est, mass = estimate()
    return {
        "estimate_arc": est,
        "error_mm": boundary_error(part, est, seq["truth"][-1]),
        "rotation_deg": float(sum(abs(r) for r in study.rolls_deg)),
        "curve": curve,
        "mass_curve": masses,
        "stopped": "fixed",
        "mass": mass,
    }


def score_particle(study: Study, part: Part | Outline, seq: dict[str, FloatArray], seed: int) -> MethodResult:
    """The particle filter over the fixed rolls' readings."""
    from localizer import ParticleFilter

    o = study.particle
    pf = ParticleFilter(
        part,
        particles=o.particles,
        sd_position=o.sd_position,
        process=o.process,
        radius=study.success_radius,
        seed=seed,
    )
    return _score_sequential(study, part, seq, lambda z, t, d: pf.update(z, t), pf.estimate)


def score_grid(study: Study, part: Part | Outline, noise: NoiseModel, seq: dict[str, FloatArray]) -> MethodResult:
    """The reactive method's grid filter over the fixed rolls' readings (no reactive rolling)."""
    flt = reactive_filter(study, part, noise)
    flt.touch(float(seq["jaw"][0]))

    def estimate() -> tuple[float, float]:
        b = flt.belief()
        return b.map_arc, b.mass

    return _score_sequential(study, part, seq, flt.update, estimate)


@dataclass(frozen=True)
class TrialInputs:
    """What every method of a trial is scored from: the study, the part and its noise model, the wrist's
    calibration, the fixed rolls and their step-by-step readings (None where they could not run), the
    start (mm) and the rig's seed the reactive method rolls from, the rules' results cached within the
    trial, the reactive method's filter class (None: :class:`localizer.ContactFilter`) and the world."""

    study: Study
    part: Part | Outline
    noise: NoiseModel
    cal: Calibration
    rolls: Sequence[RollResult] | None
    seq: dict[str, FloatArray] | None
    start: float
    rig_seed: int
    rules: dict[str, Localization | Exception]
    filter_class: type[ContactFilter] | None
    change: WorldChange | None


class Scorer(NamedTuple):
    """One method of the registry: how it is scored on a trial (its result cells, :func:`score_methods`
    completes them), and whether it needs the fixed rolls (it fails with them where they could not run)."""

    score: Callable[[TrialInputs, str], MethodResult]
    fixed_rolls: bool


def _rule(t: TrialInputs, m: str) -> MethodResult:
    return score_paper(
        t.study, t.part, cast("Sequence[RollResult]", t.rolls), cast("dict[str, FloatArray]", t.seq), m, t.rules
    )


#: Every method a study may name, by name (:data:`bench.columns.METHODS` is the same list, in order).
SCORERS: dict[str, Scorer] = {
    "paper": Scorer(_rule, True),
    "likelihood": Scorer(_rule, True),
    "particle": Scorer(
        lambda t, m: score_particle(t.study, t.part, cast("dict[str, FloatArray]", t.seq), seed=t.rig_seed), True
    ),
    "grid": Scorer(lambda t, m: score_grid(t.study, t.part, t.noise, cast("dict[str, FloatArray]", t.seq)), True),
    "reactive": Scorer(
        lambda t, m: score_reactive(t.study, t.part, t.noise, t.cal, t.start, t.rig_seed, t.filter_class, t.change),
        False,
    ),
}


def score_methods(trial: TrialInputs, fixed_failure: str = "") -> tuple[dict[str, MethodCells], int | None]:
    """The cells of every method of the trial's study, each scored on its own, by name; and the reactive
    method's rig's spiked readings (None without it).

    Where the fixed rolls could not run in the trial's world (``trial.rolls`` None), ``fixed_failure``
    says why, and the fixed-roll methods fail with it.
    """
    study, part, seq, noise = trial.study, trial.part, trial.seq, trial.noise
    sds = reading_noise(seq, part, noise) if seq is not None else (math.nan, math.nan)
    sd_scale = _sd_scale(study)
    fixed_bound: list[float] = []  # the fixed-roll methods share one path, so one bound
    out: dict[str, MethodCells] = {}
    spikes: int | None = None
    for m in study.methods:
        try:
            scorer = SCORERS[m]
            if seq is None and scorer.fixed_rolls:
                raise _MethodError(fixed_failure)
            r = scorer.score(trial, m)
            if "spikes" in r:
                spikes = r["spikes"]
            r["failure"] = ""
        except Exception as exc:  # noqa: BLE001 - this method failed on this trial; the others still count
            text = str(exc) if isinstance(exc, _MethodError) else f"{type(exc).__name__}: {exc}"
            r = {
                "estimate_arc": math.nan,
                "error_mm": math.inf,
                "rotation_deg": math.nan,
                "curve": [],
                "stopped": "error",
                "mass": "",
                "failure": text[:200],
            }
        if r["failure"]:
            bound = math.nan
        elif "path" in r:  # the method rolled on its own
            path, segments = r["path"]
            bound = method_bound(part, path, segments, sds, sd_scale, noise)
        else:
            if not fixed_bound:
                assert seq is not None  # the fixed-roll methods failed above without their rolls
                fixed_bound.append(method_bound(part, seq["truth"], None, sds, sd_scale, noise))
            bound = fixed_bound[0]
        out[m] = {
            "success": int(r["error_mm"] < study.success_radius),
            "error_mm": r["error_mm"],
            "estimate_arc": r["estimate_arc"],
            "rotation_deg": r["rotation_deg"],
            "curve": curve_cell(r["curve"]),
            "stopped": r["stopped"],
            "mass": r["mass"],
            "failure": r["failure"],
            "bridges": r.get("bridges", ""),
            "bound_mm": bound,
            "mismatch_arc": r.get("mismatch_arc", ""),
            "mass_curve": mass_cell(r.get("mass_curve", [])),
        }
    return out, spikes


def score_trial(ctx: TrialContext, rolled: StraightRoll | WheelRoll) -> Scored:
    """A trial's scores: a wheel's run as the ``reactive`` method (:func:`bench.reactive_method.score_wheel`);
    the straight jaw's fixed rolls under the study's rule (the trial's own cells) and every method of the
    study on that same trial, the trial's estimate then the first method's."""
    if isinstance(rolled, WheelRoll):
        return score_wheel(ctx.study, ctx.part, rolled.run, rolled.true_arc, rolled.failure, rolled.spikes)
    s = ctx.study
    if rolled.failure:
        return broken_trial(s.methods, rolled.failure)
    assert rolled.cal is not None  # a trial that did not break was calibrated
    rule = s.method if s.method in ("paper", "likelihood") else "paper"
    rules: dict[str, Localization | Exception] = {}
    own = (
        score_rule(s, ctx.part, rolled.rolls, rule, rolled.true_arc, rules)
        if rolled.rolls is not None
        else broken_rule(rolled.fixed_failure)
    )
    cells: ScoreCells = {
        "true_arc": rolled.true_arc,
        "estimate_arc": own["estimate_arc"],
        "error_mm": own["error_mm"],
        "success": int(own["error_mm"] < s.success_radius),
        "candidates": own["candidates"],
        "probability": own["probability"],
        "ambiguous": own["ambiguous"],
        "failure": "" if s.methods else own["failure"],
    }
    if not s.methods:
        return Scored(cells, {}, rolled.spikes)
    seq = fixed_readings(rolled.rolls, ctx.part) if rolled.rolls is not None else None
    trial = TrialInputs(
        s,
        ctx.part,
        ctx.noise,
        rolled.cal,
        rolled.rolls,
        seq,
        rolled.start,
        rolled.rig_seed,
        rules,
        ctx.spec.filter_class,
        rolled.change,
    )
    methods, spikes = score_methods(trial, rolled.fixed_failure)
    first = methods[s.methods[0]]
    cells.update({"success": first["success"], "error_mm": first["error_mm"], "estimate_arc": first["estimate_arc"]})
    return Scored(cells, methods, rolled.spikes if spikes is None else spikes)
