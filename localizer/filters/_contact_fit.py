"""The straight jaw's grid filter, its stretches of readings: whether the readings still fit the part, and
the mass the belief keeps without any one stretch (docs/filter.md, "A part that is not its model")."""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np
from scipy.special import fdtrc

from .._defaults import FIT_ALPHA
from .._types import ArrayLike, FloatArray, IntArray
from ._contact_marginal import ContactMarginal
from ._contact_settings import (
    RHO_MAX,
    STRETCH_BATCH,
)
from ._stretches import (
    FIT_MIN_READINGS,
    FIT_RATIO,
    JUMP_READING,
    Misfit,
    stretch_windows,
)
from ._sums import _quad, _Stack, _sums

__all__ = ["ContactFit"]


class ContactFit(ContactMarginal):
    """The fit test over stretches of readings and the mass without each stretch."""

    def _stack(self, rows: list[int], hyps: IntArray | None = None) -> _Stack:
        """The readings ``rows`` as rows of a matrix over the basis, their values and their predictions at
        the hypotheses live now (or ``hyps``, live): the sums of any stretch of them are then products
        (:func:`_sums`), each reading gathered once however many stretches hold it."""
        live = self._live_idx if hyps is None else np.asarray(hyps, dtype=np.int64)
        cols = np.flatnonzero(self._touched)
        a, z, p = np.zeros((len(rows), cols.size)), np.zeros(len(rows)), np.zeros((len(rows), live.size))
        where: dict[int, IntArray] = {}  # the live hypotheses' places in each set of hypotheses live then
        for n, j in enumerate(rows):
            r = self._readings[j]
            pos = where.get(id(r.live))
            if pos is None:
                pos = where[id(r.live)] = np.searchsorted(r.live, live)
            a[n, np.searchsorted(cols, r.cols)] = r.vals
            z[n] = r.z
            p[n] = r.p[pos]
        return _Stack(cols, a, z, p)

    def _windows(self, rows: list[int], width: float | None = None) -> list[tuple[float, IntArray]]:
        """The stretches of :attr:`defect_window` mm of rolled arc, overlapping by three quarters, over the
        readings ``rows``: (where each begins, mm, and the positions in ``rows`` of its readings), each
        set of readings once."""
        arcs = np.array([self._readings[j].arc for j in rows])
        return stretch_windows(arcs, self.defect_window if width is None else width)

    def _judged_windows(self, rows: list[int]) -> list[tuple[float, IntArray]]:
        """The stretches of the fit test's width over the readings ``rows`` that it can judge: three
        readings at least, and enough outside (:data:`FIT_MIN_READINGS`) to tell misfit from noise."""
        return [
            (a, inside)
            for a, inside in self._windows(rows, self._fit_width)
            if inside.size >= 3 and len(rows) - inside.size >= FIT_MIN_READINGS
        ]

    def _spread(self) -> bool:
        """Whether the trusted readings span more rolled arc than :attr:`defect_window`: else one stretch
        holds them all, and without it nothing is known."""
        if self.defect_window <= 0:
            return True
        if self._spread_at[0] != len(self._readings):
            rows = self._trusted()
            arcs = [self._readings[j].arc for j in rows] or [0.0]
            self._spread_at = (len(self._readings), max(arcs) - min(arcs) > self.defect_window)
        return self._spread_at[1]

    def _jumped(self, j: int) -> bool:
        """Whether reading ``j`` came after a jump of the contact (more than :data:`JUMP_READING` mm of arc
        since the reading before it, in the same segment)."""
        if j < 1:
            return False
        r, q = self._readings[j], self._readings[j - 1]
        # beyond the step the radius then makes of the turn: a plain stretch of 300 mm radius moves a
        # millimetre every 0.2°
        expected = r.radius * abs(r.turn - q.turn)
        return r.segment == q.segment and abs(r.arc - q.arc) - expected > JUMP_READING

    def _trusted(self) -> list[int]:
        """The readings the likelihood holds (not the first, which only places the start; not quarantined)."""
        return [j for j in range(1, len(self._readings)) if j not in self._out]

    def fit_test(self, starts: ArrayLike) -> Misfit | None:
        """Whether the readings still fit the part under each of the hypotheses ``starts`` (grid indices).

        For each start and each stretch of :attr:`defect_window` mm of rolled arc, the stretch's misfit
        per reading against the rest's (the quadratic forms of the marginalisation with and without it:
        every nuisance weighed out, the noise level left to the readings) is an F statistic; its
        p-value, Bonferroni-corrected over the stretches, below :data:`~localizer.FIT_ALPHA` means the
        stretch does not come from the part the model describes there. Noise of any level fits
        (the statistic is a ratio); a burr, a dent, debris or a spike-ridden stretch does not.

        Returns
        -------
        Misfit or None
            None when some start fits every stretch (or there are too few readings to tell); else the
            first start's worst stretch: where on the model (its path's arcs over the stretch), and
            how significant.
        """
        trusted = self._trusted()
        # a reading that came after a jump of the contact (a face crossed, a shallow dip bridged in one
        # step) carries the model's approximation of that jump, one reading's worth: judged by none
        jumped = [self._jumped(j) for j in trusted]
        jumps = [j for j, jump in zip(trusted, jumped, strict=True) if jump]
        rows = [j for j, jump in zip(trusted, jumped, strict=True) if not jump]
        hyps = np.asarray([int(h) for h in np.atleast_1d(starts) if self._live[int(h)]], dtype=np.int64)
        if len(rows) < FIT_MIN_READINGS or hyps.size == 0 or self.defect_window <= 0:
            return None
        t2 = self.sd_scale**2
        # the judged readings first, then the jumps': a stretch's positions in the stack are its own
        stack = self._stack(rows + jumps, hyps)
        at_jumps = np.arange(len(rows), len(rows) + len(jumps))
        q_all = _quad(self._solve(1.0, without=_sums(stack, [at_jumps]), hyps=hyps), t2)[0]
        k = len(rows)
        nuisance = len({self._readings[j].segment for j in rows})
        windows = self._judged_windows(rows)
        if not windows:
            return None
        # what each reading's misfit should be under each start: the row weights were set from one
        # reference start's radius of curvature when the reading came (the rotation reading's error moves
        # the contact by ρ·e), which for another start, or a reference chosen before the readings said
        # much, is not its own: the statistic compares misfit to expectation, stretch against rest
        expect = self._expected_misfit(rows, hyps, stack.p[: len(rows)])  # (len(rows), hyps)
        e_all = expect.sum(axis=0)
        best_p = np.ones(hyps.size)
        best_size = np.zeros(hyps.size)
        best_w: list[tuple[float, IntArray] | None] = [None] * hyps.size
        without = _sums(stack, [np.concatenate([inside, at_jumps]) for _, inside in windows])
        q_rests = np.maximum(_quad(self._solve(1.0, without=without, hyps=hyps), t2), 1e-12)
        for (a, inside), q_rest in zip(windows, q_rests):
            kw, kr = inside.size, k - inside.size - nuisance
            e_w = expect[inside].sum(axis=0)
            stretch = np.maximum(q_all - q_rest, 0.0) / e_w
            rest = q_rest / (e_all - e_w) * k / (k - nuisance)
            f_stat = stretch / rest
            # a misfit the part's: the stretch's readings at least FIT_RATIO times as far off as the rest,
            # and as the noise it was told (the model's own approximations leave a stretch up to about five
            # times off on clean parts; noise-free readings show them alone)
            pv = np.where(stretch >= FIT_RATIO * np.maximum(rest, 1.0), fdtrc(kw, kr, f_stat), 1.0)
            better = pv < best_p
            best_p = np.where(better, pv, best_p)
            best_size = np.where(better, stretch, best_size)
            for i in np.flatnonzero(better):
                best_w[i] = (a, inside)
        level = FIT_ALPHA / len(windows)
        if not np.all(best_p < level):
            return None
        a, inside = best_w[0]  # type: ignore[misc]
        chosen = [rows[i] for i in inside]
        return Misfit(
            arcs=self._where(chosen, int(hyps[0])),
            travel=(float(a), float(a + self._fit_width)),
            p_value=float(best_p[0]),
            start=float(self.grid[int(hyps[0])]),
            rows=tuple(chosen),
            rms_mm=float(self.sd_position * math.sqrt(best_size[0])),
        )

    def _best_stretch(self) -> tuple[int, ...]:
        """The stretch (readings) whose absence most improves the best start's likelihood beyond what taking
        out as many readings that fit would (half a unit of the quadratic form each, tempered)."""
        rows = self._trusted()
        best = -math.inf
        s = self._solved(1.0)
        top = float(np.max(s["ll"][s["live"]])) if s["live"].size else -math.inf
        lam2 = float(np.median(s["lam2"])) if s["live"].size else 1.0
        out: tuple[int, ...] = ()
        windows = [inside for _, inside in self._judged_windows(rows)]
        for first, sw in self._without_each(self._stack(rows), windows):
            for inside, ll in zip(windows[first:], sw["ll"]):
                excess = float(np.max(ll)) - top - self.temper * 0.5 * inside.size * lam2
                if excess > best:
                    best, out = excess, tuple(rows[i] for i in inside)
        return out

    def _expected_misfit(self, rows: list[int], hyps: IntArray, p: FloatArray) -> FloatArray:
        """Each reading's expected weighted misfit (in units of the told reading variance) under each start
        ``hyps``: the reading's own error and the rotation reading's, ρ·sd_turn with ρ the start's radius
        of curvature at its contact then, times the weight the reading was given. ``p``: the readings'
        weighted predictions at ``hyps`` (:meth:`_stack`'s)."""
        weight = np.array([self._readings[j].weight for j in rows], dtype=float).reshape(len(rows))
        here = p / weight[:, None]
        kappa = self.tracks.kappa[self.tracks.node_at(self.grid[hyps][None, :] + here)]
        rho = np.where(kappa > 0, 1.0 / np.maximum(kappa, 1.0 / RHO_MAX), RHO_MAX)
        out: FloatArray = weight[:, None] ** 2 * (1.0 + (rho * self.sd_turn / self.sd_position) ** 2)
        return out

    def stretch_mass(self, arc: float, radius: float | None = None) -> tuple[float, tuple[float, float]]:
        """The least probability within ``radius`` of the present contact at ``arc`` (mm) when any one
        stretch of the readings, ``defect_window`` mm of the rolled arc, is left out, and that stretch
        (cumulative arc, mm, as :meth:`~localizer.ContactFilter.update` took it).

        A burr, a dent or a speck of debris where the jaw rolls makes the readings over it follow a
        shape the model does not have, and a crest's tight bend reads like a fillet of the model: the
        readings of a short stretch alone can look like another place of the part. The belief is sure
        only where it stays sure without any one such stretch (docs/filter.md, "A part that is not its
        model"). Each stretch is taken out exactly (the marginalisation without its sums); the windows
        overlap by three quarters, so a stretch up to three quarters of a window lies inside one. Readings
        that span no more than a window are one stretch: without it nothing is known (the least is then
        0). Every live start is weighed; the stretches are tried
        fullest first, and the search stops at the first that leaves less than the confidence (the
        mass returned is then that one's: the belief is not sure, which is what the least decides).
        """
        radius = self.radius if radius is None else float(radius)
        rows = self._trusted()
        if not rows or self.defect_window <= 0:
            return 1.0, (math.nan, math.nan)
        if not self._spread():
            return 0.0, (
                float(min(self._readings[j].arc for j in rows)),
                float(max(self._readings[j].arc for j in rows)),
            )
        hyps = self._live_idx
        stack = self._stack(rows, hyps)
        worst, where = 1.0, (math.nan, math.nan)
        windows = sorted(self._windows(rows), key=lambda w: -w[1].size)
        for first, s in self._without_each(stack, [inside for _, inside in windows], hyps):
            mean, sd = self._shift_of(s)
            for n, ll in enumerate(s["ll"][:, hyps]):
                wts = np.exp(ll - ll.max())
                wts /= wts.sum()
                present = self.part.wrap_arc(self.current[hyps] + mean[n, hyps])
                mass = self._mass_near(wts, present, sd[n, hyps], arc, radius)
                if mass < worst:
                    a = windows[first + n][0]
                    worst, where = mass, (a, a + self.defect_window)
                if worst < self.confidence:
                    return worst, where
        return worst, where

    def _without_each(
        self, stack: _Stack, stretches: list[IntArray], hyps: IntArray | None = None
    ) -> Iterator[tuple[int, dict[str, Any]]]:
        """The marginalisation (:meth:`_solve`, with its log-likelihood) without each stretch of readings
        (positions in ``stack``), a few stretches at a time: (the first one's index, their solve). The
        first batches are small (1, 2, 4, ...): a caller that stops at the first stretch that decides
        pays for few more."""
        first, size = 0, 1
        while first < len(stretches):
            s = self._solve(1.0, without=_sums(stack, stretches[first : first + size]), hyps=hyps)
            s["ll"] = self._log_likelihood(s, prune=False)
            yield first, s
            first, size = first + size, min(2 * size, STRETCH_BATCH)
