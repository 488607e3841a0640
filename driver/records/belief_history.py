"""How a rolling's belief narrowed: its filter calls made again, the belief kept at every check, and drawn
as one picture.

:func:`replay_beliefs` makes the kept calls of a straight jaw's rolling (a reactive rolling's
:meth:`driver.records.LoggedFilter.columns`, or fixed rolls' :func:`sequence_calls`) on a fresh filter with
:func:`driver.records.replay_log`, and at every ``belief`` call (every check of the rolling) keeps the belief
over the present contact as a histogram along the part's arc, with the rotation rolled by then;
:func:`replay_wheel_beliefs` does the same with a wheel's readings. :func:`plot_belief_history` draws it:
the belief as an image (rotation across, arc on the part up), the truth over it where known, the
events of the rolling marked, and beside it the part with the final places and their probabilities.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import NDArray

from localizer import DEFAULT_JAW, Belief, Boundary, ContactFilter, Outline, Part, WheelFilter

from .filter_log import KeptCall, log_table, replay_log

if TYPE_CHECKING:
    from matplotlib.axes import Axes

FloatArray = NDArray[np.float64]

__all__ = [
    "BeliefHistory",
    "replay_beliefs",
    "replay_wheel_beliefs",
    "sequence_calls",
    "finger_outline",
    "stated_axes",
    "plot_belief_history",
    "ARC_BINS",
]

#: Bins along the part's arc of the belief's picture (a 300 mm part: 0.4 mm a bin).
ARC_BINS = 720


class BeliefHistory(NamedTuple):
    """The belief at every check of a rolling.

    Attributes
    ----------
    rotation : ndarray, rad
        Rotation rolled by each check (both ways counted).
    edges : ndarray, mm
        The bins' edges along the part's arc (``ARC_BINS`` + 1).
    mass : ndarray
        (checks, bins): the belief's probability in each bin.
    map_arc, stated : ndarray
        The most probable present contact (mm) and the stated probability within the radius, per check.
    true_arc : ndarray, mm
        The true contact at each check (NaN where unknown).
    events : list of (str, float)
        What the rolling did, at which rotation (rad): "turned round", "regrasp", "bridge", "restart".
    final : Belief
        The belief after the last call.
    readings : ndarray
        (readings, 4), one row per reading given to the filter: the rotation rolled by then (rad), the
        contact's measured place on the jaw (mm, NaN if not given), the true contact (mm, NaN where unknown)
        and the index of the last check before it (−1 before the first).
    """

    rotation: NDArray[np.float64]
    edges: NDArray[np.float64]
    mass: NDArray[np.float64]
    map_arc: NDArray[np.float64]
    stated: NDArray[np.float64]
    true_arc: NDArray[np.float64]
    events: list[tuple[str, float]]
    final: Belief
    readings: NDArray[np.float64]


class _Keeper:
    """What a replay keeps as it goes: the rotation rolled, the turns round, every reading and every check."""

    def __init__(self, part: Boundary) -> None:
        self.edges = np.linspace(0.0, part.perimeter, ARC_BINS + 1)
        self.rows: list[NDArray[np.float64]] = []
        self.checks: list[tuple[float, float, float, float]] = []  # rotation, map arc, stated, truth
        self.readings: list[tuple[float, float, float, float]] = []
        self.events: list[tuple[str, float]] = []
        self.rolled, self.last_turn, self.last_sign = 0.0, 0.0, 0.0
        self.belief: Belief | None = None

    def event(self, what: str) -> None:
        self.events.append((what, self.rolled))

    def restart(self) -> None:
        """The filter starts afresh: the next reading's net turn counts from 0 again."""
        if self.readings:
            self.event("restart")
        self.last_turn, self.last_sign = 0.0, 0.0

    def reading(self, turn: float, jaw: float, true_arc: float) -> None:
        """A reading at net turn ``turn`` (rad), the contact ``jaw`` mm along the jaw (NaN: not given)."""
        step = turn - self.last_turn
        sign = math.copysign(1.0, step) if step else self.last_sign
        if self.last_sign and sign != self.last_sign:
            self.event("turned round")
        self.rolled += abs(step)
        self.last_turn, self.last_sign = turn, sign
        self.readings.append((self.rolled, jaw, true_arc, float(len(self.rows) - 1)))

    def check(
        self, belief: Belief, present: NDArray[np.float64], weights: NDArray[np.float64], true_arc: float
    ) -> None:
        """A belief asked: its mass along the arc (each start's present contact, weighted)."""
        hist, _ = np.histogram(present, bins=self.edges, weights=weights)
        self.rows.append(hist / max(float(hist.sum()), 1e-300))
        self.checks.append((self.rolled, belief.map_arc, belief.mass, true_arc))
        self.belief = belief

    def history(self, final: Belief) -> BeliefHistory:
        checks = np.asarray(self.checks, dtype=float).reshape(-1, 4)
        return BeliefHistory(
            checks[:, 0],
            self.edges,
            np.asarray(self.rows).reshape(-1, ARC_BINS),
            checks[:, 1],
            checks[:, 2],
            checks[:, 3],
            self.events,
            final,
            np.asarray(self.readings, dtype=float).reshape(-1, 4),
        )


