"""Scoring several localization methods on the same Monte Carlo trial (a study's ``methods``).

- ``paper`` / ``likelihood``: the fixed rolls' (L, Ω) and the localizer's rule.
- ``particle``: :class:`localizer.ParticleFilter` over the fixed rolls' step-by-step readings.
- ``grid``: :class:`localizer.ContactFilter` (the reactive method's filter) over the same readings:
  what the filter alone does with the paper's 35°, without the reactive rolling.
- ``reactive``: :func:`driver.reactive.localize_reactively` on a fresh rig with the same seed (the
  same machined part and noise) from the same start.

Each method also gets a curve: its error (mm) had it stopped after every 5° of rolled rotation,
stored as ``"5:0.412 10:0.108 ..."`` in the ``<method>_curve`` column.
"""

from __future__ import annotations

import math

import numpy as np

MARK_DEG = 5.0


def _curve(pairs) -> str:
    return " ".join(f"{r:g}:{e:.4f}" for r, e in pairs)


def parse_curve(text: str) -> list:
    """[(rotation deg, error mm), ...] of a ``<method>_curve`` cell."""
    out = []
    for item in str(text or "").split():
        r, e = item.split(":")
        out.append((float(r), float(e)))
    return out


def fixed_readings(run, part) -> dict:
    """The fixed rolls as one step sequence: cumulative signed arc z (mm), net measured turn (rad),
    the true contact (mm), and each step's signed arc."""
    from localizer import arc_from_jaw_positions

    z, turns, truth, steps = [0.0], [0.0], [run.rolls[0].truth[0][0]], []
    phi0 = run.rolls[0].angles[0]
    for r in run.rolls:
        sign = 1.0 if r.step > 0 else -1.0
        for i in range(1, len(r.positions)):
            a = sign * arc_from_jaw_positions(r.positions[i - 1:i + 1], r.step, r.offset)
            steps.append(a)
            z.append(z[-1] + a)
            turns.append(r.angles[i] - phi0)
            truth.append(r.truth[i][0])
    return {"z": np.array(z), "turn": np.array(turns), "truth": np.array(truth), "steps": np.array(steps)}


def _err(part, est, truth) -> float:
    if not (math.isfinite(est) and math.isfinite(truth)):
        return math.inf
    return abs(float(part.arc_offset(est, truth)))


def _marks(turns) -> list:
    """(mark deg, index of the first reading at or past it) for every 5° of |turn|."""
    rot = np.degrees(np.abs(turns))
    out = []
    mark = MARK_DEG
    while mark <= rot[-1] + 1e-9:
        idx = int(np.argmax(rot >= mark - 1e-9))
        out.append((mark, idx))
        mark += MARK_DEG
    return out


def score_paper(study, part, run, seq, rule: str) -> dict:
    """The fixed rolls under a localizer rule, and the same rule on shorter prefixes."""
    from localizer import localize

    loc = run.localization if rule == run.localization.rule else localize(
        part, run.estimates, rule=rule, direction="ccw" if run.rolls[0].step > 0 else "cw",
        sd_length=study.sd_length, sd_turn=math.radians(study.sd_turn_deg))
    best = loc.best
    est = best.end_arc if best is not None else math.nan
    final = _err(part, est, seq["truth"][-1])
    share = study.rolls_deg[0] / sum(study.rolls_deg) if len(study.rolls_deg) > 1 else 1.0
    sign = 1.0 if run.rolls[0].step > 0 else -1.0
    curve = []
    for mark, k in _marks(seq["turn"]):
        k1 = max(1, int(round(k * share)))
        segs = [(0, k1)] + ([(k1, k)] if k > k1 else [])
        rolls = [(sign * (seq["z"][b] - seq["z"][a]), seq["turn"][b] - seq["turn"][a]) for a, b in segs]
        try:
            sub = localize(part, rolls, rule=rule, direction="ccw" if sign > 0 else "cw",
                           sd_length=study.sd_length, sd_turn=math.radians(study.sd_turn_deg)).best
            e = _err(part, sub.end_arc, seq["truth"][k]) if sub is not None else math.inf
        except Exception:  # a prefix the rule cannot take counts as a miss
            e = math.inf
        curve.append((mark, e))
    return {"estimate_arc": est, "error_mm": final, "rotation_deg": float(sum(abs(r) for r in study.rolls_deg)),
            "curve": curve}


