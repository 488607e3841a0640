"""Studies of the paper's marching algorithm: Proposition 1, Theorem 2, completeness, cost.

Run ``python -m bench.reports.march_study [--quick] [--out docs/generated/march]``: it prints the
figures, writes PNG plots and ``summary.json`` into ``--out``, and
``docs/march.md`` quotes them. ``--quick`` uses fewer instances and a coarser
step for the completeness study (for a smoke run); the report is made without it.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from bench.benchmarks.baselines import random_outline, trapezoid_perimeter, trefoil_part
from localizer import LENGTH_TOL, TURN_TOL, MarchOptions, feasible_segments, march, march_grid, part_from_points

from .march_plots import plot_studies

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt

    from localizer import Part, Segment

    FloatArray: TypeAlias = npt.NDArray[np.float64]

TIGHT: dict[str, float] = {"length_tol": 1e-10, "turn_tol": 1e-10}


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def _random_part(rng: np.random.Generator, convex: bool) -> Part:
    while True:
        part = part_from_points(random_outline(rng, int(rng.integers(24, 60)), 2.5 if convex else 9.0))
        kmin = part.curvature(np.linspace(0, part.n_knots, 20 * part.n_knots)).min()
        if (kmin > 0) == convex:
            return part


def _query(part: Part, rng: np.random.Generator) -> tuple[float, float, float]:
    P = part.perimeter
    s0, L = rng.uniform(0, P), rng.uniform(0.05, 0.4) * P
    w = float(part.tangent_angle_at_arc(s0 + L) - part.tangent_angle_at_arc(s0))
    return s0, L, w


def _nearest(part: Part, segs: Sequence[Segment], arc: float) -> Segment:
    return min(segs, key=lambda g: abs(part.arc_offset(g.start_arc, arc)))


def measured_ratio(part: Part, seg: Segment, exact_start: float) -> float | None:
    """Median ratio of consecutive iterate errors in the linear regime, or None."""
    err = np.abs(part.arc_offset(np.array(seg.iterates), exact_start))
    tail = err[(err > 1e-6) & (err < 0.1)]
    if tail.size < 4:
        return None
    return float(np.median(tail[1:] / tail[:-1]))


# ------------------------------------------------------------------ studies
def proposition_1(n_parts: int, seed: int, h: float = 1e-4, max_iterations: int = 20_000) -> list[dict[str, Any]]:
    """Measured convergence ratio against κ(s*)/κ(t*) on random convex parts."""
    rng = np.random.default_rng(seed)
    rows: list[dict[str, Any]] = []
    for k in range(n_parts):
        part = _random_part(rng, convex=True)
        for _ in range(2):
            _, L, w = _query(part, rng)
            exact = feasible_segments(part, L, w)
            res = march(
                part, L, w, MarchOptions(step=h, max_iterations=max_iterations, length_tol=1e-10, turn_tol=1e-10)
            )
            for seg in res.segments:
                e = _nearest(part, exact, seg.start_arc)
                ks, kt = float(part.curvature(e.start_param)), float(part.curvature(e.end_param))
                rows.append(
                    {
                        "part": k,
                        "length": L,
                        "turn": w,
                        "start_arc": e.start_arc,
                        "predicted": min(ks / kt, kt / ks),
                        "measured": measured_ratio(part, seg, e.start_arc),
                        "iterations": seg.iterations,
                        "kind": seg.kind,
                        "error": abs(float(part.arc_offset(seg.start_arc, e.start_arc))),
                    }
                )
        _log(f"  proposition 1: part {k + 1}/{n_parts}, {len(rows)} segments")
    rows += near_equal_curvature(max(2, n_parts // 5), seed + 1, h, max_iterations)
    return rows


def near_equal_curvature(
    n_parts: int,
    seed: int,
    h: float,
    max_iterations: int,
    deltas: Sequence[float] = (3e-2, 1e-2, 3e-3, 1e-3, 3e-4),
) -> list[dict[str, Any]]:
    """Instances made to have κ(t*)/κ(s*) = 1 + δ: the ratio of Proposition 1 close to 1."""
    from scipy.optimize import brentq

    rng = np.random.default_rng(seed)
    rows: list[dict[str, Any]] = []
    for k in range(n_parts):
        part = _random_part(rng, convex=True)
        P = part.perimeter
        s0 = rng.uniform(0, P)
        k0 = float(part.curvature_at_arc(s0))
        Ls = np.linspace(0.05 * P, 0.6 * P, 400)
        q = part.curvature_at_arc(s0 + Ls) / k0
        for d in deltas:
            for sgn in (1.0, -1.0):
                f = q - (1 + sgn * d)
                hit = np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:]))
                if hit.size == 0:
                    continue
                i = int(hit[0])
                L = brentq(
                    lambda x, part=part, s0=s0, k0=k0, sgn=sgn, d=d: (
                        float(part.curvature_at_arc(s0 + x)) / k0 - (1 + sgn * d)
                    ),
                    Ls[i],
                    Ls[i + 1],
                )
                w = float(part.tangent_angle_at_arc(s0 + L) - part.tangent_angle_at_arc(s0))
                res = march(
                    part, L, w, MarchOptions(step=h, max_iterations=max_iterations, length_tol=1e-10, turn_tol=1e-10)
                )
                seg = _nearest(part, res.segments, s0) if res.segments else None
                if seg is None or abs(part.arc_offset(seg.start_arc, s0)) > 1.0:
                    continue
                rows.append(
                    {
                        "part": f"near-equal {k}",
                        "length": L,
                        "turn": w,
                        "start_arc": s0,
                        "predicted": min(1 + sgn * d, 1 / (1 + sgn * d)),
                        "measured": measured_ratio(part, seg, s0),
                        "iterations": seg.iterations,
                        "kind": seg.kind,
                        "error": abs(float(part.arc_offset(seg.start_arc, s0))),
                    }
                )
                break
        _log(f"  proposition 1, κ(s*) ≈ κ(t*): part {k + 1}/{n_parts}")
    return rows


def theorem_2(n_parts: int, seed: int, h: float = 1e-4) -> list[dict[str, Any]]:
    """Steps taken against the bound 6τ/h, convex and non-convex."""
    rng = np.random.default_rng(seed)
    rows: list[dict[str, Any]] = []
    for _k in range(n_parts):
        for convex in (True, False):
            part = _random_part(rng, convex)
            _, L, w = _query(part, rng)
            res = march(part, L, w, MarchOptions(step=h))
            rows.append(
                {
                    "convex": convex,
                    "steps": res.steps,
                    "grid_cells": res.grid_cells,
                    "steps_per_period": res.steps / res.grid_cells,
                    "segments": len(res.segments),
                }
            )
    return rows


def cost_against_step(
    steps: Sequence[float] = (1e-3, 3e-4, 1e-4, 3e-5, 1e-5), n_queries: int = 5, seed: int = 3
) -> list[dict[str, Any]]:
    """Grid build, march and step count against h on the 90-knot trefoil."""
    part = trefoil_part()
    rng = np.random.default_rng(seed)
    qs = [_query(part, rng) for _ in range(n_queries)]
    rows: list[dict[str, Any]] = []
    for h in steps:
        part.forget_tables()
        t0 = time.perf_counter()
        march_grid(part, h)
        build = time.perf_counter() - t0
        t0 = time.perf_counter()
        nsteps = [march(part, L, w, MarchOptions(step=h)).steps for _, L, w in qs]
        per_query = (time.perf_counter() - t0) / n_queries
        rows.append(
            {
                "h": h,
                "build_s": build,
                "march_s": per_query,
                "steps": float(np.mean(nsteps)),
                "grid_cells": int(round(part.n_knots / h)),
            }
        )
        _log(f"  cost: h={h:g} build {build:.3f} s, march {per_query:.3f} s/query")
    return rows


def completeness(n_parts: int, seed: int, h: float = 1e-5, queries_per_part: int = 3) -> list[dict[str, Any]]:
    """Does the march at the paper's step and tolerances find every exact segment?"""
    rng = np.random.default_rng(seed)
    rows: list[dict[str, Any]] = []
    for convex in (True, False):
        for k in range(n_parts):
            part = _random_part(rng, convex)
            for _ in range(queries_per_part):
                s0, L, w = _query(part, rng)
                exact = feasible_segments(part, L, w)
                marched = march(part, L, w, MarchOptions(step=h)).segments
                missed: list[dict[str, float]] = []
                for e in exact:
                    slope = abs(float(part.curvature(e.end_param) - part.curvature(e.start_param)))
                    allowed = 2 * TURN_TOL / max(slope, 1e-12) + 2 * LENGTH_TOL + 0.01
                    d = min((abs(float(part.arc_offset(m.start_arc, e.start_arc))) for m in marched), default=np.inf)
                    if d > allowed:
                        missed.append({"start_arc": e.start_arc, "distance": d, "allowed": allowed, "slope": slope})
                rows.append(
                    {
                        "convex": convex,
                        "part": k,
                        "points": part.points.tolist(),
                        "length": L,
                        "turn": w,
                        "exact": [e.start_arc for e in exact],
                        "march": [m.start_arc for m in marched],
                        "missed": missed,
                    }
                )
            part.forget_tables()  # free the h-grid (72 MB per million cells)
            _log(f"  completeness: {'convex' if convex else 'non-convex'} part {k + 1}/{n_parts}")
    return rows