def replay_beliefs(
    flt: ContactFilter, columns: dict[str, np.ndarray], readings: dict[str, np.ndarray] | None = None
) -> BeliefHistory:
    """Make a kept log's calls on ``flt`` (a fresh filter) and keep the belief at every ``belief`` call.

    ``readings``: a simulated rolling's readings, ``arcs`` (mm), ``turns`` (rad) and ``true_arcs`` (mm), as its
    trace holds them; a check's truth is that of the last reading given to the filter, found among them by
    its arc and turn (the trace also holds readings the filter never took: a bridge's, a re-read spike).
    None or empty on a real rig.
    """
    keep = _Keeper(flt.part)
    rows_arc, rows_turn, rows_true = (
        (np.asarray(readings[k], dtype=float) for k in ("arcs", "turns", "true_arcs"))
        if readings
        else (np.zeros(0), np.zeros(0), np.zeros(0))
    )
    found, now_true = 0, float(rows_true[0]) if rows_true.size else math.nan

    def observe(name: str, arc: float, turn: float, jaw: float, value: float, belief: Belief | None) -> None:
        nonlocal found, now_true
        if name in ("update", "regrasp"):
            # the first of the readings not yet found that is this one: near the last found, so looked for
            # there first (a rolling has thousands of readings), then among the rest
            for lo, hi in ((found, found + 64), (found + 64, rows_turn.size)):
                match = np.flatnonzero(
                    (np.abs(rows_turn[lo:hi] - turn) < 1e-12) & (np.abs(rows_arc[lo:hi] - arc) < 1e-9)
                )
                if match.size:
                    found = lo + int(match[0]) + 1
                    now_true = float(rows_true[found - 1])
                    break
            keep.reading(turn, jaw, now_true)  # jaw: NaN where not given
            if name == "regrasp":
                keep.event("regrasp")
        elif name == "reset":
            keep.restart()
        elif name == "bridged":
            keep.event("bridge")
        elif belief is not None:
            keep.check(belief, flt.present(), flt.posterior(), now_true)

    return keep.history(replay_log(flt, columns, observe))


def sequence_calls(seq: dict[str, np.ndarray], check_every: int = 5) -> dict[str, np.ndarray]:
    """Fixed rolls' step sequence (:meth:`driver.records.Trace.step_sequence`) as the calls a sequential
    filter would have had: the first contact's place on the jaw, every later reading, and the belief asked
    every ``check_every`` readings and at the end (a kept log, :data:`LOG_COLUMNS`)."""
    z, turn, jaw = (np.asarray(seq[k], dtype=float) for k in ("z", "turn", "jaw"))
    calls: list[KeptCall] = [("touch", None, None, float(jaw[0]), None)]
    for j in range(1, z.size):
        calls.append(("update", float(z[j]), float(turn[j]), float(jaw[j]), None))
        if j % check_every == 0 or j == z.size - 1:
            calls.append(("belief", None, None, None, None))
    return log_table(calls)