def _score_sequential(study, part, seq, update, estimate) -> dict:
    """A filter fed the fixed rolls' readings one by one, its estimate at every 5° and at the end."""
    marks = dict((k, m) for m, k in _marks(seq["turn"]))
    curve = []
    for j in range(1, len(seq["z"])):
        update(float(seq["z"][j]), float(seq["turn"][j]))
        if j in marks:
            curve.append((marks[j], _err(part, estimate(), seq["truth"][j])))
    est = estimate()
    return {"estimate_arc": est, "error_mm": _err(part, est, seq["truth"][-1]),
            "rotation_deg": float(sum(abs(r) for r in study.rolls_deg)), "curve": curve}


def score_particle(study, part, seq, seed: int) -> dict:
    """The particle filter over the fixed rolls' readings."""
    from localizer import ParticleFilter

    o = study.particle
    pf = ParticleFilter(part, particles=o.particles, sd_position=o.sd_position, process=o.process,
                        radius=study.success_radius, seed=seed)
    return _score_sequential(study, part, seq, pf.update, lambda: pf.estimate()[0])


def score_grid(study, part, noise, seq) -> dict:
    """The reactive method's grid filter over the fixed rolls' readings (no reactive rolling)."""
    flt = reactive_filter(study, part, noise)
    return _score_sequential(study, part, seq, flt.update, lambda: flt.belief().map_arc)


def reactive_filter(study, part, noise):
    """The ContactFilter a study's [reactive] options describe (sd_slope "auto" from the noise model)."""
    from localizer import ContactFilter, machining_slope

    o = study.reactive
    slope = o.sd_slope
    if slope is None:
        # 5x the model's RMS slope: machined parts vary (measured: 0.8e-3 to 1.9e-3 rad RMS at the
        # paper preset, whose model RMS is 0.6e-3), and the basis' coefficients are not its values
        slope = max(5.0 * machining_slope(noise.machining_error, noise.machining_wavelength, part.perimeter), 5e-4)
    return ContactFilter(part, sd_position=o.sd_position, sd_scale=o.sd_scale, sd_slope=slope,
                         radius=study.success_radius, confidence=o.confidence)


def score_reactive(study, part, noise, cal, start: float, rig_seed: int) -> dict:
    """The reactive filter from the same start on a rig with the same seed."""
    from driver.reactive import localize_reactively
    from sim2d import SimRig

    o = study.reactive
    rig = SimRig(part, noise=noise, seed=rig_seed, engine=study.engine)
    res = localize_reactively(rig, part, calibration=cal, filter=reactive_filter(study, part, noise),
                              approach_pose=rig.approach_pose(start, jaw_position=-40.0, standoff=1.0),
                              step=math.radians(study.step_deg), confidence=o.confidence,
                              max_rotation=math.radians(o.max_rotation_deg), check_every=o.check_every,
                              min_spread=o.min_spread)
    truth = rig.truth()["contact_arc"]
    final = _err(part, res.estimate_arc, truth)
    rot = math.degrees(res.rotation)
    curve = []
    mark = MARK_DEG
    hist = res.history
    while mark <= o.max_rotation_deg + 1e-9:
        if rot <= mark + 1e-9:
            e = final                      # stopped (sure, or out of budget) before this mark
        else:
            before = [h for h in hist if math.degrees(h[0]) <= mark + 1e-9]
            e = _err(part, before[-1][1], before[-1][3]) if before else math.inf
        curve.append((mark, e))
        mark += MARK_DEG
    return {"estimate_arc": res.estimate_arc, "error_mm": final, "rotation_deg": rot, "curve": curve,
            "stopped": res.stopped}


def score_methods(study, part, noise, cal, run, start: float, rig_seed: int, true_arc: float) -> dict:
    """The ``<method>_<column>`` cells of one trial for every method of ``study``."""
    seq = fixed_readings(run, part)
    out = {}
    for m in study.methods:
        try:
            if m in ("paper", "likelihood"):
                r = score_paper(study, part, run, seq, m)
            elif m == "particle":
                r = score_particle(study, part, seq, seed=rig_seed)
            elif m == "grid":
                r = score_grid(study, part, noise, seq)
            else:
                r = score_reactive(study, part, noise, cal, start, rig_seed)
        except Exception:  # this method failed on this trial: a miss, the others still count
            r = {"estimate_arc": math.nan, "error_mm": math.inf, "rotation_deg": math.nan, "curve": []}
        out.update({f"{m}_success": int(r["error_mm"] < study.success_radius), f"{m}_error_mm": r["error_mm"],
                    f"{m}_estimate_arc": r["estimate_arc"], f"{m}_rotation_deg": r["rotation_deg"],
                    f"{m}_curve": _curve(r["curve"])})
    return out
