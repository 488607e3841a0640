"""Disambiguation over a chain of rolls on an outline with corners (the rules of
:func:`localizer.localize`, for parts drawn in CAD).

On a spline part the likelihood rule fits each mode by least squares; on an outline that cannot
work: θ jumps at corners (the fit's cost is not smooth), and on lines and equal arcs whole stretches
fit equally (continua), where a fit would pick one point and call it sure. So here both rules look
at every start:

``"likelihood"``
    The exact marginal over a grid of positions every ``spacing`` mm: the start is uniform on the
    grid, and roll k moves the contact from cell a to cell b with probability
    N(travel − L_k; sd_length²) · N(Ω_k − Φ(a, b); sd_turn²), Φ the tangent's turn between the cells.
    A cell that holds a corner stands for every jaw angle within its jump, so Φ is an interval there
    and the turn's error is the distance to it. The sum over every path (the forward recursion)
    gives the posterior of the present contact; the most probable path into each of its modes
    (max-product) gives the candidate's start and rolls. A mode's probability is the posterior mass
    within ``min_separation`` of its peak, so a mode spread along a face (a continuum the rolls did
    not resolve) is honestly not sure.

``"paper"``
    Jia's rule: every first-roll segment is a candidate (a continuum is sampled along its span every
    ``spacing`` mm and its best start kept), followed with the measured lengths; a following end
    within ``length_tol`` of a corner may be at any angle of its jump.
"""

from __future__ import annotations

import math

import numpy as np

from .._types import FloatArray, IntArray
from ..geometry import Outline, check_grid, count_text
from ..solve import Segment

__all__: list[str] = []

#: The most candidates the likelihood rule reports (a long face the rolls did not resolve would give
#: one per ``min_separation``).
MAX_CANDIDATES = 200


def _interval(outline: Outline, sigma: FloatArray, half: float) -> tuple[FloatArray, FloatArray]:
    """(lowest, highest) tangent angle, rad, of a contact within ``half`` mm of ``sigma`` (unrolled, mm):
    θ ∓ |κ|·half on a smooth stretch, the whole jump where the window holds a corner."""
    mid = outline.tangent_angle_at_arc(sigma)
    a = outline.tangent_angle_at_arc(sigma - half, side="before")
    b = outline.tangent_angle_at_arc(sigma + half, side="after")
    lo: FloatArray = np.minimum(np.minimum(a, b), mid)
    hi: FloatArray = np.maximum(np.maximum(a, b), mid)
    return lo, hi


def _nodes(outline: Outline, h: float, dpsi: float) -> tuple[FloatArray, FloatArray, list[IntArray]]:
    """The contact's states over one lap as (arc σ, jaw angle ψ) pairs in rolling order: a point every
    ``h`` mm where ψ = θ(σ), and at each corner the jaw's angles within the jump every ``dpsi`` rad at
    the corner's σ. A roll from one state to another travels their σ difference and turns by their ψ
    difference, so a jaw that stops on a corner starts the next roll at the angle it stopped at.
    Also returns each corner's states (indices, in rolling order)."""
    P = outline.perimeter
    n = int(math.ceil(P / h))
    # the states are a point every h and each corner's angles every dpsi; several arrays of them per roll
    at_corners = sum(max(2, int(math.ceil(abs(c.angle) / dpsi))) - 1 for c in outline.corners)
    advice = (
        f"{count_text(at_corners)} of them at its {len(outline.corners)} corners, one every {dpsi:.3g} rad of their "
        "jumps: give a larger sd_turn"
        if at_corners > n
        else "is the part in the right units (mm)?"
    )
    check_grid(outline, "roll chain", h, n + at_corners, unit="states", advice=advice)
    sig = np.arange(n) * (P / n)
    psi = outline.tangent_angle_at_arc(sig)
    order_key, owner = [np.zeros(n)], [np.full(n, -1)]
    sigs, psis = [sig], [psi]
    for i, c in enumerate(outline.corners):
        m = max(2, int(math.ceil(abs(c.angle) / dpsi)))
        before = float(outline.tangent_angle_at_arc(np.array([c.arc]), side="before")[0])
        frac = np.arange(1, m) / m
        sigs.append(np.full(m - 1, c.arc))
        psis.append(before + c.angle * frac)
        order_key.append(frac - 1.0)  # before the grid point at the corner itself (θ after the jump)
        owner.append(np.full(m - 1, i))
    sig_all, psi_all, key = np.concatenate(sigs), np.concatenate(psis), np.concatenate(order_key)
    order = np.lexsort((key, sig_all))
    own = np.concatenate(owner)[order]
    return sig_all[order], psi_all[order], [np.flatnonzero(own == i) for i in range(len(outline.corners))]


