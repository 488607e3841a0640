"""A study's figures, written beside its table: success per level, the fingers' reach, the error over the
bound, success against rotation per method, and the reliability diagram."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from localizer import load_part

from .study import Study
from .summary import (
    calibration,
    cell_number,
    error_over_bound,
    reliability,
    summarize,
    wilson,
)

__all__ = ["plot_study"]


def plot_study(study: Study, rows: Sequence[dict[str, Any]], out: Path) -> None:
    """success.png (rate against the swept value), errors.png, failures.png (where on the parts)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from localizer import Outline

    full = summarize(study, rows)
    summ = full["levels"]
    if study.methods and rows:
        _plot_methods(study, full, out)
        _plot_reliability(study, rows, out)
        _plot_bound(study, rows, out)
    if study.parameter == "jaw" and rows:
        _plot_fingers(study, rows, summ, out)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    x = [lv["value"] if isinstance(lv["value"], (int, float)) else k for k, lv in enumerate(summ)]
    if not all(isinstance(lv["value"], (int, float)) for lv in summ):
        ax.set_xticks(range(len(summ)), [str(lv["value"]) for lv in summ], fontsize=8)
    rate = np.array([lv["success_rate"] if lv["success_rate"] is not None else np.nan for lv in summ])
    lo = np.array([lv["ci95"][0] for lv in summ])
    hi = np.array([lv["ci95"][1] for lv in summ])
    ax.errorbar(x, rate, yerr=[rate - lo, hi - rate], fmt="o-", capsize=4, label=f"{study.name} ({study.method} rule)")
    ax.axhline(0.45, color="tab:red", lw=1, ls="--", label="the paper's rig: about 45%")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel(study.parameter or "level")
    ax.set_ylabel(f"success rate (error < {study.success_radius} mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "success.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    bins = np.logspace(-4, 3, 36).tolist()
    for lv in range(study.levels):
        e = np.array([float(r["error_mm"]) for r in rows if int(r["level"]) == lv])
        e = np.clip(e[np.isfinite(e)], 1e-4, 1e3)
        if e.size:
            label = f"{study.parameter}={study.level_label(lv)}" if study.parameter else "all trials"
            ax.hist(e, bins=bins, histtype="step", lw=1.5, label=label)
    ax.axvline(study.success_radius, color="tab:red", lw=1, ls="--", label=f"{study.success_radius} mm")
    ax.set_xscale("log")
    ax.set_xlabel("arc error of the final contact (mm)")
    ax.set_ylabel("trials")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "errors.png", dpi=110)
    plt.close(fig)

    names = sorted({r["part"] for r in rows})
    if names:
        fig, axes = plt.subplots(1, len(names), figsize=(4.3 * len(names), 4.4), squeeze=False)
        by_name = {Path(p).name: p for p in study.parts}
        for ax, name in zip(axes[0], names):
            part = load_part(by_name[name])
            # an outline from CAD every 0.5 mm with its corners, a spline 16 points per piece
            xy = part.sample(0.5) if isinstance(part, Outline) else part.sample(16)
            ax.plot(xy[:, 0], xy[:, 1], color="0.6", lw=1)
            sel = [r for r in rows if r["part"] == name and r["true_arc"] not in ("", "nan")]
            for ok, colour, label in ((1, "tab:green", "success"), (0, "tab:red", "failure")):
                arcs = np.array([float(r["true_arc"]) for r in sel if int(r["success"]) == ok])
                arcs = arcs[np.isfinite(arcs)]
                if arcs.size:
                    p = part.point_at_arc(arcs)
                    ax.plot(p[:, 0], p[:, 1], "o", ms=3, color=colour, alpha=0.6, label=f"{label} ({arcs.size})")
            ax.set_title(f"{name}: final true contacts", fontsize=9)
            ax.set_aspect("equal")
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7)
            else:  # no trial's fixed rolls ran on this part (e.g. every world's part made them bridge)
                ax.text(0.5, 0.5, "no fixed-roll trial", transform=ax.transAxes, ha="center", fontsize=8)
        fig.tight_layout()
        fig.savefig(out / "failures.png", dpi=110)
        plt.close(fig)


