"""The likelihood rule's forward recursion on a drawing, compiled (numba): one roll's sums in one loop.

:func:`localizer.chain._outline_chain.chain_likelihood` sums, for every state of the contact, the
weights of every way into it from the states one roll before: from the grid, a run of sources within
five standard errors of the measured travel (a thousand at the CLI's ``sd_length`` of 0.5 mm and the
rule's 0.01 mm grid), and from each corner the jaw angles near the one the turn asks for. In numpy
that was one pass over every state per source offset, a dozen temporaries each: 1-2 s a two-roll
query on the shipped drawings. Here each state's terms are added in the same order with the same
arithmetic, a running log-sum-exp and arg-max per state, and a term more than :data:`UNDERFLOW` nats
under the state's running largest is left out (it would not change the sum, which is at least 1 in
units of that largest, by a rounding).
"""

from __future__ import annotations

import math

import numba

from .._types import FloatArray, IntArray

__all__ = ["add_from_runs", "add_from_pairs", "sum_from_runs", "sum_from_pairs", "TURN_CUT"]

#: Terms this many nats below a sum's largest are left out (e⁻⁵⁰ ≈ 2·10⁻²²).
UNDERFLOW = 50.0
#: In the sums taken relative to the largest source (:func:`sum_from_runs`), a turn this many standard
#: errors off weighs e⁻⁷²⁰, below what a double holds next to 1: the way is not weighed.
TURN_CUT = 38.0


@numba.njit(cache=True)
def _add(j: int, v: float, src: int, top: FloatArray, acc: FloatArray, best: FloatArray, best_from: IntArray) -> None:
    """Add the term ``v`` (log-weight) from state ``src`` to state ``j``'s running sum and arg-max."""
    if v > best[j]:
        best[j] = v
        best_from[j] = src
    t = top[j]
    if v > t:
        acc[j] = acc[j] * math.exp(t - v) + 1.0 if t > -math.inf else 1.0
        top[j] = v
    elif v > t - UNDERFLOW:
        acc[j] += math.exp(v - t)


@numba.njit(cache=True)
def add_from_runs(
    sig: FloatArray,
    psi: FloatArray,
    g_sig: FloatArray,
    g_psi: FloatArray,
    g_idx: IntArray,
    a_lo: IntArray,
    a_hi: IntArray,
    prev: FloatArray,
    sign: float,
    length: float,
    omega: float,
    sd_length: float,
    sd_turn: float,
    top: FloatArray,
    acc: FloatArray,
    best: FloatArray,
    best_from: IntArray,
) -> None:
    """Add to every state ``j`` (arc ``sig``, mm; jaw angle ``psi``, rad) the ways into it from the grid's
    states ``a_lo[j]`` to ``a_hi[j]`` − 1 (at ``g_sig``, ``g_psi``; state ``g_idx``; log-weight
    ``prev``) by a roll of travel ``length`` mm in direction ``sign`` and turn ``omega`` rad: Gaussian in
    both, their standard errors ``sd_length`` and ``sd_turn``; a way that does not travel forward weighs
    nothing. The running sums ``top``, ``acc`` (log-sum-exp: top + log acc) and the arg-max ``best``,
    ``best_from`` are updated in place."""
    for j in range(sig.size):
        for a in range(a_lo[j], a_hi[j]):
            travel = sign * (sig[j] - g_sig[a])
            if travel <= 0.0:
                continue
            s = g_idx[a]
            v = prev[s] - 0.5 * ((psi[j] - g_psi[a] - omega) / sd_turn) ** 2
            v = v - 0.5 * ((travel - length) / sd_length) ** 2
            _add(j, v, s, top, acc, best, best_from)


@numba.njit(cache=True)
def add_from_pairs(
    at: IntArray,
    src_sig: FloatArray,
    src_psi: FloatArray,
    src: IntArray,
    sig: FloatArray,
    psi: FloatArray,
    prev: FloatArray,
    sign: float,
    length: float,
    omega: float,
    sd_length: float,
    sd_turn: float,
    top: FloatArray,
    acc: FloatArray,
    best: FloatArray,
    best_from: IntArray,
) -> None:
    """As :func:`add_from_runs`, for the ways listed one by one: into state ``at[i]`` from state ``src[i]``
    at arc ``src_sig[i]`` and angle ``src_psi[i]``."""
    for i in range(at.size):
        j = at[i]
        travel = sign * (sig[j] - src_sig[i])
        if travel <= 0.0:
            continue
        v = prev[src[i]] - 0.5 * ((psi[j] - src_psi[i] - omega) / sd_turn) ** 2
        v = v - 0.5 * ((travel - length) / sd_length) ** 2
        _add(j, v, src[i], top, acc, best, best_from)


@numba.njit(cache=True)
def sum_from_runs(
    sig: FloatArray,
    psi: FloatArray,
    g_sig: FloatArray,
    g_psi: FloatArray,
    g_idx: IntArray,
    a_lo: IntArray,
    a_hi: IntArray,
    weight: FloatArray,
    sign: float,
    length: float,
    omega: float,
    sd_length: float,
    sd_turn: float,
    acc: FloatArray,
    best: FloatArray,
    best_from: IntArray,
) -> None:
    """:func:`add_from_runs` with the sources' weights given as ``weight`` = exp(prev − max prev): each
    state's sum ``acc`` and its largest term ``best`` (from ``best_from``) in those units. A way whose turn
    is :data:`TURN_CUT` standard errors off is not weighed, and a turn shared by a run of sources (a
    face) is weighed once: no exponential for most ways, one for the rest."""
    cut = TURN_CUT * sd_turn
    for j in range(sig.size):
        last = math.nan
        g_turn = 0.0
        for a in range(a_lo[j], a_hi[j]):
            travel = sign * (sig[j] - g_sig[a])
            if travel <= 0.0:
                continue
            d = psi[j] - g_psi[a] - omega
            if abs(d) > cut:
                continue
            s = g_idx[a]
            w = weight[s]
            if w == 0.0:
                continue
            if d != last:
                g_turn = math.exp(-0.5 * (d / sd_turn) ** 2)
                last = d
            t = w * g_turn * math.exp(-0.5 * ((travel - length) / sd_length) ** 2)
            acc[j] += t
            if t > best[j]:
                best[j] = t
                best_from[j] = s


@numba.njit(cache=True)
def sum_from_pairs(
    at: IntArray,
    src_sig: FloatArray,
    src_psi: FloatArray,
    src: IntArray,
    sig: FloatArray,
    psi: FloatArray,
    weight: FloatArray,
    sign: float,
    length: float,
    omega: float,
    sd_length: float,
    sd_turn: float,
    acc: FloatArray,
    best: FloatArray,
    best_from: IntArray,
) -> None:
    """:func:`add_from_pairs` as :func:`sum_from_runs` takes :func:`add_from_runs`."""
    for i in range(at.size):
        j = at[i]
        travel = sign * (sig[j] - src_sig[i])
        if travel <= 0.0:
            continue
        w = weight[src[i]]
        if w == 0.0:
            continue
        t = w * math.exp(-0.5 * ((psi[j] - src_psi[i] - omega) / sd_turn) ** 2)
        t *= math.exp(-0.5 * ((travel - length) / sd_length) ** 2)
        acc[j] += t
        if t > best[j]:
            best[j] = t
            best_from[j] = src[i]