class _LogSum:
    """Running log-sum-exp and arg-max over candidate terms, one slot per state."""

    def __init__(self, n: int) -> None:
        self.top = np.full(n, -np.inf)
        self.acc = np.zeros(n)
        self.best = np.full(n, -np.inf)
        self.best_from = np.zeros(n, dtype=np.int64)

    def add(self, at: IntArray, v: FloatArray, source: IntArray) -> None:
        """Add the terms ``v`` to the slots ``at`` (distinct), from states ``source``."""
        top, acc = self.top[at], self.acc[at]
        better = v > self.best[at]
        self.best[at] = np.where(better, v, self.best[at])
        self.best_from[at] = np.where(better, source, self.best_from[at])
        m = np.maximum(top, v)
        fin = np.isfinite(m)
        m0 = np.where(fin, m, 0.0)
        with np.errstate(invalid="ignore"):
            old = np.where(np.isfinite(top), np.exp(top - m0), 0.0)
        self.acc[at] = np.where(fin, acc * old + np.exp(v - m0), 0.0)
        self.top[at] = m

    def total(self) -> FloatArray:
        out: FloatArray = np.full(self.top.size, -np.inf)
        ok = self.acc > 0
        out[ok] = self.top[ok] + np.log(self.acc[ok])
        return out


def chain_likelihood(
    outline: Outline,
    chain: tuple[tuple[float, float], ...],
    sign: float,
    sd_length: float,
    sd_turn: float,
    min_separation: float,
    spacing: float = 0.01,
) -> list[tuple[float, FloatArray, FloatArray]]:
    """The likelihood rule (module notes). Returns, per mode of the present contact, most probable
    first: (probability, the most probable path's unrolled arcs (mm), its turn residuals (rad))."""
    P = outline.perimeter
    turning = float(outline.turning)
    dpsi = max(sd_turn, 1e-6)
    sig, psi, corner_states = _nodes(outline, spacing, dpsi)
    n = sig.size
    dest = np.arange(n)
    # the grid's states over three laps, so that a window past either end of the lap finds them
    on_grid = np.ones(n, dtype=bool)
    for c in corner_states:
        on_grid[c] = False
    g = np.flatnonzero(on_grid)
    g_sig = np.concatenate([sig[g] - P, sig[g], sig[g] + P])
    g_psi = np.concatenate([psi[g] - turning, psi[g], psi[g] + turning])
    g_idx = np.concatenate([g, g, g])
    reach = int(math.ceil(6.0 * sd_turn / dpsi)) + 1  # a corner's states worth weighing per destination
    log_alpha = np.full(n, -math.log(n))
    backs: list[IntArray] = []
    for L, omega in chain:
        wide = max(5.0 * sd_length, 2.0 * spacing)
        into = _LogSum(n)

        def term(
            src_sig: FloatArray, src_psi: FloatArray, src: IntArray, at: IntArray, prev: FloatArray = log_alpha
        ) -> FloatArray:
            """Log-weight of arriving at states ``at`` from ``src`` (at σ ``src_sig``, ψ ``src_psi``)."""
            travel = sign * (sig[at] - src_sig)
            v = prev[src] - 0.5 * ((psi[at] - src_psi - omega) / sd_turn) ** 2  # noqa: B023 (called in this roll only)
            v = v - 0.5 * ((travel - L) / sd_length) ** 2  # noqa: B023
            out: FloatArray = np.where(travel > 0, v, -np.inf)
            return out

        # from the grid: each destination's sources are a contiguous run of it
        a_lo = np.searchsorted(g_sig, sig - sign * L - wide, side="left")
        a_hi = np.searchsorted(g_sig, sig - sign * L + wide, side="right")
        for k in range(int((a_hi - a_lo).max(initial=0))):
            ok = a_lo + k < a_hi
            a = a_lo[ok] + k
            into.add(dest[ok], term(g_sig[a], g_psi[a], g_idx[a], dest[ok]), g_idx[a])
        # from a corner: only its angles near ψ_destination − Ω (its states are ordered by angle)
        for c in corner_states:
            c_psi = psi[c]
            ascending = c_psi[-1] >= c_psi[0]
            for lap in (-1, 0, 1):
                c_sig = float(sig[c[0]]) + lap * P
                at = np.flatnonzero(np.abs(sign * (sig - c_sig) - L) <= wide)
                if at.size == 0:
                    continue
                want = psi[at] - omega - lap * turning
                near = np.searchsorted(c_psi if ascending else c_psi[::-1], want)
                if not ascending:
                    near = c.size - near
                for dj in range(-reach, reach + 1):
                    jx = near + dj
                    ok = (jx >= 0) & (jx < c.size)
                    src = c[jx[ok]]
                    into.add(at[ok], term(np.full(src.size, c_sig), psi[src] + lap * turning, src, at[ok]), src)
        log_alpha = into.total()
        if not np.isfinite(log_alpha).any():
            return []
        backs.append(into.best_from)
    w = np.exp(log_alpha - log_alpha.max())
    w /= w.sum()
    # the present contact's weight per cell of the σ grid (a corner's angles share its cell)
    cells = int(math.ceil(P / spacing))
    cell = np.minimum((sig / P * cells).astype(np.int64), cells - 1)
    wc = np.bincount(cell, weights=w, minlength=cells)
    live = wc > 1e-9 * wc.max()
    taken = np.zeros(cells, dtype=bool)
    radius = max(int(round(min_separation / (P / cells))), 1)
    out: list[tuple[float, FloatArray, FloatArray]] = []
    # each candidate claims the posterior within min_separation of its peak that no better one has:
    # a mode spread along a face gives several, each saying how little it holds
    for top_cell in np.argsort(-wc):
        j = int(top_cell)
        if not live[j]:
            break
        if len(out) >= MAX_CANDIDATES:
            break
        if taken[j]:
            continue
        window = np.mod(np.arange(j - radius, j + radius + 1), cells)
        window = window[~taken[window]]
        prob = float(wc[window].sum())
        taken[window] = True
        # the most probable path into the mode's most probable state, back to the start
        here = np.flatnonzero(cell == j)
        path = [int(here[np.argmax(log_alpha[here])])]
        for back in reversed(backs):
            path.append(int(back[path[-1]]))
        idx = np.array(path[::-1], dtype=np.int64)
        arcs = np.empty(idx.size)
        arcs[0] = sig[idx[0]]
        for k in range(1, idx.size):
            arcs[k] = arcs[k - 1] + sign * ((sign * (sig[idx[k]] - sig[idx[k - 1]])) % P)
        turns = psi[idx] + turning * np.floor(arcs / P + 1e-12)
        res = np.diff(turns) - np.array([w_ for _, w_ in chain])
        out.append((prob, arcs, res))
    out.sort(key=lambda m: -m[0])
    return out


