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
from typing import NamedTuple

import numpy as np

from .._types import FloatArray, IntArray
from ..geometry import Outline, check_grid, count_text
from ..solve import Segment
from ._chain_kernels import UNDERFLOW, add_from_pairs, add_from_runs, sum_from_pairs, sum_from_runs

__all__: list[str] = []

#: The most candidates the likelihood rule reports (a long face the rolls did not resolve would give
#: one per ``min_separation``).
MAX_CANDIDATES = 200
#: A way the sums relative to a roll's largest source leave out weighs less than e^-LOST_BELOW of it: the
#: smallest positive double is e⁻⁷⁴⁵, a normal one e⁻⁷⁰⁸, and a turn TURN_CUT standard errors off e⁻⁷²².
LOST_BELOW = 708.0


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
    """Running log-sum-exp (top + log acc) and arg-max over the terms into each state, filled by the
    kernels of :mod:`localizer.chain._chain_kernels`."""

    def __init__(self, n: int) -> None:
        self.top = np.full(n, -np.inf)
        self.acc = np.zeros(n)
        self.best = np.full(n, -np.inf)
        self.best_from = np.zeros(n, dtype=np.int64)

    def total(self) -> FloatArray:
        out: FloatArray = np.full(self.top.size, -np.inf)
        ok = self.acc > 0
        out[ok] = self.top[ok] + np.log(self.acc[ok])
        return out


class _Ways(NamedTuple):
    """The ways into every state by one roll: from the grid's states ``a_lo[j]`` to ``a_hi[j]`` − 1 (over
    three laps), and from the corners' angles listed as (into, from arc, from angle, from state)."""

    a_lo: IntArray
    a_hi: IntArray
    pairs: list[tuple[IntArray, FloatArray, FloatArray, IntArray]]

    @property
    def most(self) -> int:
        """The most ways into any one state (at least 1)."""
        return max(
            1,
            int((self.a_hi - self.a_lo).max(initial=0))
            + sum(int(np.bincount(p[0]).max(initial=0)) for p in self.pairs),
        )


def _ways(
    sig: FloatArray,
    psi: FloatArray,
    corner_states: list[IntArray],
    g_sig: FloatArray,
    sign: float,
    L: float,
    omega: float,
    P: float,
    turning: float,
    sd_length: float,
    spacing: float,
    reach: int,
) -> _Ways:
    """The sources worth weighing for each state after a roll of travel ``L`` and turn ``omega``: within five
    standard errors of the travel, and at a corner its ``reach`` angles on each side of the one the turn asks."""
    wide = max(5.0 * sd_length, 2.0 * spacing)
    # from the grid: each destination's sources are a contiguous run of it
    a_lo = np.searchsorted(g_sig, sig - sign * L - wide, side="left")
    a_hi = np.searchsorted(g_sig, sig - sign * L + wide, side="right")
    pairs = []
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
            # each destination's angles in the order of their offset from the nearest
            jx = near[None, :] + np.arange(-reach, reach + 1)[:, None]
            ok = (jx >= 0) & (jx < c.size)
            src = c[jx[ok]]
            pairs.append((np.broadcast_to(at, jx.shape)[ok], np.full(src.size, c_sig), psi[src] + lap * turning, src))
    return _Ways(a_lo, a_hi, pairs)


class Forward(NamedTuple):
    """The forward recursion over a chain: the states (arc ``sig``, mm; jaw angle ``psi``, rad), each one's
    log-weight after the last roll (``log_alpha``, unnormalised) and, per roll, the state each one's most
    probable way came from (``backs``)."""

    sig: FloatArray
    psi: FloatArray
    log_alpha: FloatArray
    backs: list[IntArray]


def chain_forward(
    outline: Outline,
    chain: tuple[tuple[float, float], ...],
    sign: float,
    sd_length: float,
    sd_turn: float,
    spacing: float = 0.01,
    *,
    exact: bool = False,
) -> Forward | None:
    """The likelihood rule's sum over every path (module notes); None when no path has any weight.

    Each roll's sums are taken relative to the largest source (:func:`sum_from_runs`): one exponential a
    way at most, none for a way whose turn is far off. A way so left out, or lost below what a double
    holds, weighs under e⁻⁷⁰⁸ of that roll's largest source, so each state's error is under W·e⁻⁷⁰⁸ of it
    (W ways into a state), and after R rolls under (2W)^R·e⁻⁷⁰⁸ of the largest source any roll had. While the
    best final state weighs e⁵⁰ more than that, what was left out is below a rounding of the posterior;
    else (a chain that fits almost nowhere) the whole chain is summed again in logarithms, every way
    weighed (``exact``: always so)."""
    P = outline.perimeter
    turning = float(outline.turning)
    dpsi = max(sd_turn, 1e-6)
    sig, psi, corner_states = _nodes(outline, spacing, dpsi)
    n = sig.size
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
    lost = -math.inf  # the log of the most any left-out way could have added to the final states
    for L, omega in chain:
        roll = (sign, float(L), float(omega), sd_length, sd_turn)
        ways = _ways(
            sig, psi, corner_states, g_sig, sign, float(L), float(omega), P, turning, sd_length, spacing, reach
        )
        if exact:
            into = _LogSum(n)
            sums = (into.top, into.acc, into.best, into.best_from)
            add_from_runs(sig, psi, g_sig, g_psi, g_idx, ways.a_lo, ways.a_hi, log_alpha, *roll, *sums)
            for at, src_sig, src_psi, src in ways.pairs:
                add_from_pairs(at, src_sig, src_psi, src, sig, psi, log_alpha, *roll, *sums)
            log_alpha, best_from = into.total(), into.best_from
        else:
            top = float(log_alpha.max())
            weight = np.exp(log_alpha - top)
            acc, best, best_from = np.zeros(n), np.zeros(n), np.zeros(n, dtype=np.int64)
            sum_from_runs(sig, psi, g_sig, g_psi, g_idx, ways.a_lo, ways.a_hi, weight, *roll, acc, best, best_from)
            for at, src_sig, src_psi, src in ways.pairs:
                sum_from_pairs(at, src_sig, src_psi, src, sig, psi, weight, *roll, acc, best, best_from)
            with np.errstate(divide="ignore"):
                log_alpha = top + np.log(acc)
            lost = max(lost, top - LOST_BELOW) + math.log(2.0 * ways.most)
        if not np.isfinite(log_alpha).any():
            break
        backs.append(best_from)
    if not exact and not log_alpha.max() >= lost + UNDERFLOW:
        return chain_forward(outline, chain, sign, sd_length, sd_turn, spacing, exact=True)
    if not np.isfinite(log_alpha).any():
        return None
    return Forward(sig, psi, log_alpha, backs)


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
    forward = chain_forward(outline, chain, sign, sd_length, sd_turn, spacing)
    if forward is None:
        return []
    sig, psi, log_alpha, backs = forward
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
