"""A study's table summed up: success with its Wilson interval, sure and sure-and-wrong, rotation, the
error over the bound, reliability (stated against actual), per level and method; summary.json's content
and the lines printed at the end of a run."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TypeAlias

import numpy as np
import numpy.typing as npt

from localizer import load_part

from .study import Study

FloatArray: TypeAlias = npt.NDArray[np.float64]

__all__ = [
    "wilson",
    "json_safe",
    "cell_number",
    "quantile",
    "summarize",
    "method_detail",
    "error_over_bound",
    "NEAR_DEFECT_MM",
    "mismatch_near",
    "summarize_methods",
    "sure_by_rotation",
    "rotation_marks",
    "at_marks",
    "RELIABILITY_BINS",
    "reliability",
    "FULL_BIN",
    "binned",
    "calibration",
    "calibration_of",
    "print_summary",
]


def wilson(successes: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """Wilson 95% interval of a success rate, (low, high).

    Examples
    --------
    >>> [round(v, 3) for v in wilson(45, 100)]
    [0.356, 0.548]
    >>> wilson(100, 100)[1]
    1.0
    """
    if n == 0:
        return (math.nan, math.nan)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    # in exact arithmetic the interval holds p; rounding at p = 1 (or 0) must not put it outside
    return (max(0.0, min(p, centre - half)), min(1.0, max(p, centre + half)))


def json_safe(value: object) -> object:
    """``value`` with every non-finite float as None: JSON has no NaN or Infinity."""
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def quantile(values: FloatArray, q: float) -> float:
    """The ``q`` quantile of ``values`` (numpy's linear interpolation), infinite where it falls between two
    infinite values (failed trials' errors), where numpy's interpolation would say NaN."""
    with np.errstate(invalid="ignore"):
        out = float(np.quantile(values, q))
    if math.isnan(out) and not np.isnan(values).any():
        return math.inf
    return out


def cell_number(text: Any) -> float:
    """A trials.csv cell as a float (empty: nan)."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


#: A run's reported mismatch interval is *near* a defect when it overlaps the defect's stretch (its centre ±
#: half its length) or lies within this of it, mm (the model-mismatch target's 2 mm, docs/robustness.md).
NEAR_DEFECT_MM = 2.0


@functools.lru_cache(maxsize=64)
def _perimeter(path: str) -> float:
    return float(load_part(path).perimeter)


def mismatch_near(study: Study, m: str, rows: Sequence[dict[str, Any]]) -> int | None:
    """How many of method ``m``'s runs in ``rows`` that ended ``mismatch`` reported an interval near one of
    their world's defects (:data:`NEAR_DEFECT_MM`); None when no row has a defect, or the table has no
    defect lengths (written before ``world_defect_length_mm``)."""
    paths = {Path(p).name: p for p in study.parts}
    near = counted = 0
    for r in rows:
        centres = [float(c) for c in str(r.get("world_defect_arc", "")).split()]
        if not centres:
            continue
        if "world_defect_length_mm" not in r:
            return None
        counted += 1
        cell = str(r.get(f"{m}_mismatch_arc", ""))
        if r.get(f"{m}_stopped") != "mismatch" or cell in ("", "unknown"):
            continue
        lo, hi = (float(v) for v in cell.rsplit("-", 1))
        lengths = [float(v) for v in str(r["world_defect_length_mm"]).split()]
        per = _perimeter(paths[r["part"]])
        span = (hi - lo) % per
        for c, length in zip(centres, lengths):
            ahead = (c - lo) % per  # the defect's centre, forward from the interval's start
            gap = 0.0 if ahead <= span else min(ahead - span, per - ahead)
            if gap <= 0.5 * length + NEAR_DEFECT_MM:
                near += 1
                break
    return near if counted else None


def summarize(study: Study, rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Success rate per level with its 95% interval, error quantiles, failures."""
    levels: list[dict[str, Any]] = []
    for level in range(study.levels):
        sel = [r for r in rows if int(r["level"]) == level]
        n = len(sel)
        ok = sum(int(r["success"]) for r in sel)
        err = np.array([float(r["error_mm"]) for r in sel]) if sel else np.array([])
        levels.append(
            {
                "level": level,
                "parameter": study.parameter,
                "value": study.level_label(level),
                "trials": n,
                "success": ok,
                "success_rate": ok / n if n else None,
                "ci95": list(wilson(ok, n)),
                "error_median_mm": float(np.median(err)) if n else None,
                "error_p90_mm": quantile(err, 0.9) if n else None,
                "ambiguous": sum(int(r["ambiguous"]) for r in sel),
                "broken": sum(bool(r["failure"]) for r in sel),
                "mean_time_s": float(np.mean([float(r["time_s"]) for r in sel])) if n else None,
                "mean_restarts": float(np.mean([float(r["restarts"]) for r in sel])) if n else None,
            }
        )
        if study.methods:
            levels[-1]["methods"] = {m: method_detail(study, m, sel) for m in study.methods}
        if study.fingers and n:
            arcs = np.array([cell_number(r.get("arc_mm", "")) for r in sel], dtype=float)
            levels[-1].update(
                {
                    "jaw": study.level_jaw(level),
                    "reachable": float(np.mean([float(r["reachable"]) for r in sel])),
                    "mean_redraws": float(np.mean([float(r["redraws"]) for r in sel])),
                    "mean_arc_mm": float(np.nanmean(arcs)) if np.isfinite(arcs).any() else None,
                }
            )
    out = {
        "study": study.name,
        "method": study.method,
        "engine": study.engine,
        "noise": study.noise,
        "success_radius": study.success_radius,
        "levels": levels,
    }
    if study.methods:
        out.update(summarize_methods(study, rows))
    return out


def method_detail(study: Study, m: str, rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """One method's record over ``rows``: success, how it stopped, confident and wrong, per part."""
    n = len(rows)
    ok = sum(int(r[f"{m}_success"]) for r in rows)
    rot = np.array([cell_number(r[f"{m}_rotation_deg"]) for r in rows], dtype=float)
    err = np.array([cell_number(r[f"{m}_error_mm"]) for r in rows], dtype=float)
    stopped = [r.get(f"{m}_stopped", "") for r in rows]
    confident = [r for r, st in zip(rows, stopped) if st == "confident"]
    per_part: dict[str, dict[str, int]] = {}
    for r in rows:
        d = per_part.setdefault(r["part"], {"success": 0, "trials": 0})
        d["trials"] += 1
        d["success"] += int(r[f"{m}_success"])
    wrong = sum(1 - int(r[f"{m}_success"]) for r in confident)
    ratio = error_over_bound(m, rows)
    return {
        "success": ok,
        "trials": n,
        "ci95": list(wilson(ok, n)),
        "mean_rotation_deg": float(np.nanmean(rot)) if n and np.isfinite(rot).any() else None,
        "median_rotation_deg": float(np.nanmedian(rot)) if n and np.isfinite(rot).any() else None,
        "error_median_mm": float(np.median(err)) if n else None,
        "confident": len(confident),
        "confident_wrong": wrong,
        "mismatch": stopped.count("mismatch"),
        "mismatch_near": mismatch_near(study, m, rows),
        "confident_wrong_ci95": list(wilson(wrong, len(confident))),
        "stopped": {k: stopped.count(k) for k in sorted(set(stopped)) if k},
        "failures": sum(bool(r.get(f"{m}_failure", "")) for r in rows),
        "per_part": dict(sorted(per_part.items())),
        "error_over_bound_rms": float(np.sqrt(np.mean(ratio**2))) if ratio.size else None,
        "error_over_bound_median": float(np.median(ratio)) if ratio.size else None,
        "bounded_successes": int(ratio.size),
        "calibration": calibration(m, rows),
    }


def error_over_bound(m: str, rows: Sequence[dict[str, Any]]) -> FloatArray:
    """Error / Cramér–Rao bound of method ``m`` over its successful trials that have a finite bound."""
    out = []
    for r in rows:
        bound = cell_number(r.get(f"{m}_bound_mm", ""))
        if int(r[f"{m}_success"]) and math.isfinite(bound) and bound > 0:
            out.append(cell_number(r[f"{m}_error_mm"]) / bound)
    return np.array(out, dtype=float)


def summarize_methods(study: Study, rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """``methods`` {name: success rate} over all trials, with details and success against rotation."""
    rates, details, curves = {}, {}, {}
    sure: dict[str, dict[str, dict[str, float]] | None] = {}
    n = len(rows)
    marks = rotation_marks(study)
    for m in study.methods:
        details[m] = method_detail(study, m, rows)
        rates[m] = details[m]["success"] / n if n else None
        hits = np.array([np.array(at_marks(r[f"{m}_curve"], marks, math.inf)) < study.success_radius for r in rows])
        curves[m] = {f"{k:g}": float(np.mean(hits[:, j])) for j, k in enumerate(marks)} if n else {}
        sure[m] = sure_by_rotation(study, m, rows)
    return {
        "methods": rates,
        "method_details": details,
        "success_by_rotation_deg": curves,
        "sure_by_rotation_deg": sure,
    }


def rotation_marks(study: Study) -> FloatArray:
    """Every 5° mark (``MARK_DEG``) of rotation up to the larger of the reactive budget and the fixed rolls."""
    from .scoring import MARK_DEG

    top = max(study.reactive.max_rotation_deg, sum(abs(a) for a in study.rolls_deg))
    return np.arange(MARK_DEG, top + 1e-9, MARK_DEG)


def at_marks(text: str, marks: npt.ArrayLike, missing: float) -> list[float]:
    """A ``<method>_curve`` or ``<method>_mass_curve`` cell's value at each of ``marks`` (deg): past its last
    mark its last value (a rolling that stopped keeps its last answer), ``missing`` where it has none."""
    from .scoring import parse_curve

    pairs = parse_curve(text)
    values = {round(k, 6): v for k, v in pairs}
    top = max(values) if values else 0.0
    last = pairs[-1][1] if pairs else missing
    return [values.get(round(float(k), 6), last if k > top else missing) for k in np.asarray(marks, dtype=float)]


def sure_by_rotation(study: Study, m: str, rows: Sequence[dict[str, Any]]) -> dict[str, dict[str, float]] | None:
    """Method ``m``'s fraction of trials sure (stated probability at least the study's confidence) and
    sure and wrong (error not within the success radius) at every mark of rotation, {"5": {"sure": ...,
    "sure_wrong": ...}, ...}; a trial keeps its last statement past its last mark. None where the trials
    have no ``<m>_mass_curve`` (studies run before it) or the method states nothing."""
    if not rows or not any(r.get(f"{m}_mass_curve") for r in rows):
        return None
    marks = rotation_marks(study)
    stated = np.array([at_marks(r.get(f"{m}_mass_curve", ""), marks, math.nan) for r in rows])
    errors = np.array([at_marks(r.get(f"{m}_curve", ""), marks, math.inf) for r in rows])
    sure = stated >= study.reactive.confidence
    wrong = sure & ~(errors < study.success_radius)
    n = len(rows)
    return {
        f"{k:g}": {"sure": float(sure[:, j].sum() / n), "sure_wrong": float(wrong[:, j].sum() / n)}
        for j, k in enumerate(marks)
    }


#: Bins of stated confidence in the reliability diagram and the calibration error (fine near 1, where the
#: stops are).
RELIABILITY_BINS = (0.0, 0.1, 0.2, 0.35, 0.5, 0.65, 0.8, 0.9, 0.95, 0.97, 0.99, 0.999, 1.0 + 1e-12)

#: A bin of the reliability diagram this full is held to its promise on its own (the calibration's
#: ``worst_gap``): with fewer trials its actual rate is too uncertain to tell a gap of 0.05 from chance.
FULL_BIN = 30


def reliability(m: str, rows: Sequence[dict[str, Any]]) -> list[tuple[float, float, int]]:
    """(mean stated mass, fraction within the success radius, trials) per bin of stated mass at the end."""
    mass = np.array([cell_number(r.get(f"{m}_mass", "")) for r in rows])
    hit = np.array([int(r[f"{m}_success"]) for r in rows])
    return binned(mass, hit)


def binned(stated: npt.ArrayLike, right: npt.ArrayLike) -> list[tuple[float, float, int]]:
    """(mean stated, fraction right, count) per bin of :data:`RELIABILITY_BINS` that holds any of the
    finite ``stated`` probabilities (``right``: 1 or 0 each)."""
    p, hit = np.asarray(stated, dtype=float), np.asarray(right, dtype=float)
    out = []
    for lo, hi in zip(RELIABILITY_BINS[:-1], RELIABILITY_BINS[1:]):
        sel = np.isfinite(p) & (p >= lo) & (p < hi)
        if sel.any():
            out.append((float(p[sel].mean()), float(hit[sel].mean()), int(sel.sum())))
    return out


def calibration(m: str, rows: Sequence[dict[str, Any]]) -> dict[str, Any] | None:
    """How well method ``m``'s stated probability within the success radius at the end of each trial
    matches how often it is so (:func:`calibration_of`); None where it states none on any of ``rows``."""
    return calibration_of(reliability(m, rows))


def calibration_of(bins: Sequence[tuple[float, float, int]]) -> dict[str, Any] | None:
    """The calibration of :func:`binned`'s ``bins``.

    ``error``: the count-weighted mean of |mean stated − fraction right| (the expected calibration
    error); ``worst_gap``: the largest such gap in a bin of at least :data:`FULL_BIN` (None: no bin that
    full); ``trials``: the count; ``bins``: each bin's mean stated probability, fraction right, count and
    that fraction's Wilson 95% interval. None without any bin.
    """
    if not bins:
        return None
    n = sum(b[2] for b in bins)
    gaps = [abs(stated - actual) for stated, actual, _ in bins]
    full = [g for g, b in zip(gaps, bins) if b[2] >= FULL_BIN]
    return {
        "error": float(sum(g * b[2] for g, b in zip(gaps, bins)) / n),
        "worst_gap": max(full) if full else None,
        "trials": n,
        "bins": [
            {"stated": stated, "actual": actual, "trials": k, "ci95": list(wilson(int(round(actual * k)), k))}
            for stated, actual, k in bins
        ],
    }


def print_summary(summary: dict[str, Any]) -> None:
    print(
        f"study {summary['study']}: {summary['method']} rule, {summary['engine']} engine, "
        f"noise {Path(str(summary['noise'])).name}"
    )
    for lv in summary["levels"]:
        v = "" if lv["value"] is None else f"{lv['parameter']} = {lv['value']}: "
        rate = lv["success_rate"]
        print(
            f"  {v}{lv['success']}/{lv['trials']} within {summary['success_radius']} mm = "
            f"{rate:.1%} (95% CI {lv['ci95'][0]:.1%}–{lv['ci95'][1]:.1%}), median error "
            f"{lv['error_median_mm']:.3f} mm"
            if rate is not None
            else f"  {v}no trials"
        )
        if len(summary["levels"]) > 1:
            for m, d in lv.get("methods", {}).items():
                _print_method(m, d, indent="    ")
    for m, d in summary.get("method_details", {}).items():
        _print_method(m, d, indent="  ")


def _print_method(m: str, d: dict[str, Any], indent: str) -> None:
    if not d["trials"]:
        return
    rot = "" if d["mean_rotation_deg"] is None else f"mean rotation {d['mean_rotation_deg']:.1f}°, "
    print(
        f"{indent}{m:10s} {d['success']}/{d['trials']} = {d['success'] / d['trials']:.1%} "
        f"(95% CI {d['ci95'][0]:.1%}–{d['ci95'][1]:.1%}), {rot}median error {d['error_median_mm']:.3f} mm; "
        f"stopped confident {d['confident']}, of which wrong {d['confident_wrong']}"
        + (f"; model mismatch {d['mismatch']}" if d.get("mismatch") else "")
        + (f" ({d['mismatch_near']} near a defect)" if d.get("mismatch") and d.get("mismatch_near") is not None else "")
    )
    cal = d.get("calibration")
    if cal is not None:
        worst = "no bin of 30" if cal["worst_gap"] is None else f"worst full bin {cal['worst_gap']:.3f}"
        print(f"{indent}{'':10s} calibration error {cal['error']:.3f} over {cal['trials']} stated ({worst})")
