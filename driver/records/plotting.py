"""Figures of localization results (matplotlib, imported only when drawing)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import NDArray

from localizer import SUCCESS_RADIUS, Localization, Outline, Part

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..jaw import ReactiveRun
    from ..wheel import WheelRun
    from .trace import Trace

__all__ = ["plot_localization", "plot_run", "plot_reactive", "draw_part"]


def draw_part(ax: Axes, part: Part | Outline) -> None:
    """The part's boundary as it is: a spline densely, an outline from CAD piece by piece with its corners
    marked (convex ones, where the jaw pivots, and concave ones, which a straight jaw cannot touch),
    and its first point (arc 0)."""
    if isinstance(part, Outline):
        xy = part.sample(0.2)  # every piece's ends included: corners stay sharp
        ax.plot(xy[:, 0], xy[:, 1], color="0.55", lw=1.2, label=f"part {part.name} ({len(part.pieces)} pieces)")
        for convex, marker, label in ((True, "o", "convex corner"), (False, "x", "concave corner")):
            arcs = [c.arc for c in part.corners if (c.angle > 0) == convex]
            if arcs:
                pts = part.point_at_arc(np.array(arcs))
                ax.plot(pts[:, 0], pts[:, 1], marker, color="0.3", ms=5, ls="none", mfc="none", label=label)
    else:
        xy = part.sample(24)
        ax.plot(xy[:, 0], xy[:, 1], color="0.55", lw=1.2, label=f"part {part.name}")
    ax.plot(*part.point_at_arc(0.0), "k^", ms=6, label="arc 0 (first point)")


def _finish(fig: Figure, ax: Axes, path: str | os.PathLike[str]) -> None:
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


def _arc_points(part: Part | Outline, start: float, length: float, sign: float, n: int = 80) -> NDArray[np.float64]:
    s = start + sign * np.linspace(0.0, length, n)
    return part.point_at_arc(s)


def plot_localization(
    part: Part | Outline, result: Localization, path: str | os.PathLike[str], *, title: str | None = None
) -> None:
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
    draw_part(ax, part)
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
                f"p={cand.probability:.2f}",
                cast("tuple[float, float]", end),
                textcoords="offset points",
                xytext=(6, 6),
                fontsize=8,
                color=colour,
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


def plot_run(
    part: Part | Outline, trace: Trace, result: Localization, path: str | os.PathLike[str], *, half_span: float = 50.0
) -> None:
    """Draw a rolling run: the part, the jaw at each roll's start and end, true and estimated contacts.

    Parameters
    ----------
    part : localizer.Part
    trace : driver.records.trace.Trace
    result : localizer.Localization
    path : str or Path
        PNG file to write.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 7.5))
    draw_part(ax, part)
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


def plot_reactive(
    part: Part | Outline,
    run: ReactiveRun | WheelRun,
    path: str | os.PathLike[str],
    *,
    true_arcs: Sequence[float] | None = None,
) -> None:
    """Draw a reactive localization (:class:`driver.jaw.ReactiveRun`): the part as it is, the stretch
    the contact rolled over (from the readings' truth where known), the estimate with its stated
    probability, and the truth.

    Parameters
    ----------
    part : Part or Outline
    run : ReactiveRun
    path : str or Path
        PNG file to write.
    true_arcs : sequence of float, mm, optional
        The contact's true arc positions at the readings (a simulated rig's); default ``run.true_arcs``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 7))
    draw_part(ax, part)
    truth = np.asarray(run.true_arcs if true_arcs is None else true_arcs, dtype=float)
    truth = truth[np.isfinite(truth)]
    if truth.size:
        xy = part.point_at_arc(truth)
        ax.plot(xy[:, 0], xy[:, 1], ".", color="tab:blue", ms=2, label="the contact while rolling (truth)")
        ax.plot(*part.point_at_arc(truth[-1]), "o", color="tab:blue", ms=7, mfc="none", label="true contact now")
    b = run.belief
    mismatch = getattr(b, "mismatch", None)
    if mismatch is not None and all(np.isfinite(mismatch)):
        # where the part seems to differ from its model: the stretch, and a marker that reads at any zoom
        lo, hi = (float(v) for v in mismatch)
        span = float(part.arc_offset(hi, lo)) % part.perimeter
        stretch = part.point_at_arc(part.wrap_arc(lo + np.linspace(0.0, span, 64)))
        size = getattr(b, "mismatch_mm", float("nan"))
        how = f", {size:.2f} mm off" if np.isfinite(size) else ""
        ax.plot(stretch[:, 0], stretch[:, 1], "-", color="tab:orange", lw=6, alpha=0.7, solid_capstyle="round")
        ax.plot(
            *stretch[len(stretch) // 2],
            "X",
            color="tab:orange",
            ms=12,
            mec="black",
            label=f"model mismatch, arc {lo:.1f}–{hi:.1f} mm{how}",
        )
    est = part.point_at_arc(b.map_arc)
    if np.all(np.isfinite(est)):
        ax.plot(
            *est, "*", color="tab:red", ms=12, label=f"estimate: {b.mass:.1%} within {b.radius:g} mm ({run.stopped})"
        )
    ax.set_title(f"reactive localization on {part.name}: {np.degrees(run.rotation):.1f} deg rolled", fontsize=9)
    _finish(fig, ax, path)