def exact_vs_march(h: float = 1e-5, n_queries: int = 10, seed: int = 5) -> dict[str, Any]:
    """Time per query and error of both methods on the trefoil, in one run.

    The error is the distance from the true start (the queries are made from
    known starts) to the nearest returned start, mm.
    """
    part = trefoil_part()
    rng = np.random.default_rng(seed)
    qs = [_query(part, rng) for _ in range(n_queries)]
    feasible_segments(part, 10.0, 0.1)  # the exact solver's tables, once per part
    t0 = time.perf_counter()
    grid = march_grid(part, h)  # the march's h-grid, once per part and step
    _ = grid.inflections, grid.negated_turn  # and what it derives from it
    build = time.perf_counter() - t0
    rows: list[dict[str, Any]] = []
    for s0, L, w in qs:
        t0 = time.perf_counter()
        ex = feasible_segments(part, L, w)
        t_exact = time.perf_counter() - t0
        t0 = time.perf_counter()
        res = march(part, L, w, MarchOptions(step=h))
        t_march = time.perf_counter() - t0
        ma = res.segments
        rows.append(
            {
                "length": L,
                "turn": w,
                "exact_s": t_exact,
                "march_s": t_march,
                "steps": res.steps,
                "exact_error": abs(float(part.arc_offset(_nearest(part, ex, s0).start_arc, s0))),
                "march_error": abs(float(part.arc_offset(_nearest(part, ma, s0).start_arc, s0))),
                "segments_exact": len(ex),
                "segments_march": len(ma),
            }
        )
    t0 = time.perf_counter()
    trapezoid_perimeter(part, h)
    integration = time.perf_counter() - t0
    per_step = integration / grid.cells
    for r in rows:  # what the march costs integrating as it goes, at the measured cost of a step
        r["march_paper_cost_s"] = r["steps"] * per_step
    return {"h": h, "march_grid_build_s": build, "integration_s": integration, "rows": rows}