def replay_wheel_beliefs(flt: WheelFilter, columns: dict[str, np.ndarray], check_every: int = 4) -> BeliefHistory:
    """A wheel's readings (a :class:`~driver.records.WheelTrace`'s ``segment``, ``length``, ``turn``,
    ``true_arc``) given to ``flt`` (a fresh filter for its finger), the belief kept every ``check_every``
    readings (the wheel's rolling checks every 4) and at the end. The rolling started afresh at every new
    segment, and so does the filter (a "restart"); the jumps the rolling told its filter are not in a
    trace, so the replay's belief may differ a little from the run's.
    """
    keep = _Keeper(flt.part)
    segment, length, turn, truth = (np.asarray(columns[k]) for k in ("segment", "length", "turn", "true_arc"))
    for k in range(length.size):
        if k and segment[k] != segment[k - 1]:
            keep.restart()
            flt.reset()
        keep.reading(float(turn[k]), math.nan, float(truth[k]))
        flt.update(float(length[k]), float(turn[k]))  # as WheelTrace.relocalize gives them
        if (k + 1) % check_every == 0 or k == length.size - 1:
            keep.check(flt.belief(), flt.present(), flt.posterior(), float(truth[k]))
    return keep.history(keep.belief if keep.belief is not None else flt.belief())


def finger_outline(part: Boundary, arc: float, jaw: float, wheel_radius: float | None = None) -> FloatArray:
    """The finger touching the part at ``arc`` (mm), as points (n, 2) mm to draw: the straight jaw along the
    tangent there with the contact ``jaw`` mm along it (0 where NaN), or a wheel of ``wheel_radius`` mm
    outside the part (its hub along the outward normal: the tangent turned −90°)."""
    p = part.point_at_arc(arc)
    angle = float(part.tangent_angle_at_arc(arc))
    e = np.array([math.cos(angle), math.sin(angle)])
    if wheel_radius is None:
        centre = p - (jaw if math.isfinite(jaw) else 0.0) * e
        return np.array([centre - DEFAULT_JAW.half * e, centre + DEFAULT_JAW.half * e])
    hub = p + wheel_radius * np.array([e[1], -e[0]])
    t = np.linspace(0.0, 2.0 * math.pi, 49)
    return np.column_stack([hub[0] + wheel_radius * np.cos(t), hub[1] + wheel_radius * np.sin(t)])


def stated_axes(ax: Axes, history: BeliefHistory, right: float) -> None:
    """The axes of the stated probability against the rotation rolled (to ``right`` degrees)."""
    ax.set_xlim(0.0, right)
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel("rotation rolled, degrees")
    ax.set_ylabel(f"P(within {history.final.radius:g} mm)", fontsize=8)
    ax.grid(alpha=0.3)


#: How many moments of the rolling the picture draws the finger at, beside the belief.
FINGER_MOMENTS = 4


