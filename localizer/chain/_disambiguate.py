"""Disambiguation over a chain of consecutive rolls (paper §II-B, §IV, and beyond).

A chain ``[(L1, Ω1), (L2, Ω2), ...]`` is what the jaw measured in consecutive
rolls, each starting where the previous one ended. Two rules:

``"paper"``
    Jia's rule (§IV): every feasible segment of the first roll is a candidate;
    follow each with segments of the measured lengths and keep the candidates
    whose following total curvatures best match the measured rotations. A
    following segment may be up to ``length_tol`` mm longer or shorter (the
    paper's ±0.004 mm), and candidates whose summed mismatch is within
    ``turn_tol`` rad per roll (the paper's ±0.0004) of the best are kept
    together, with equal probability.

``"likelihood"``
    A posterior over the starting arc position under Gaussian errors of
    standard deviation ``sd_length`` (mm) on each measured length and
    ``sd_turn`` (rad) on each measured rotation. The true lengths are nuisance
    parameters; each mode is located by least squares on
    ``[(Φ_k - Ω_k) / sd_turn, (ℓ_k - L_k) / sd_length]`` and weighted by its
    Laplace evidence ``exp(-cost) / sqrt(det JᵀJ)``, with a uniform prior on the
    start. Modes closer than ``min_separation`` mm are merged.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.special import chdtrc

from .._defaults import CONFIDENCE, FIT_ALPHA, LENGTH_TOL, MIN_SEPARATION, SD_LENGTH, SD_TURN, TURN_TOL
from .._errors import QueryError
from .._types import FloatArray
from ..geometry import Boundary, Outline, Part
from ..solve import DIRECTIONS, Segment, feasible_segments
from ._outline_chain import chain_likelihood, chain_paper

__all__ = ["Candidate", "Localization", "localize", "RULES"]

#: The smallest standard deviations :func:`localize` accepts: a contact travel to 0.1 µm, a rotation to
#: 1e-7 rad (0.02 arc-seconds); below them the likelihood's exponents overflow.
SD_LENGTH_MIN = 1e-4
SD_TURN_MIN = 1e-7
#: Disambiguation rules accepted by :func:`localize`.
RULES = ("likelihood", "paper")


@dataclass(frozen=True)
class Candidate:
    """One hypothesis of where the jaw rolled.

    Attributes
    ----------
    start_arc : float, mm
        Contact position before the first roll, in [0, perimeter).
    end_arc : float, mm
        Contact position after the last roll (the jaw's present contact).
    path : tuple of float, mm
        Contact positions at the start and after each roll, in [0, perimeter).
    lengths : tuple of float, mm
        Arc length of each roll under this hypothesis (the measured ones for
        the paper rule, the fitted ones for the likelihood rule).
    turn_residuals : tuple of float, rad
        Total curvature of each rolled segment minus the measured rotation.
    probability : float
        Posterior probability (likelihood rule), or 1/k for each of the k
        kept candidates (paper rule; 0 for the rejected ones).
    score : float
        Paper rule: summed |mismatch| of the following rolls (rad).
        Likelihood rule: -log evidence (smaller is better).
    start_param, end_param : float
        Spline parameters of ``start_arc`` and ``end_arc``.
    """

    start_arc: float
    end_arc: float
    path: tuple[float, ...]
    lengths: tuple[float, ...]
    turn_residuals: tuple[float, ...]
    probability: float
    score: float
    start_param: float
    end_param: float

    def as_dict(self) -> dict[str, Any]:
        """Plain-JSON form."""
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        d["path"], d["lengths"], d["turn_residuals"] = list(self.path), list(self.lengths), list(self.turn_residuals)
        return d


@dataclass(frozen=True)
class Localization:
    """Result of :func:`localize`.

    Attributes
    ----------
    candidates : tuple of Candidate
        Most probable first.
    segments : tuple of Segment
        The exact feasible segments of the first roll.
    rolls : tuple of (float, float)
        The measured chain, (mm, rad).
    rule : str
        Rule used.
    direction : {"ccw", "cw"}
        Direction the contact moved on the part.
    confidence : float
        Probability the best candidate needs for the result not to be ambiguous.
    fit_pvalue : float
        How probable a fit as poor as the best candidate's is under the noise model (the χ² test of
        its standardized residuals, n − 1 degrees of freedom for n rolls; 1 for one roll, which any
        feasible segment fits exactly; 0 when nothing fits).
    """

    candidates: tuple[Candidate, ...]
    segments: tuple[Segment, ...]
    rolls: tuple[tuple[float, float], ...]
    rule: str
    direction: str
    confidence: float
    fit_pvalue: float = 1.0

    @property
    def best(self) -> Candidate | None:
        """The most probable candidate, or None if nothing fits."""
        return self.candidates[0] if self.candidates else None

    @property
    def consistent(self) -> bool:
        """False when the readings fit no place on the part: no candidate, or the best one's fit fails
        the χ² test at :data:`localizer.FIT_ALPHA` (implausible readings: a stuck encoder, a wrong
        unit). Then no candidate's probability means anything."""
        return self.best is not None and self.fit_pvalue >= FIT_ALPHA

    @property
    def ambiguous(self) -> bool:
        """True when no candidate reaches ``confidence`` (e.g. a symmetric part), or the readings fit no
        place (:attr:`consistent`)."""
        return not self.consistent or self.best is None or self.best.probability < self.confidence


