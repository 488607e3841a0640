"""A reactive rolling as an animation: the finger on the part at every reading, the belief along the boundary.

Each frame is one reading of a :class:`~driver.records.BeliefHistory` (at most :data:`MAX_FRAMES`, evenly
chosen, the last always among them): the part, the straight jaw laid on it (tangent at the contact, the
contact at its measured place on the jaw) or the wheel touching it (the true contact where known, else
the most probable one), the
belief of the last check as a band of colour along the boundary, the leading places with their shares,
and the stated probability growing under it. GIF by Pillow (matplotlib's own dependency); MP4 by ffmpeg
where it is installed.
"""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from localizer import DEFAULT_JAW, Outline, Part

from ..rig import RigError
from .belief_history import BeliefHistory, finger_outline, stated_axes

__all__ = ["write_film", "check_film", "MAX_FRAMES", "FILM_SUFFIXES"]

#: The most frames drawn: a longer rolling is sampled evenly (one frame a reading up to it).
MAX_FRAMES = 160
#: What the suffix of the output picks.
FILM_SUFFIXES = (".gif", ".mp4")


def _frames(n: int) -> NDArray[np.intp]:
    """The readings drawn: all of them up to MAX_FRAMES, else evenly spaced, the last included."""
    if n <= MAX_FRAMES:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, MAX_FRAMES)).astype(np.intp))


def _places(mass: NDArray[np.float64], edges: NDArray[np.float64], k: int = 3) -> list[tuple[float, float]]:
    """The ``k`` leading places of a belief histogram: (arc mm, share), each the peak of a run of bins
    separated by empty ones (at most 1e-6 of the fullest), its share the run's mass."""
    full = np.r_[False, mass > 1e-6 * mass.max(), False]
    starts = np.flatnonzero(full[1:] & ~full[:-1])
    stops = np.flatnonzero(full[:-1] & ~full[1:])
    runs: list[tuple[float, float]] = []
    for a, b in zip(starts, stops):
        seg = mass[a:b]
        peak = int(a) + int(np.argmax(seg))
        runs.append((0.5 * float(edges[peak] + edges[peak + 1]), float(seg.sum())))
    return sorted(runs, key=lambda r: -r[1])[:k]


def check_film(path: str | os.PathLike[str], fps: int = 10) -> str:
    """The suffix of a film :func:`write_film` can write to ``path`` at ``fps``; checked before the rolling is
    replayed for it, so that a film that cannot be written is refused at once.

    Raises
    ------
    RigError
        An output that is neither .gif nor .mp4, .mp4 without ffmpeg, ``fps`` not from 1 to 60.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in FILM_SUFFIXES:
        raise RigError(f"{path}: an animation is written as {' or '.join(FILM_SUFFIXES)}")
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise RigError(f"{path}: an MP4 needs ffmpeg, which is not installed; write a .gif instead")
    if not (isinstance(fps, int) and 1 <= fps <= 60):
        raise RigError(f"fps={fps!r} must be a whole number of frames per second from 1 to 60")
    return suffix


def write_film(
    part: Part | Outline,
    history: BeliefHistory,
    path: str | os.PathLike[str],
    *,
    fps: int = 10,
    wheel_radius: float | None = None,
) -> int:
    """Write the animation of ``history`` to ``path`` (.gif, or .mp4 with ffmpeg installed); returns the frames.

    ``wheel_radius`` (mm): draw a wheel finger of that radius on the part instead of the straight jaw.

    Raises
    ------
    RigError
        An output that is neither .gif nor .mp4, .mp4 without ffmpeg, a history without readings.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FFMpegWriter, PillowWriter
    from matplotlib.artist import Artist

    from .plotting import draw_part

    suffix = check_film(path, fps)
    readings = history.readings
    if not readings.shape[0] or not history.rotation.size:
        raise RigError("a rolling without readings or checks has nothing to animate")
    frames = _frames(readings.shape[0])
    centres = 0.5 * (history.edges[:-1] + history.edges[1:])
    ring = part.point_at_arc(centres)
    half = DEFAULT_JAW.half

    fig = plt.figure(figsize=(7.0, 6.6), layout="constrained")
    grid = fig.add_gridspec(2, 1, height_ratios=(5.0, 1.2))
    ax, ax_p = fig.add_subplot(grid[0]), fig.add_subplot(grid[1])
    draw_part(ax, part)
    lo, hi = ring.min(axis=0), ring.max(axis=0)
    pad = 0.05 * float(max(hi - lo)) + 0.6 * half
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.axis("off")
    cmap = matplotlib.colormaps["Reds"].with_extremes(bad=(0.0, 0.0, 0.0, 0.0))  # no belief: the part shows
    band = ax.scatter(ring[:, 0], ring[:, 1], c=np.zeros(len(ring)), cmap=cmap, vmin=0, vmax=1, s=30, zorder=5)
    (jaw_line,) = ax.plot([], [], "-", color="tab:blue", lw=4, alpha=0.8, solid_capstyle="butt", zorder=4)
    (contact,) = ax.plot([], [], "o", color="tab:blue", ms=5, mfc="none", zorder=6)
    labels = [ax.text(0, 0, "", fontsize=9, color="darkred", zorder=6) for _ in range(3)]
    title = ax.set_title("", fontsize=10)
    deg = np.degrees(history.rotation)
    ax_p.plot(deg, history.stated, "-", color="0.8", lw=1)
    (grown,) = ax_p.plot([], [], "-", color="tab:red", lw=1.6)
    stated_axes(ax_p, history, max(float(deg[-1]), 1.0))

    placed: dict[int, list[tuple[float, float]]] = {}  # frames between two checks show the same places

    def draw(k: int) -> list[Artist]:
        rotation, jaw, true_arc, check = readings[k]
        c = int(check)
        mass = history.mass[c] if c >= 0 else np.full(len(centres), 1.0 / len(centres))
        band.set_array(np.ma.masked_less(mass / max(float(mass.max()), 1e-300), 0.02))
        where = true_arc if math.isfinite(true_arc) else (history.map_arc[c] if c >= 0 else math.nan)
        if math.isfinite(where):
            outline = finger_outline(part, float(where), float(jaw), wheel_radius)
            jaw_line.set_data(outline[:, 0], outline[:, 1])
            p = part.point_at_arc(where)
            contact.set_data([p[0]], [p[1]])
        places = placed.setdefault(c, _places(mass, history.edges) if c >= 0 else [])
        for label, (arc, share) in zip(labels, places):
            xy = part.point_at_arc(arc)
            label.set_position((float(xy[0]), float(xy[1])))
            label.set_text(f" {share:.0%}")
        for label in labels[len(places) :]:
            label.set_text("")
        stated = history.stated[c] if c >= 0 else 0.0
        title.set_text(f"{part.name}: {math.degrees(rotation):.0f}° rolled, {stated:.0%} within the radius")
        grown.set_data(deg[: c + 1], history.stated[: c + 1])
        return [band, jaw_line, contact, grown, title, *labels]

    # laid out once, on the first frame (its title in place), and kept: each frame is then drawn once, where
    # an animation drew it three times (once to show it, twice to lay it out and save it)
    draw(int(frames[0]))
    fig.canvas.draw()
    fig.set_layout_engine("none")
    writer = PillowWriter(fps=fps) if suffix == ".gif" else FFMpegWriter(fps=fps)
    try:
        with writer.saving(fig, str(path), dpi=80):
            for k in frames:
                draw(int(k))
                writer.grab_frame()
    except OSError as exc:
        raise RigError(f"cannot write {path}: {exc.strerror or exc}") from None
    finally:
        plt.close(fig)
    return int(frames.size)
