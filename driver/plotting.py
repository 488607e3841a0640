"""Figures of localization results (matplotlib, imported only when drawing)."""

from __future__ import annotations

import numpy as np

from localizer import SUCCESS_RADIUS

__all__ = ["plot_localization", "plot_run"]


def _finish(fig, ax, path) -> None:
    """Equal axes in mm, legend, grid; write the PNG and close the figure."""
    import matplotlib.pyplot as plt

    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.legend(loc="best", fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


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
        ax.plot(
            xy[:, 0],
            xy[:, 1],
            color="tab:orange",
            lw=4,
            alpha=0.45,
            label="feasible segments of roll 1" if k == 0 else None,
        )
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
            ax.annotate(
                f"p={cand.probability:.2f}", end, textcoords="offset points", xytext=(6, 6), fontsize=8, color=colour
            )
    best = result.best
    if best is not None:
        start, end = part.point_at_arc(best.start_arc), part.point_at_arc(best.end_arc)
        ax.plot(*start, "o", color="tab:blue", ms=8, label=f"start {best.start_arc:.2f} mm")
        ax.plot(
            *end, "*", color="tab:red", ms=16, label=f"contact now {best.end_arc:.2f} mm (p={best.probability:.2f})"
        )
    verdict = "ambiguous" if result.ambiguous else "localized"
    rolls = ", ".join(f"({L:.2f} mm, {np.degrees(w):.2f}°)" for L, w in result.rolls)
    ax.set_title(title or f"{part.name}: {verdict} from rolls {rolls}\nrule: {result.rule}", fontsize=9)
    _finish(fig, ax, path)


def plot_run(part, trace, result, path, *, half_span: float = 50.0):
    """Draw a rolling run: the part, the jaw at each roll's start and end, true and estimated contacts.

    Parameters
    ----------
    part : localizer.Part
    trace : driver.trace.Trace
    result : localizer.Localization
    path : str or Path
        PNG file to write.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 7.5))
    outline = part.sample(24)
    ax.plot(outline[:, 0], outline[:, 1], color="0.55", lw=1.2, label=f"part {part.name}")
    cols = trace.columns
    jaw = trace.jaw_positions()
    has_truth = np.isfinite(cols["true_arc"]).all()
    boundaries = [i for i in range(len(jaw)) if i == 0 or cols["roll"][i] != cols["roll"][i - 1]] + [len(jaw) - 1]
    for k, i in enumerate(boundaries):
        phi = cols["phi"][i]
        e = np.array([np.cos(phi), np.sin(phi)])
        at = (
            cols["true_arc"][i]
            if has_truth
            else (result.best.path[min(k, len(result.best.path) - 1)] if result.best else np.nan)
        )
        if not np.isfinite(at):
            continue
        c = part.point_at_arc(at)
        u = jaw[i]
        ends = np.array([c - (u + half_span) * e, c + (half_span - u) * e])
        ax.plot(
            ends[:, 0],
            ends[:, 1],
            color="tab:gray",
            lw=3,
            alpha=0.5,
            label="jaw at the start and end of each roll" if k == 0 else None,
        )
    if has_truth:
        arcs = cols["true_arc"]
        xy = part.point_at_arc(arcs)
        ax.plot(xy[:, 0], xy[:, 1], ".", color="tab:green", ms=3, label="true contacts")
        ax.plot(
            *part.point_at_arc(arcs[-1]), "*", color="tab:green", ms=16, label=f"true contact now {arcs[-1]:.2f} mm"
        )
    for j, cand in enumerate(result.candidates[:5]):
        if cand.probability < 0.01:
            continue
        ax.plot(
            *part.point_at_arc(cand.end_arc),
            "x",
            color="tab:red",
            ms=10 if j == 0 else 7,
            mew=2,
            label=(f"estimate {cand.end_arc:.2f} mm (p={cand.probability:.2f})" if j == 0 else None),
        )
    title = f"{part.name}: {trace.metadata.get('engine', '')} rig, noise {trace.metadata.get('noise_name', '')}"
    if has_truth and result.best is not None:
        err = abs(float(part.arc_offset(result.best.end_arc, cols["true_arc"][-1])))
        title += f"\nerror {err:.3f} mm ({'success' if err < SUCCESS_RADIUS else 'failure'} at {SUCCESS_RADIUS} mm)"
    ax.set_title(title, fontsize=9)
    _finish(fig, ax, path)