def plot_belief_history(
    part: Part | Outline,
    history: BeliefHistory,
    path: str | os.PathLike[str],
    *,
    title: str = "",
    wheel_radius: float | None = None,
) -> None:
    """Draw ``history`` to the PNG ``path``: the belief along the part's arc against the rotation rolled (darker
    is more probable, each check against its own most probable place; the truth a line, the most probable
    contact dots, the rolling's events as dashed lines), the stated probability under it, and beside it the
    part with the finger (a ``wheel_radius`` mm disc, else the straight jaw) at a few moments, the final places
    and the truth."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .plotting import draw_part

    if not history.rotation.size:
        raise ValueError("a rolling that never asked its belief has no history to draw")
    deg = np.degrees(history.rotation)
    fig = plt.figure(figsize=(12, 6.2), layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(1.7, 1.0), height_ratios=(3.2, 1.0))
    ax, ax_p, ax_part = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[:, 1])
    right = deg[-1] + (deg[-1] - deg[-2] if deg.size > 1 else 1.0)
    columns = np.concatenate([deg, [right]])
    # each check's belief against its own most probable bin: where it is at every moment, however spread
    shade = history.mass / np.maximum(history.mass.max(axis=1, keepdims=True), 1e-300)
    ax.pcolormesh(columns, history.edges, shade.T, cmap="Greys", vmin=0.0, vmax=1.0, shading="flat", rasterized=True)
    ax.plot(deg, history.map_arc, ".", color="tab:red", ms=3, label="most probable contact")
    if np.isfinite(history.true_arc).any():
        # broken where the contact passes the arc's origin, not drawn across the picture
        line = history.true_arc.copy()
        line[1:][np.abs(np.diff(line)) > 0.5 * part.perimeter] = np.nan
        ax.plot(deg, line, "-", color="tab:blue", lw=1.2, alpha=0.8, label="true contact")
    colours = {"turned round": "tab:green", "regrasp": "tab:purple", "bridge": "tab:orange", "restart": "black"}
    shown: set[str] = set()
    for what, at in history.events:
        ax.axvline(math.degrees(at), color=colours[what], lw=0.8, ls="--", label=None if what in shown else what)
        shown.add(what)
    ax.set_xlim(0.0, right)
    ax.set_ylim(0.0, part.perimeter)
    ax.set_ylabel("arc on the part, mm")
    fig.suptitle(title or f"the belief while rolling on {part.name}", fontsize=11)
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=6, fontsize=7, frameon=False)
    ax_p.plot(deg, history.stated, "-", color="tab:red", lw=1.2)
    stated_axes(ax_p, history, right)
    draw_part(ax_part, part)
    # the finger at a few moments, fainter the earlier, where the contact was (the truth, else the estimate)
    rows = history.readings
    for n, k in enumerate(np.linspace(0, rows.shape[0] - 1, FINGER_MOMENTS).round().astype(int) if rows.size else []):
        rotation, jaw, true_arc, check = rows[k]
        arc = true_arc if math.isfinite(true_arc) else history.map_arc[max(int(check), 0)]
        xy = finger_outline(part, float(arc), float(jaw), wheel_radius)
        alpha = 0.25 + 0.6 * n / max(FINGER_MOMENTS - 1, 1)
        ax_part.plot(xy[:, 0], xy[:, 1], "-", color="tab:blue", lw=2.5, alpha=alpha, solid_capstyle="butt")
        ax_part.annotate(
            f"{math.degrees(rotation):.0f}°", (float(xy[-1, 0]), float(xy[-1, 1])), fontsize=7, color="tab:blue"
        )
    for k, m in enumerate(history.final.modes[:4]):
        xy = part.point_at_arc(m.arc)
        ax_part.plot(*xy, "*", ms=14 if k == 0 else 9, color="tab:red", alpha=1.0 if k == 0 else 0.6)
        ax_part.annotate(
            f"{m.mass:.0%}",
            (float(xy[0]), float(xy[1])),
            textcoords="offset points",
            xytext=(6, 6),
            fontsize=8,
            color="tab:red",
        )
    if np.isfinite(history.true_arc[-1]):
        ax_part.plot(*part.point_at_arc(history.true_arc[-1]), "o", mfc="none", color="tab:blue", ms=10)
    ax_part.set_title(
        "the finger at a few moments (blue), the final places\n"
        "with their shares of the belief (red), the truth (circle)",
        fontsize=9,
    )
    ax_part.set_aspect("equal")
    ax_part.axis("off")
    fig.savefig(path, dpi=110)
    plt.close(fig)