# -------------------------------------------------------------------- plots


def summarize(
    prop1: list[dict[str, Any]],
    thm2: list[dict[str, Any]],
    cost: list[dict[str, Any]],
    compl: list[dict[str, Any]],
    versus: dict[str, Any],
) -> dict[str, Any]:
    ok = [r for r in prop1 if r["measured"] is not None and r["kind"] == "simple"]
    dev = np.array([abs(r["measured"] - r["predicted"]) for r in ok])
    rows = versus["rows"]
    by: dict[str, dict[str, Any]] = {}
    for convex in (True, False):
        sel = [r for r in compl if r["convex"] == convex]
        by["convex" if convex else "non_convex"] = {
            "instances": len(sel),
            "complete": sum(not r["missed"] for r in sel),
            "fraction": sum(not r["missed"] for r in sel) / max(len(sel), 1),
            "exact_segments": sum(len(r["exact"]) for r in sel),
            "missed_segments": sum(len(r["missed"]) for r in sel),
        }
    inv_h = np.log([1 / c["h"] for c in cost])
    slopes = {
        key: float(np.polyfit(inv_h, np.log([c[key] for c in cost]), 1)[0]) for key in ("steps", "build_s", "march_s")
    }
    return {
        "proposition_1": {
            "segments": len(prop1),
            "with_measured_ratio": len(ok),
            "abs_dev_median": float(np.median(dev)) if dev.size else None,
            "abs_dev_max": float(dev.max()) if dev.size else None,
            "stalled": sum(r["kind"] == "stalled" for r in prop1),
            "stalled_predicted_min": min((r["predicted"] for r in prop1 if r["kind"] == "stalled"), default=None),
        },
        "theorem_2": {
            "instances": len(thm2),
            "max_steps_per_period": max(r["steps_per_period"] for r in thm2),
            "median_steps_per_period": float(np.median([r["steps_per_period"] for r in thm2])),
            "bound": 6,
        },
        "cost_against_h": {"rows": cost, "loglog_slope_vs_1_over_h": slopes},
        "completeness": by,
        "exact_vs_march": {
            "h": versus["h"],
            "queries": len(rows),
            "exact_s_median": float(np.median([r["exact_s"] for r in rows])),
            "march_s_median": float(np.median([r["march_s"] for r in rows])),
            "march_paper_cost_s_median": float(np.median([r["march_paper_cost_s"] for r in rows])),
            "march_steps_median": float(np.median([r["steps"] for r in rows])),
            "march_grid_build_s": versus["march_grid_build_s"],
            "integration_s": versus["integration_s"],
            "exact_error_max": float(max(r["exact_error"] for r in rows)),
            "march_error_median": float(np.median([r["march_error"] for r in rows])),
            "march_error_max": float(max(r["march_error"] for r in rows)),
        },
    }


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/generated/march", help="folder for the PNG plots and summary.json")
    ap.add_argument("--quick", action="store_true", help="few instances and h=1e-4 for completeness")
    ap.add_argument("--seed", type=int, default=2005)
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    q = args.quick
    _log("Proposition 1 ...")
    prop1 = proposition_1(4 if q else 30, args.seed)
    _log("Theorem 2 ...")
    thm2 = theorem_2(3 if q else 15, args.seed + 1)
    _log("cost against h ...")
    cost = cost_against_step((1e-3, 3e-4, 1e-4) if q else (1e-3, 3e-4, 1e-4, 3e-5, 1e-5))
    _log("completeness ...")
    compl = completeness(2 if q else 12, args.seed + 2, h=1e-4 if q else 1e-5)
    _log("exact against march ...")
    versus = exact_vs_march(h=1e-4 if q else 1e-5, n_queries=4 if q else 10)
    summary = summarize(prop1, thm2, cost, compl, versus)
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    (out / "completeness.json").write_text(
        json.dumps([{k: v for k, v in r.items() if k != "points"} for r in compl], indent=1) + "\n"
    )
    plot_studies(out, prop1, thm2, cost, compl, versus)
    print(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
