"""The straight jaw's grid filter, its evidence: the nuisances (offsets, scale, slope, the jaw's calibration,
drift, the noise's scale) weighed out in closed form over the live starts, and where the posterior's mass
lies on the part (docs/filter.md)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._errors import QueryError
from .._types import FloatArray, IntArray
from ._belief import Mode, find_modes, within
from ._contact_settings import (
    FACE_SLOPES,
    RHO_MAX,
)
from ._contact_state import ContactState, _Gathered
from ._filter_kernels import gather, weigh_scales
from ._sums import _quad, _Sums

__all__ = ["ContactMarginal"]


class ContactMarginal(ContactState):
    """The closed-form marginalisation over the live starts and what it says of the present contact."""

    def _solved(self, factor: float = 1.0) -> dict[str, Any]:
        """The marginalisation over the live hypotheses and their log-likelihoods, with the slope
        prior's standard deviations times ``factor``, once per reading (cached: the reference
        refresh, :meth:`~localizer.ContactFilter.belief` and :meth:`shift` share it)."""
        s = self._cached.get(factor)
        if s is None or s["version"] != self._version:
            s = self._solve(factor)
            s["version"] = self._version
            # the slope prior prunes alone only without an envelope; with one, a start far below the
            # best under one prior may carry the mass under another: the belief
            # (:meth:`~localizer.ContactFilter.belief`) prunes what is hopeless under all of them
            s["ll"] = self._log_likelihood(s, prune=factor == 1.0 and not self.slope_envelope)
            self._cached[factor] = s
        return s

    def _solve(self, factor: float = 1.0, without: _Sums | None = None, hyps: IntArray | None = None) -> dict[str, Any]:
        """The closed-form marginalisation over the live hypotheses (see the docs/filter.md), or over
        ``hyps``; with ``without``, once without each of its stretches of readings (summed over the same
        hypotheses), every array then with a leading axis over the stretches."""
        cols = np.flatnonzero(self._touched)
        s2 = self.sd_position**2
        prior = self._slope_var[cols] * factor**2  # the contact's offset ρ·η: (ρ·sd_slope)²
        prior[cols < self._segments] = 1e6  # the segments' offsets: flat
        prior[(cols >= self._jaw0) & (cols < self._jaw_end)] = self.sd_jaw**2
        prior[cols == self._drift] = self.sd_drift**2
        gathered = self._gathered(cols) if hyps is None else self._sums_over(cols, np.asarray(hyps, dtype=np.int64))
        live, uu, uz, szz, v, spp, szp = gathered
        if without is not None:
            uu, uz, szz = uu - without.uu, uz - without.uz, szz - without.szz
            v, spp, szp = v - without.up, spp - without.spp, szp - without.szp
        g = uu + np.diag(s2 / prior)
        # an inverse and products, not a solve: with ten thousand starts live a solve for each was most of
        # a belief. Inverted with its diagonal scaled to 1 (its flat offsets' small terms beside the slope
        # terms' large ones make g's condition 10⁸; scaled, 10⁴ on the benchmark's rolling)
        d = 1.0 / np.sqrt(np.diagonal(g, axis1=-2, axis2=-1))
        g_inv = d[..., :, None] * np.linalg.inv(d[..., :, None] * g * d[..., None, :]) * d[..., None, :]
        gi_v, gi_wz = g_inv @ v, np.einsum("...ij,...j->...i", g_inv, uz)
        # ≥ 0 in exact arithmetic (a squared norm after projection); rounding must not make it less
        qpp = np.maximum(spp - np.einsum("...ij,...ij->...j", v, gi_v), 0.0) / s2
        qpz = (szp - np.einsum("...i,...ij->...j", gi_wz, v)) / s2
        qzz = (szz - np.einsum("...i,...i->...", uz, gi_wz))[..., None] / s2  # one per stretch, as the others
        return {
            "cols": cols,
            "g_inv": g_inv,
            "live": live,
            "gi_v": gi_v,
            "gi_wz": gi_wz,
            "qpp": qpp,
            "qpz": qpz,
            "qzz": qzz,
            "k_less": np.zeros(()) if without is None else without.readings,
        }

    def _gathered(self, cols: IntArray) -> _Gathered:
        """The live starts and the sums over the touched columns ``cols`` and those starts: (live, UᵀU, Uᵀz,
        zᵀz, Uᵀp (m, n_live), pᵀp, zᵀp). Gathered once per state of the sums and of the live starts, which the
        slope prior's factors share: with a thousand starts live the gather was a third of a solve."""
        key = (self._version, self._live_idx)
        hit = self._gather
        if hit is not None and hit[0][0] == key[0] and hit[0][1] is key[1]:
            return hit[1]
        out = self._sums_over(cols, self._live_idx)
        self._gather = (key, out)
        return out

    def _sums_over(self, cols: IntArray, live: IntArray) -> _Gathered:
        """(live, UᵀU, Uᵀz, zᵀz, Uᵀp (m, n_live), pᵀp, zᵀp) over the columns ``cols`` and the starts ``live``."""
        uu, uz, szz = self._uu[np.ix_(cols, cols)], self._uz[cols], np.asarray(self._szz)
        return live, uu, uz, szz, gather(self._up, cols, live), self._spp[live], self._szp[live]

    def _log_likelihood(self, s: dict[str, Any], prune: bool = True) -> FloatArray:
        """Log-likelihood of each start from a :meth:`_solve` (over the grid, after its leading axis if any),
        the noise scale weighed out; prunes the hopeless ones (of a single solve). Also leaves in ``s`` each
        live start's posterior mean of the squared scale."""
        live, qpp = s["live"], s["qpp"]
        t2 = self.sd_scale**2
        quad = _quad(s, t2)
        # every standard deviation times λ: the quadratic form scales by 1/λ², the determinant by
        # λ^(2k) with k the readings not absorbed by a flat offset; t2·qpp does not change
        k = np.maximum(self._rows - len(self._out) - s["k_less"] - (self._segment + 1), 0).astype(float)
        log_mean, lam2 = weigh_scales(np.atleast_2d(quad), np.atleast_1d(k), np.asarray(self.noise_scales, dtype=float))
        s["lam2"] = lam2.reshape(quad.shape)
        ll_live = self.temper * (log_mean.reshape(quad.shape) - 0.5 * np.log1p(t2 * qpp)) + self._penalty[live]
        ll = np.full(qpp.shape[:-1] + self.grid.shape, -np.inf)
        ll[..., live] = ll_live
        if prune and self.prune > 0 and live.size and qpp.ndim == 1:
            # hypotheses this far below the best are dropped from later evaluations
            drop = live[ll_live < ll_live.max() - self.prune]
            if drop.size:
                self._live[drop] = False
                self._live_idx = np.flatnonzero(self._live)
        return ll

    def _prune_under_every_prior(self) -> None:
        """Drop the live starts more than ``prune`` nats below the best under the slope prior and under
        every factor of the envelope (each judged against its own best)."""
        if not self.prune > 0:
            return
        live = self._live_idx
        hopeless = np.ones(live.size, dtype=bool)
        for factor in (1.0, *self.slope_envelope):
            s = self._solved(factor)
            ll = s["ll"][live]
            hopeless &= ll < ll.max() - self.prune
        if hopeless.any():
            self._live[live[hopeless]] = False
            self._live_idx = np.flatnonzero(self._live)

    def noise_scale(self) -> float:
        """The factor λ on the noise settings that the readings say at the most probable start: the
        root of its posterior mean square (1 when the settings are right)."""
        s = self._solved()
        return float(math.sqrt(s["lam2"][int(np.argmax(s["ll"][s["live"]]))]))

    def log_likelihood(self) -> FloatArray:
        """Log-likelihood of each start (−inf where infeasible or pruned), up to a constant."""
        ll: FloatArray = self._solved()["ll"]
        return ll.copy()

    def shift(self) -> tuple[FloatArray, FloatArray]:
        """How far the real present contact is from each hypothesis' nominal one, mm.

        The slope error η moves the contact for a given jaw angle by ρ·η along the part
        (docs/filter.md), so the readings' term ρ̂·η(z) at the last reading is also the
        present contact's offset from where the model puts it. Given the start it is
        Gaussian; with sd_slope = 0 it is zero. The spread also holds the last rotation
        reading's error, which moves the present contact by ρ·e (``sd_turn``).

        Returns
        -------
        mean, sd : ndarray, mm
            Over the grid (0 where infeasible or pruned).
        """
        return self._shift(1.0)

    def present(self) -> FloatArray:
        """Each start's present contact, mm: the nominal one moved by its :meth:`shift`."""
        out: FloatArray = self.part.wrap_arc(self.current + self.shift()[0])
        return out

    def _shift(self, factor: float) -> tuple[FloatArray, FloatArray]:
        """:meth:`shift` with the slope prior's standard deviations times ``factor``."""
        return self._shift_of(self._solved(factor))

    def _shift_of(self, s: dict[str, Any]) -> tuple[FloatArray, FloatArray]:
        """:meth:`shift` from the marginalisation ``s`` (:meth:`_solve`, with its log-likelihood; with a
        leading axis as it has)."""
        shape = s["qpp"].shape[:-1] + self.grid.shape
        mean, sd = np.zeros(shape), np.zeros(shape)
        live = s["live"]
        # the last rotation reading's error moves the present contact by ρ·e
        kappa = self.tracks.kappa[self.tracks.node_at(self.current[live])]
        var_turn = (self.sd_turn / np.maximum(kappa, 1.0 / RHO_MAX)) ** 2
        if self.sd_slope <= 0:
            sd[..., live] = np.sqrt(var_turn)
            return mean, sd
        cols = s["cols"]
        a = np.zeros(cols.size)
        row_cols, row_vals = self._last_row
        a[np.searchsorted(cols, row_cols)] = row_vals
        a[cols < self._segments] = 0.0  # the offset is the reading's, not the contact's
        a[cols >= self._jaw0] = 0.0  # so are the calibration's error and the drift
        t2 = self.sd_scale**2
        qpr = s["qpz"] - s["qpp"]
        d_mean = t2 * qpr / (1 + t2 * s["qpp"])  # the scale's posterior, b = 1 + δ
        d_var = t2 / (1 + t2 * s["qpp"])
        a_v = np.einsum("i,...ij->...j", a, s["gi_v"])
        mean[..., live] = np.einsum("i,...i->...", a, s["gi_wz"])[..., None] - (1 + d_mean) * a_v
        # pivoting on a corner the real contact is the corner: machining moves it along the normal
        # only, so it keeps its arc, whatever the slope term says of the stretch before it
        mean[..., live[self.tracks.pivot[self.node[live]]]] = 0.0
        var0 = self.sd_position**2 * np.einsum("i,...i->...", a, np.einsum("...ij,j->...i", s["g_inv"], a))
        # the evidence is tempered (TEMPER): so is what it says of the slope term, whose spread
        # grows by 1/TEMPER in variance as the start's does
        sd[..., live] = np.sqrt(s["lam2"] * (var0[..., None] + d_var * a_v**2) / self.temper + var_turn)
        return mean, sd

    def posterior(self) -> FloatArray:
        """Posterior probability of each start (sums to 1).

        Computed once per reading (a check asks for it several times: the belief and the
        rolling procedure's look-ahead rules)."""
        return self._posterior(1.0)

    def _posterior(self, factor: float) -> FloatArray:
        """:meth:`posterior` with the slope prior's standard deviations times ``factor``."""
        s = self._solved(factor)
        if "w" not in s:
            ll = s["ll"]
            top = ll.max()
            if not np.isfinite(top):
                raise QueryError("no start on the part fits the readings (all hypotheses ruled out)")
            w = np.exp(ll - top)
            s["w"] = w / w.sum()
        posterior: FloatArray = s["w"]
        return posterior.copy()

    def _in_travel(self, travel: tuple[float, float]) -> list[int]:
        """The readings (indices, the first's aside: it only places the start) taken within ``travel``, rolled
        arc mm as :meth:`update` took it: a stretch the fit test found, whose readings the most probable start
        of the end places on the model. Not the readings taken out for it (``Misfit.rows``): those are the
        stretch whose absence lets some start fit best, which where the model's own tight bends misfit a
        little over many readings is not always the stretch that stopped fitting."""
        lo, hi = travel
        return [j for j in range(1, len(self._readings)) if lo <= self._readings[j].arc <= hi]

    def _where(self, rows: list[int], start: int) -> tuple[float, float]:
        """The stretch of the model (arc positions, mm, counter-clockwise from first to last) the contact
        covered over the readings ``rows`` if the rolling started at grid point ``start``."""
        present = []
        for j in rows:
            r = self._readings[j]
            pos = int(np.searchsorted(r.live, start))
            if pos < r.live.size and r.live[pos] == start:
                present.append(self.grid[start] + r.p[pos] / r.weight)
        if not present:
            return (math.nan, math.nan)
        first = present[0]
        rel = np.asarray(self.part.arc_offset(np.array(present), first))
        lo, hi = first + float(rel.min()), first + float(rel.max())
        return float(self.part.wrap_arc(lo)), float(self.part.wrap_arc(hi))

    def _mass_past_faces(self, w: FloatArray, present: FloatArray, sd: FloatArray, arc: float, radius: float) -> float:
        """:meth:`_mass_near`, but a start whose jaw is within :data:`FACE_SLOPES` machined slopes (``sd_slope``)
        of the angle of a face its contact has just left or is about to reach counts as anywhere between that
        face's far end and its contact: the real face, tilted by its machining, may still hold the jaw there.
        The jaw's angle is the start's present node's (on a pivot, within the corner's jump)."""
        part = self.part
        i = int(np.argmax(w))
        sel = np.flatnonzero(w > 1e-12 * w[i])
        p = present[sel]
        theta = np.asarray(self.tracks.theta[self.node[sel]], dtype=float)
        slack = FACE_SLOPES * max(self.sd_slope, 1e-4)
        lo, hi = p.copy(), p.copy()
        wide = np.zeros(p.size, dtype=bool)
        for start, length, angle in self._faces:
            turned = (theta - angle + np.pi) % (2.0 * np.pi) - np.pi
            past = np.asarray(part.arc_offset(p, start + length))  # > 0: beyond the face's end
            before = np.asarray(part.arc_offset(start, p))  # > 0: short of the face's start
            after = (past > 0) & (past < length) & (turned > 0) & (turned <= slack)
            ahead = (before > 0) & (before < length) & (turned < 0) & (turned >= -slack)
            lo = np.where(after, p - past - length, lo)
            hi = np.where(ahead, p + before + length, hi)
            wide |= after | ahead
        if not wide.any():
            return self._mass_near(w, present, sd, arc, radius)
        off_lo = np.asarray(part.arc_offset(lo, arc))
        off_hi = off_lo + (hi - lo)
        overlap = np.clip(np.minimum(off_hi, radius) - np.maximum(off_lo, -radius), 0.0, None)
        inside_wide = overlap / np.maximum(hi - lo, 1e-12)
        inside = self._inside(p, sd[sel], arc, radius)
        return float(np.sum(w[sel] * np.where(wide, inside_wide, inside)))

    def _mass_near(self, w: FloatArray, present: FloatArray, sd: FloatArray, arc: float, radius: float) -> float:
        """Probability that the present contact is within ``radius`` mm of ``arc``: each start's (weight
        ``w``) is N(``present``, ``sd``²) along the part."""
        i = int(np.argmax(w))
        sel = np.flatnonzero(w > 1e-12 * w[i])
        return float(np.sum(w[sel] * self._inside(present[sel], sd[sel], arc, radius)))

    def _inside(self, present: FloatArray, sd: FloatArray, arc: float, radius: float) -> FloatArray:
        """Probability that a contact N(``present``, ``sd``²) along the part is within ``radius`` mm of ``arc``."""
        return within(self.part, present, sd, arc, radius)

    def _modes(self, w: FloatArray, present: FloatArray, radius: float) -> list[Mode]:
        """Connected groups of probable present contacts, binned at ``radius``."""
        return find_modes(self.part, w, present, self.grid, radius)
