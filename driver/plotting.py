"""Figures of localization results (matplotlib, imported only when drawing)."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_localization"]


def _arc_points(part, start, length, sign, n=80):
    s = start + sign * np.linspace(0.0, length, n)
    return part.point_at_arc(s)


def plot_localization(part, result, path, *, title: str | None = None):
    """Draw the part, every feasible first-roll segment, each candidate's chain and the chosen contact.

    Parameters
    ----------
    part : localizer.Part
    result : localizer.Localization
    path : str or Path
        PNG file to write.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sign = 1.0 if result.direction == "ccw" else -1.0
    fig, ax = plt.subplots(figsize=(7, 7))
    outline = part.sample(24)
    ax.plot(outline[:, 0], outline[:, 1], color="0.55", lw=1.2, label=f"part {part.name}")
    ax.plot(*part.point(0.0), "k^", ms=6, label="arc 0 (first point)")
    for k, seg in enumerate(result.segments):
        xy = _arc_points(part, seg.start_arc, seg.length, sign)
        ax.plot(xy[:, 0], xy[:, 1], color="tab:orange", lw=4, alpha=0.45,
                label="feasible segments of roll 1" if k == 0 else None)
    cmap = plt.get_cmap("viridis")
    for k, cand in enumerate(result.candidates):
        if cand.probability <= 0:
            continue
        colour = cmap(0.15 + 0.7 * k / max(1, len(result.candidates) - 1))
        for j, L in enumerate(cand.lengths):
            xy = _arc_points(part, cand.path[j], L, sign)
            ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=1.6, ls="-" if j == 0 else "--")
        end = part.point_at_arc(cand.end_arc)
        if cand.probability >= 0.01:
            ax.annotate(f"p={cand.probability:.2f}", end, textcoords="offset points", xytext=(6, 6),
                        fontsize=8, color=colour)
    best = result.best
    if best is not None:
        start, end = part.point_at_arc(best.start_arc), part.point_at_arc(best.end_arc)
        ax.plot(*start, "o", color="tab:blue", ms=8, label=f"start {best.start_arc:.2f} mm")
        ax.plot(*end, "*", color="tab:red", ms=16,
                label=f"contact now {best.end_arc:.2f} mm (p={best.probability:.2f})")
    verdict = "ambiguous" if result.ambiguous else "localized"
    rolls = ", ".join(f"({L:.2f} mm, {np.degrees(w):.2f}°)" for L, w in result.rolls)
    ax.set_title(title or f"{part.name}: {verdict} from rolls {rolls}\nrule: {result.rule}", fontsize=9)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.legend(loc="best", fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
