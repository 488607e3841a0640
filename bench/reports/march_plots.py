"""The figures of the marching algorithm's studies (:mod:`bench.reports.march_study`): Proposition 1's
errors, Theorem 2's steps, completeness and cost against the step, the exact solver against the march."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from localizer import part_from_points

if TYPE_CHECKING:
    import numpy.typing as npt

    FloatArray: TypeAlias = npt.NDArray[np.float64]

__all__ = ["plot_studies"]


def plot_studies(
    out: Path,
    prop1: list[dict[str, Any]],
    thm2: list[dict[str, Any]],
    cost: list[dict[str, Any]],
    compl: list[dict[str, Any]],
    versus: dict[str, Any],
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # Proposition 1: measured ratio against the curvature ratio, and iterations
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.5))
    ok = [r for r in prop1 if r["measured"] is not None and r["kind"] == "simple"]
    pred = np.array([r["predicted"] for r in ok])
    meas = np.array([r["measured"] for r in ok])
    a1.plot([0, 1], [0, 1], color="0.6", lw=1, label="measured = predicted")
    a1.plot(pred, meas, "o", ms=4, alpha=0.7, label=f"{len(ok)} segments on random convex parts")
    a1.set_xlabel("predicted ratio min(κ(s*)/κ(t*), κ(t*)/κ(s*))")
    a1.set_ylabel("measured ratio e(i+1)/e(i) of the iterates")
    a1.set_title("Proposition 1: linear convergence")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    allp = np.array([r["predicted"] for r in prop1])
    its = np.array([r["iterations"] for r in prop1])
    stalled = np.array([r["kind"] == "stalled" for r in prop1])
    a2.semilogy(allp[~stalled], np.maximum(its[~stalled], 1), "o", ms=4, alpha=0.7, label="converged")
    a2.semilogy(allp[stalled], its[stalled], "x", color="tab:red", ms=7, label="stalled (iteration cap)")
    r: FloatArray | dict[str, Any]  # the name serves twice: these ratios, then a completeness row below
    r = np.linspace(0.05, 0.9995, 400)
    a2.semilogy(r, np.log(1e-10 / 10.0) / np.log(r), color="0.5", lw=1, label="log(1e-10 / 10 mm) / log r")
    a2.set_xlabel("predicted ratio")
    a2.set_ylabel("iterations to |Φ - Ω| <= 1e-10")
    a2.set_title("where κ(s*) ≈ κ(t*) the march stalls")
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out / "proposition1.png", dpi=110)
    plt.close(fig)

    # Theorem 2 and cost against h
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.5))
    for convex, mark in ((True, "o"), (False, "s")):
        v = [r["steps_per_period"] for r in thm2 if r["convex"] == convex]
        a1.plot(np.arange(len(v)), v, mark, label="convex" if convex else "non-convex")
    a1.axhline(6, color="tab:red", lw=1, label="Theorem 2 bound: 6τ/h")
    a1.set_ylabel("steps taken / (τ/h)")
    a1.set_xlabel("instance")
    a1.set_title("Theorem 2: steps against the bound")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    hs = np.array([c["h"] for c in cost])
    steps = np.array([c["steps"] for c in cost])
    a2.loglog(1 / hs, steps, "o-", color="tab:blue", label="numerical steps per query (march)")
    a2.loglog(1 / hs, steps[-1] * hs[-1] / hs, color="0.6", lw=1, ls="--", label="∝ 1/h")
    a2.set_ylabel("steps per query")
    a3 = a2.twinx()
    a3.loglog(1 / hs, [c["build_s"] for c in cost], "s-", color="tab:green", label="h-grid integrals (s), per part")
    a3.loglog(1 / hs, [c["march_s"] for c in cost], "^-", color="tab:orange", label="march wall time (s), per query")
    a3.set_ylabel("time (s)")
    lines = a2.get_legend_handles_labels()
    more = a3.get_legend_handles_labels()
    a2.legend(lines[0] + more[0], lines[1] + more[1], fontsize=7, loc="upper left")
    a2.set_xlabel("1/h")
    a2.set_title("cost against the step (trefoil, 90 knots)")
    a2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out / "theorem2.png", dpi=110)
    plt.close(fig)

    # completeness failures: the first ones drawn
    fails = [r for r in compl if r["missed"]][:4]
    if fails:
        fig, axes = plt.subplots(1, len(fails), figsize=(4.2 * len(fails), 4.4), squeeze=False)
        for ax, r in zip(axes[0], fails):
            part = part_from_points(r["points"])
            xy = part.sample(16)
            ax.plot(xy[:, 0], xy[:, 1], color="0.6", lw=1)
            for k, e in enumerate(r["exact"]):
                ax.plot(*part.point_at_arc(e), "o", color="tab:blue", ms=6, label="exact" if k == 0 else None)
            for k, m in enumerate(r["march"]):
                ax.plot(*part.point_at_arc(m), "x", color="tab:orange", ms=7, label="march" if k == 0 else None)
            for k, miss in enumerate(r["missed"]):
                ax.plot(
                    *part.point_at_arc(miss["start_arc"]),
                    "o",
                    mfc="none",
                    mec="tab:red",
                    ms=14,
                    label="missed" if k == 0 else None,
                )
            miss = r["missed"][0]["start_arc"]
            zoom = ax.inset_axes([0.58, 0.58, 0.4, 0.4])
            arcs = miss + np.linspace(-3, 3, 200)
            zxy = part.point_at_arc(arcs)
            zoom.plot(zxy[:, 0], zxy[:, 1], color="0.6", lw=1)
            for e in r["exact"]:
                if abs(part.arc_offset(e, miss)) < 3:
                    zoom.plot(*part.point_at_arc(e), "o", color="tab:blue", ms=5)
            for m in r["march"]:
                if abs(part.arc_offset(m, miss)) < 3:
                    zoom.plot(*part.point_at_arc(m), "x", color="tab:orange", ms=6)
            zoom.plot(*part.point_at_arc(miss), "o", mfc="none", mec="tab:red", ms=11)
            zoom.set_xticks([])
            zoom.set_yticks([])
            zoom.text(0.03, 0.04, "±3 mm", transform=zoom.transAxes, fontsize=7)
            ax.set_title(
                f"{'convex' if r['convex'] else 'non-convex'}, L={r['length']:.1f} mm, Ω={np.degrees(r['turn']):.1f}°",
                fontsize=8,
            )
            ax.set_aspect("equal")
            ax.legend(fontsize=7, loc="lower left")
        fig.tight_layout()
        fig.savefig(out / "completeness_failures.png", dpi=110)
        plt.close(fig)

    # exact against march, per query
    rows = versus["rows"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    idx = np.arange(len(rows))
    a1.semilogy(idx, [r["exact_s"] for r in rows], "o", label="exact solver")
    a1.semilogy(
        idx, [r["march_paper_cost_s"] for r in rows], "s", label=f"march, h={versus['h']:g}: steps × cost of a step"
    )
    a1.semilogy(idx, [r["march_s"] for r in rows], "^", label="march on the precomputed h-grid (grid not counted)")
    a1.axhline(versus["integration_s"], color="0.5", lw=1, ls="--", label="one perimeter integration")
    a1.set_xlabel("query")
    a1.set_ylabel("time per query (s)")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3, which="both")
    a2.semilogy(idx, np.maximum([r["exact_error"] for r in rows], 1e-16), "o", label="exact solver")
    a2.semilogy(idx, np.maximum([r["march_error"] for r in rows], 1e-16), "s", label="march, paper tolerances")
    a2.set_xlabel("query")
    a2.set_ylabel("distance of the nearest start to the truth (mm)")
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3, which="both")
    fig.suptitle("exact solver against the march on the trefoil, same run", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "exact_vs_march.png", dpi=110)
    plt.close(fig)