def _plot_fingers(study: Study, rows: Sequence[dict[str, Any]], levels: list[dict[str, Any]], out: Path) -> None:
    """fingers.png for a sweep over fingers: success against the rotation used, per finger (left), and
    where each can start and how far it rolled (right)."""
    import matplotlib.pyplot as plt

    from .scoring import MARK_DEG, parse_curve

    m = study.methods[0]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1.6, 1]})
    for lv in levels:
        sel = [r for r in rows if int(r["level"]) == lv["level"]]
        marks = np.arange(MARK_DEG, study.reactive.max_rotation_deg + 1e-9, MARK_DEG)
        hit = np.zeros(marks.size)
        for r in sel:
            pairs = dict((round(k, 6), e) for k, e in parse_curve(r[f"{m}_curve"]))
            hit += [pairs.get(round(k, 6), math.inf) < study.success_radius for k in marks]
        d = lv["methods"][m]
        ax.plot(
            marks,
            hit / max(len(sel), 1),
            "o-",
            ms=2.5,
            label=f"{lv['value']}: {d['success']}/{d['trials']}"
            + ("" if d["median_rotation_deg"] is None else f", median {d['median_rotation_deg']:.0f}°"),
        )
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("rotation used (degrees; a wheel: the hand's turning)")
    ax.set_ylabel(f"success rate (error < {study.success_radius} mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    names = [str(lv["value"]) for lv in levels]
    reach = [lv.get("reachable", math.nan) for lv in levels]
    bx.bar(names, reach, color="tab:blue", alpha=0.7, label="boundary a start can be drawn from")
    for k, lv in enumerate(levels):
        bx.text(k, reach[k] + 0.02, f"{lv.get('mean_redraws', 0):.1f} redraws", ha="center", fontsize=7)
    bx.set_ylim(0, 1.15)
    bx.set_ylabel("fraction of the boundary")
    bx.legend(fontsize=7, loc="lower right")
    bx.grid(alpha=0.3, axis="y")
    bx.tick_params(axis="x", labelsize=8)
    fig.suptitle(f"{study.name}: fingers on the same trial seeds, noise {Path(str(study.noise)).stem}", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "fingers.png", dpi=110)
    plt.close(fig)


def _plot_bound(study: Study, rows: Sequence[dict[str, Any]], out: Path) -> None:
    """bound.png: each method's final error against the Cramér–Rao bound of its readings, trial by trial
    (successes filled, failures hollow), with the bound itself and 1.3 times it."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 5.0))
    lo, hi = math.inf, 0.0
    for k, m in enumerate(study.methods):
        bound = np.array([cell_number(r.get(f"{m}_bound_mm", "")) for r in rows])
        err = np.array([cell_number(r[f"{m}_error_mm"]) for r in rows])
        ok = np.array([int(r[f"{m}_success"]) for r in rows], dtype=bool)
        keep = np.isfinite(bound) & (bound > 0) & np.isfinite(err)
        if not keep.any():
            continue
        err = np.maximum(err, 1e-5)
        ratio = error_over_bound(m, rows)
        rms = f", rms error/bound {np.sqrt(np.mean(ratio**2)):.2f} over {ratio.size} successes" if ratio.size else ""
        colour = f"C{k}"
        ax.loglog(bound[keep & ok], err[keep & ok], "o", ms=3, color=colour, alpha=0.6, label=f"{m}{rms}")
        ax.loglog(bound[keep & ~ok], err[keep & ~ok], "o", ms=3, mfc="none", color=colour, alpha=0.6)
        lo, hi = min(lo, bound[keep].min()), max(hi, bound[keep].max())
    if hi > 0:
        line = np.array([lo / 2, hi * 2])
        ax.loglog(line, line, "k-", lw=1, label="error = bound")
        ax.loglog(line, 1.3 * line, "k--", lw=1, label="1.3 × bound")
        ax.axhline(
            study.success_radius, color="tab:red", lw=1, ls=":", label=f"success radius {study.success_radius} mm"
        )
    ax.set_xlabel("Cramér–Rao bound of the final place from the readings taken (mm)")
    ax.set_ylabel("final error (mm)")
    ax.set_title(f"{study.name}: error against its bound (hollow: failures)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    if hi > 0:
        ax.legend(fontsize=7)
    else:  # no method stated a bound for any trial (every trial broke, or none had readings to bound)
        ax.text(0.5, 0.5, "no trial with a bound", transform=ax.transAxes, ha="center", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "bound.png", dpi=110)
    plt.close(fig)


def _plot_methods(study: Study, summary: dict[str, Any], out: Path) -> None:
    """methods.png: each method's success rate against the rotation rolled (left) and how many were sure,
    and sure and wrong, by then (right; studies with each method's stated probability along the rolling),
    the fixed rolls' total (the paper's two-roll method) marked on both."""
    import matplotlib.pyplot as plt

    sure = summary.get("sure_by_rotation_deg", {})
    stating = [m for m in study.methods if sure.get(m)]
    fig, axes = plt.subplots(1, 2 if stating else 1, figsize=(13 if stating else 7, 4.4), squeeze=False)
    ax = axes[0][0]
    fixed = sum(abs(a) for a in study.rolls_deg)
    colors = {m: f"C{k}" for k, m in enumerate(study.methods)}
    for m in study.methods:
        curve = summary["success_by_rotation_deg"][m]
        x = [float(k) for k in curve]
        d = summary["method_details"][m]
        rot = "" if d["mean_rotation_deg"] is None else f", mean rotation {d['mean_rotation_deg']:.0f}°"
        rate = summary["methods"][m]
        label = f"{m}: {rate:.1%} at the end{rot}" if rate is not None else m
        ax.plot(x, list(curve.values()), "o-", ms=3, color=colors[m], label=label)
    ax.axhline(0.45, color="tab:red", lw=1, ls="--", label="the paper's rig: about 45%")
    ax.set_ylabel(f"success rate (error < {study.success_radius} mm)")
    ax.set_title(f"{study.name}: {len(study.methods)} methods on the same trials", fontsize=10)
    if stating:
        bx = axes[0][1]
        for m in stating:
            by = sure[m]
            x = [float(k) for k in by]
            end = list(by.values())[-1]
            label = f"{m}: {end['sure']:.0%} sure, {end['sure_wrong']:.0%} sure and wrong at the end"
            bx.plot(x, [v["sure"] for v in by.values()], "o-", ms=3, color=colors[m], label=label)
            bx.plot(x, [v["sure_wrong"] for v in by.values()], "x--", ms=3, lw=1, color=colors[m])
        bx.set_ylabel(f"fraction sure (stated ≥ {study.reactive.confidence:g}); dashed: sure and wrong")
        bx.set_title("sure against rotation", fontsize=10)
    for a in axes[0]:
        a.axvline(fixed, color="0.5", lw=1, ls=":", label=f"the fixed rolls: {fixed:g}°")
        a.set_ylim(0, 1.02)
        a.set_xlabel("rotation rolled (degrees)")
        a.grid(alpha=0.3)
        a.legend(fontsize=7, loc="lower right" if a is ax else "upper left")
    fig.tight_layout()
    fig.savefig(out / "methods.png", dpi=110)
    plt.close(fig)


def _plot_reliability(study: Study, rows: Sequence[dict[str, Any]], out: Path) -> None:
    """reliability.png: stated confidence at the stop against the fraction within the radius, per level.

    For each method that states one: the whole range, and the range from 0.9 up, where a promise
    of 95% is about the few that miss. Bars: each bin's 95% Wilson interval."""
    import matplotlib.pyplot as plt

    stating = [m for m in study.methods if any(np.isfinite(cell_number(r.get(f"{m}_mass", ""))) for r in rows)]
    if not stating:
        return
    fig, axes = plt.subplots(len(stating), 2, figsize=(10, 4.2 * len(stating)), squeeze=False)
    for row_axes, m in zip(axes, stating):
        if not any(r.get(f"{m}_stopped") == "confident" for r in rows):
            row_axes[1].set_visible(False)  # it never stops sure: nothing to zoom into
        for ax, lo in zip(row_axes, (0.0, 0.9)):
            if not ax.get_visible():
                continue
            ax.plot([lo, 1], [lo, 1], color="0.6", lw=1, ls="--", label="a promise kept")
            for level in range(study.levels):
                sel = [r for r in rows if int(r["level"]) == level]
                pts = [p for p in reliability(m, sel) if p[0] >= lo]
                if not pts:
                    continue
                x, y, n = (np.array(v) for v in zip(*pts))
                ci = np.array([wilson(int(round(a * b)), int(b)) for a, b in zip(y, n)])
                label = str(study.level_label(level)) if study.parameter else "all trials"
                err = [np.clip(y - ci[:, 0], 0, None), np.clip(ci[:, 1] - y, 0, None)]
                ax.errorbar(x, y, yerr=err, fmt="o-", ms=3, capsize=2, lw=1, label=label)
                for xi, yi, ni in zip(x, y, n):
                    ax.annotate(str(ni), (xi, yi), fontsize=6, xytext=(3, -9), textcoords="offset points")
            ax.set_xlim(lo, 1.0 + (1 - lo) * 0.01)
            ax.set_ylim(lo if lo else 0.0, 1.0 + (1 - lo) * 0.01)
            ax.set_xlabel("stated probability within the radius at the stop")
            ax.set_ylabel(f"fraction actually within {study.success_radius} mm")
            cal = calibration(m, rows)
            told = "" if cal is None else f"; calibration error {cal['error']:.3f} over {cal['trials']}"
            ax.set_title(f"{m}" + (" (from 0.9 up)" if lo else told), fontsize=10)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper left" if not lo else "lower right")
    fig.suptitle(f"{study.name}: reliability (numbers: trials per bin; bars: 95% intervals)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "reliability.png", dpi=110)
    plt.close(fig)