def chain_paper(
    outline: Outline,
    chain: tuple[tuple[float, float], ...],
    segs: list[Segment],
    sign: float,
    length_tol: float,
    spacing: float = 0.01,
) -> list[tuple[float, FloatArray, FloatArray]]:
    """Jia's rule (module notes): per first-roll segment, (summed mismatch of the following rolls, rad;
    the unrolled positions, mm; each roll's turn residual, rad)."""
    lengths = np.array([L for L, _ in chain])
    omegas = np.array([w for _, w in chain])
    rows: list[tuple[float, FloatArray, FloatArray]] = []
    for seg in segs:
        starts = np.array([seg.start_arc])
        if seg.kind == "continuum" and seg.span > 0:
            check_grid(outline, "paper rule", spacing, seg.span / spacing + 1, unit="starts along a face")
            starts = seg.start_arc + sign * np.linspace(0.0, seg.span, max(2, int(seg.span / spacing) + 1))
        pos = starts[:, None] + sign * np.concatenate([[0.0], np.cumsum(lengths)])[None, :]
        lo, hi = _interval(outline, pos.ravel(), length_tol)
        lo, hi = lo.reshape(pos.shape), hi.reshape(pos.shape)
        # the jaw's angle is carried from roll to roll: the angles it can have after roll k are those
        # after roll k − 1 turned by Ω_k, within what the contact's place allows; where none are, the
        # mismatch is the gap and the nearest allowed angle goes on
        f_lo, f_hi = lo[:, 0].copy(), hi[:, 0].copy()
        res = np.zeros((starts.size, len(chain)))
        for k, omega in enumerate(omegas):
            t_lo, t_hi = f_lo + omega, f_hi + omega
            n_lo, n_hi = np.maximum(t_lo, lo[:, k + 1]), np.minimum(t_hi, hi[:, k + 1])
            empty = n_lo > n_hi
            # signed: Ω minus the nearest turn that fits
            res[:, k] = np.where(empty, np.where(t_lo > hi[:, k + 1], t_lo - hi[:, k + 1], t_hi - lo[:, k + 1]), 0.0)
            near = np.where(t_lo > hi[:, k + 1], hi[:, k + 1], lo[:, k + 1])
            f_lo, f_hi = np.where(empty, near, n_lo), np.where(empty, near, n_hi)
        mismatch = np.abs(res[:, 1:]).sum(axis=1)
        # every start of a continuum is a candidate of its own (the caller merges the close ones)
        rows.extend((float(mismatch[k]), pos[k], res[k]) for k in range(starts.size))
    return rows