def _check_rolls(part: Boundary, rolls: Iterable[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    try:
        chain = [(float(L), float(w)) for L, w in rolls]
    except (TypeError, ValueError):
        raise QueryError(f"rolls must be a sequence of (length mm, turn rad) pairs, got {rolls!r}") from None
    if not chain:
        raise QueryError("rolls is empty: give at least one (length, turn) pair")
    total = 0.0
    for k, (L, w) in enumerate(chain):
        if not (np.isfinite(L) and np.isfinite(w)):
            raise QueryError(f"roll {k + 1}: length={L!r} mm and turn={w!r} rad must be finite")
        if not 0.0 < L < part.perimeter:
            raise QueryError(f"roll {k + 1}: length={L!r} mm must be in (0, perimeter={part.perimeter:.6g}) mm")
        total += L
    return tuple(chain)


def _chain_turns(
    part: Part, start: FloatArray | float, lengths: FloatArray, sign: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Positions and turns of consecutive segments from unrolled arc ``start``."""
    pos = start + sign * np.concatenate([[0.0], np.cumsum(lengths)])
    t = part.param_at_arc(pos)
    _, theta, kappa, _ = part.state(t)
    return pos, np.diff(theta), kappa, t


def _paper(
    part: Part,
    chain: tuple[tuple[float, float], ...],
    segs: list[Segment],
    sign: float,
    length_tol: float,
    turn_tol: float,
) -> list[Candidate]:
    rows = []
    lengths = np.array([L for L, _ in chain])
    omegas = np.array([w for _, w in chain])
    for seg in segs:
        pos, turns, kappa, t = _chain_turns(part, seg.start_arc, lengths, sign)
        res = turns - omegas
        # a following segment may be length_tol longer or shorter: its turn moves by κ(end)·δ
        slack = np.abs(kappa[1:]) * length_tol
        mismatch = np.maximum(np.abs(res[1:]) - slack[1:], 0.0)
        rows.append((float(mismatch.sum()), pos, res, t))
    if not rows:
        return []
    best = min(r[0] for r in rows)
    limit = best + turn_tol * max(len(chain) - 1, 1)
    kept = [r[0] <= limit for r in rows]
    k = sum(kept)
    out = []
    for (score, pos, res, t), keep in zip(rows, kept):
        out.append(
            Candidate(
                start_arc=float(part.wrap_arc(pos[0])),
                end_arc=float(part.wrap_arc(pos[-1])),
                path=tuple(float(x) for x in part.wrap_arc(pos)),
                lengths=tuple(float(x) for x in lengths),
                turn_residuals=tuple(float(x) for x in res),
                probability=(1.0 / k) if keep else 0.0,
                score=score,
                start_param=float(np.mod(t[0], part.n_knots)),
                end_param=float(np.mod(t[-1], part.n_knots)),
            )
        )
    return out


def _likelihood(
    part: Part,
    chain: tuple[tuple[float, float], ...],
    sign: float,
    direction: str,
    sd_length: float,
    sd_turn: float,
    min_separation: float,
) -> list[Candidate]:
    n = len(chain)
    L = np.array([c[0] for c in chain])
    W = np.array([c[1] for c in chain])
    # seeds: first-roll feasible starts for the measurement and for ±2 sd around it
    # (a rotation error moves a start by sd_turn/|g'|, a length error by about
    # sd_length·κ/|g'|: the turn-shifted queries bracket both)
    sd_eff = float(np.hypot(sd_turn, sd_length * part.curvature_bound))
    found: list[float] = []
    for dw in (-2.0, 0.0, 2.0):
        for seg in feasible_segments(part, L[0], W[0] + dw * min(sd_eff, 10 * sd_turn), direction=direction):
            found.append(seg.start_arc)
    if not found:
        return []
    seeds = np.sort(np.array(found))
    seeds = seeds[np.concatenate([[True], np.diff(seeds) > 0.1 * min_separation])]

    # the solver asks for the residuals and the Jacobian at the same x: one chain for both
    last_x: list[FloatArray] = []
    last_chain: list[tuple[FloatArray, FloatArray, FloatArray, FloatArray]] = []

    def chain_at(x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        if not last_x or not np.array_equal(last_x[0], x):
            last_x[:] = [np.array(x, dtype=float, copy=True)]
            last_chain[:] = [_chain_turns(part, x[0], x[1:], sign)]
        return last_chain[0]

    def resid(x: FloatArray) -> FloatArray:
        pos, turns, _, _ = chain_at(x)
        return np.concatenate([(turns - W) / sd_turn, (x[1:] - L) / sd_length])

    def jac(x: FloatArray) -> FloatArray:
        pos, turns, kappa, _ = chain_at(x)
        J = np.zeros((2 * n, n + 1))
        dk = kappa[1:] - kappa[:-1]
        J[:n, 0] = dk
        for k in range(n):
            J[k, 1 : k + 1] = sign * dk[k]
            J[k, k + 1] = sign * kappa[k + 1]
        J[:n] /= sd_turn
        J[n:, 1:] = np.eye(n) / sd_length
        return J

    from scipy.optimize import least_squares  # here: scipy.optimize is 0.3 s of every command's start

    fits = []
    for s0 in seeds:
        x0 = np.concatenate([[s0], L])
        r = least_squares(resid, x0, jac=jac, method="lm", xtol=1e-10, ftol=1e-10, max_nfev=100)
        J = jac(r.x)
        sign_det, logdet = np.linalg.slogdet(J.T @ J)
        if sign_det <= 0:
            logdet = np.inf
        neg_log_evidence = float(r.cost + 0.5 * logdet)
        fits.append((neg_log_evidence, r.x))
    fits.sort(key=lambda f: f[0])
    kept: list[tuple[float, FloatArray]] = []
    for f in fits:
        s = part.wrap_arc(f[1][0])
        if all(abs(part.arc_offset(s, k[1][0])) > min_separation for k in kept):
            kept.append(f)
    nle = np.array([k[0] for k in kept])
    w = np.exp(-(nle - nle.min()))
    w /= w.sum()
    out = []
    for (score, x), prob in zip(kept, w):
        pos, turns, _, t = _chain_turns(part, x[0], x[1:], sign)
        out.append(
            Candidate(
                start_arc=float(part.wrap_arc(pos[0])),
                end_arc=float(part.wrap_arc(pos[-1])),
                path=tuple(float(v) for v in part.wrap_arc(pos)),
                lengths=tuple(float(v) for v in x[1:]),
                turn_residuals=tuple(float(v) for v in turns - W),
                probability=float(prob),
                score=score,
                start_param=float(np.mod(t[0], part.n_knots)),
                end_param=float(np.mod(t[-1], part.n_knots)),
            )
        )
    out.sort(key=lambda c: -c.probability)
    return out


def _on_outline(
    outline: Outline,
    chain: tuple[tuple[float, float], ...],
    segs: list[Segment],
    rule: str,
    sign: float,
    sd_length: float,
    sd_turn: float,
    length_tol: float,
    turn_tol: float,
    min_separation: float,
) -> list[Candidate]:
    """The rules on an outline with corners (:mod:`localizer.chain._outline_chain`) as candidates."""
    P = outline.perimeter

    def candidate(pos: FloatArray, res: FloatArray, prob: float, score: float) -> Candidate:
        wrapped = np.mod(pos, P)
        return Candidate(
            start_arc=float(wrapped[0]),
            end_arc=float(wrapped[-1]),
            path=tuple(float(v) for v in wrapped),
            lengths=tuple(float(v) for v in np.abs(np.diff(pos))),
            turn_residuals=tuple(float(v) for v in res),
            probability=prob,
            score=score,
            start_param=float(wrapped[0]),
            end_param=float(wrapped[-1]),
        )

    if rule == "paper":
        rows = chain_paper(outline, chain, segs, sign, length_tol)
        if not rows:
            return []
        best = min(r[0] for r in rows)
        limit = best + turn_tol * max(len(chain) - 1, 1)
        rows.sort(key=lambda r: r[0])
        kept: list[tuple[float, FloatArray, FloatArray]] = []
        ends = np.empty(len(rows))
        for r in rows:
            if r[0] > limit:
                break
            end = r[1][-1] % P
            gap = np.abs((ends[: len(kept)] - end + 0.5 * P) % P - 0.5 * P)
            if not (gap <= min_separation).any():
                ends[len(kept)] = end
                kept.append(r)
        out = [candidate(pos, res, 1.0 / len(kept), score) for score, pos, res in kept]
        return out
    modes = chain_likelihood(outline, chain, sign, sd_length, sd_turn, min_separation)
    return [candidate(arcs, res, prob, -math.log(max(prob, 1e-300))) for prob, arcs, res in modes]


def localize(
    part: Part | Outline,
    rolls: Iterable[tuple[float, float]],
    *,
    rule: str = "likelihood",
    direction: str = "ccw",
    sd_length: float = SD_LENGTH,
    sd_turn: float = SD_TURN,
    length_tol: float = LENGTH_TOL,
    turn_tol: float = TURN_TOL,
    min_separation: float = MIN_SEPARATION,
    confidence: float = CONFIDENCE,
) -> Localization:
    """Localize the jaw from a chain of consecutive rolls.

    Parameters
    ----------
    part : Part or Outline
        On an outline with corners both rules weigh every start on a grid (see
        :mod:`localizer.chain._outline_chain`): corners and continua make a least-squares fit unsound.
    rolls : sequence of (float, float)
        Measured (contact travel L in mm, signed jaw rotation Ω in rad) of each roll.
    rule : {"likelihood", "paper"}
        See the module notes.
    direction : {"ccw", "cw"}
        Direction the contact moved on the part in every roll.
    sd_length : float, mm
        Standard deviation of a measured contact travel (likelihood rule).
    sd_turn : float, rad
        Standard deviation of a measured rotation (likelihood rule); the
        default is the Adept controller's ±0.03°.
    length_tol, turn_tol : float, mm and rad
        The paper rule's tolerances (paper: 0.004 and 0.0004).
    min_separation : float, mm
        Candidates closer than this are one (paper: 0.5).
    confidence : float
        Probability the best candidate needs for ``ambiguous`` to be False.

    Returns
    -------
    Localization

    Raises
    ------
    QueryError
        An empty or malformed chain, a length outside (0, perimeter), an
        unknown rule or direction, non-positive standard deviations.

    Examples
    --------
    >>> import numpy as np
    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    >>> r = 40 + 6 * np.cos(3 * a) + 2 * np.sin(2 * a)
    >>> part = part_from_points(np.c_[r * np.cos(a), r * np.sin(a)])
    >>> s0, lengths = 30.0, [20.0, 15.0]          # simulate two noise-free rolls
    >>> pos = s0 + np.cumsum([0.0] + lengths)
    >>> turns = np.diff(part.tangent_angle_at_arc(pos))
    >>> result = localize(part, list(zip(lengths, turns)), rule="paper")
    >>> round(result.best.start_arc, 6), round(result.best.end_arc, 6)
    (30.0, 65.0)
    """
    if rule not in RULES:
        raise QueryError(f"unknown rule {rule!r}; use one of {list(RULES)}")
    if direction not in DIRECTIONS:
        raise QueryError(f"unknown direction {direction!r}; use one of {list(DIRECTIONS)}")
    for name, val, floor in (("sd_length", sd_length, SD_LENGTH_MIN), ("sd_turn", sd_turn, SD_TURN_MIN)):
        if not (np.isfinite(val) and val >= floor):
            raise QueryError(
                f"{name}={val!r} is below {floor:g} ({'mm' if name == 'sd_length' else 'rad'}): no sensor is that "
                "precise, and the probabilities would overflow; give the reading's real standard deviation"
            )
    for name, val in (
        ("length_tol", length_tol),
        ("turn_tol", turn_tol),
        ("min_separation", min_separation),
    ):
        if not (np.isfinite(val) and val > 0):
            raise QueryError(f"{name}={val!r} must be a positive number")
    if not 0.0 < confidence <= 1.0:
        raise QueryError(f"confidence={confidence!r} must be in (0, 1]")
    chain = _check_rolls(part, rolls)
    sign = 1.0 if direction == "ccw" else -1.0
    segs = feasible_segments(part, chain[0][0], chain[0][1], direction=direction)
    if isinstance(part, Outline):
        cands = _on_outline(part, chain, segs, rule, sign, sd_length, sd_turn, length_tol, turn_tol, min_separation)
        lik = "likelihood"
        fits = (
            cands
            if rule == lik
            else _on_outline(part, chain, segs, lik, sign, sd_length, sd_turn, 0, 0, min_separation)
        )
    elif rule == "paper":
        cands = _paper(part, chain, segs, sign, length_tol, turn_tol)
        cands.sort(key=lambda c: (-c.probability, c.score))
        fits = _likelihood(part, chain, sign, direction, sd_length, sd_turn, min_separation)
    else:
        cands = _likelihood(part, chain, sign, direction, sd_length, sd_turn, min_separation)
        fits = cands
    return Localization(
        candidates=tuple(cands),
        segments=tuple(segs),
        rolls=chain,
        rule=rule,
        direction=direction,
        confidence=confidence,
        fit_pvalue=_fit_pvalue(chain, fits, sd_length, sd_turn),
    )


def _fit_pvalue(
    chain: tuple[tuple[float, float], ...], fits: list[Candidate], sd_length: float, sd_turn: float
) -> float:
    """The χ² test of the readings against the part, whichever rule disambiguates: the likelihood
    rule's best fit (``fits``), its turn residuals over ``sd_turn`` and its lengths' misfit over
    ``sd_length``, n − 1 degrees of freedom (n rolls: 2n readings; a start and n lengths fitted)."""
    if not fits:
        return 0.0
    n = len(chain)
    if n < 2:
        return 1.0
    best = min(fits, key=lambda c: c.score)
    res = np.asarray(best.turn_residuals, dtype=float)
    misfit = np.asarray(best.lengths, dtype=float) - np.array([L for L, _ in chain])
    stat = float(np.sum((res / sd_turn) ** 2) + np.sum((misfit / sd_length) ** 2))
    if not np.isfinite(stat):
        return 0.0
    return float(chdtrc(n - 1, stat))
