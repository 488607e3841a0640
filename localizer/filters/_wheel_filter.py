"""The sequential filter of a wheel finger: a belief over the roll's start, the rolled arc as the coordinate.

The straight jaw's :class:`~localizer.ContactFilter` moves its hypotheses by the measured turn, along
stretches where the tangent angle rises, so that each turn names one place. A wheel also rolls
through concave stretches, where θ falls and a turn names several places (docs/wheel.md). Here the
rolling coordinate is the arc L the axle encoder reads (the wheel's L = r·Δψ_e), and the reading is
the hand's net turn Ω. For a start s the model's turn after L is

    Ω̂(s, L) = Θ(s + L) − Θ(s),          Θ the unwrapped tangent angle,

and the residuals ρ_k = Ω_k − Ω̂(s, L_k) of the readings of one roll share their errors:

- the start's angle error (the arm's, the wrist's direction and the machined part's slope at s), one
  offset for the roll;
- the machined part's slope error along the roll, a smooth random function of the arc: Gaussian
  covariance ``sd_slope``² · exp(−ΔL²/2ℓ²) with ℓ = ``slope_length``;
- independent errors of each reading: the arm's angle and the wrist's direction (``sd_turn``), and L's
  error seen through the tangent's turning, κ(s + L)·σ_L with σ_L² = ``sd_length``² + (L·``sd_scale``)²
  (the encoder and the calibrated radius's relative error).

and one error common to the roll that depends on the start: the part's **scale** against its model (a
part made 2% large, its drawing an older revision's). The wheel rolls the real arc, so after L the
contact under a start s is at s + L·(1 + u), u = 1/b − 1 for a part b times its model's size, and the
model's turn Θ(s + L(1 + u)) − Θ(s) ≈ Ω̂(s, L) + g·u, g the turn's slope across the prior's ±1σ of u
(κ(s + L)·L where the curvature is even over it; a secant, so that a face's end at an arc's start within
it is read as such); on a drawing a pivot on a convex corner (the turn inside its jump) places the
contact on it, s + L(1 + u) = c. The prior is a spike and a slab: the part is its model's size (u = 0)
but with probability ``off_scale`` (default :data:`~localizer.OFF_SCALE`; 0: the scale is not carried),
then u ~ N(0, ``sd_part_scale``²). Given a start both are weighed out in closed form
(the residuals are linear in u), and the start's present contact is s + L at the model's size,
N(s + L(1 + û), (L·σ_u)²) off it (:class:`~localizer.Spread`). Only curvature and corners tell a scale: on a face,
a near-circular stretch or a short roll the prior decides, and the stated probability, the least also
under a part as likely off its size as not (``off_scale_doubt``), is not sure there (docs/robustness.md,
"The wheel on a part off its model's size").

The first three depend on the readings' L only, the same for every start: their covariance is
factored once, a row per reading (a Cholesky factor grown by one row), and every start's residuals
are whitened against it, so the log-likelihood is exact for them at O(starts × readings) per
reading; the last term is added to each start's innovation variance. Readings closer than ``thin``
mm of arc to the last one used only move the present contact (their errors are not independent of the
last one's: the arm encoder's quantization is a function of the angle), but with the scale carried on a
drawing, a pivot's first reading beyond a reading's error is used: its place is a reading of the scale.

Where the wheel reaches (:class:`~localizer.WheelReach`) is the prior. A start from which the arc
rolled so far, either way, runs over a point the wheel cannot touch (it would have jumped there,
which the rolling procedure detects and undoes instead) is made :data:`~localizer.CONTRADICTION`
times less likely at each reading used: soft, as the straight jaw's reach is, so that a model error in
the reach does not rule out the truth. Off its model's size the roll is L(1 + u) of the model, clear of such
points for u up to a bound per start: a part a little large explains a roll a little past a free run, with
the probability its scale's posterior gives u below the bound (:func:`~localizer.filters._wheel_scale.weigh_scale`).

Trust, as the straight jaw's filter (docs/filter.md, "Trust"): the readings' likelihood is raised to the
power :data:`~localizer.TEMPER`, and a stated probability is the least over ``noise_scales`` (the
covariance times each factor squared), so that readings noisier than the filter was told lower it
instead of making it confidently wrong; with the scale carried, the least also over the prior
probabilities ``off_scale`` and ``off_scale_doubt`` that the part is off its size, so that where the
readings cannot tell the size, the prior's odds do not make the belief sure. And a belief is only stated
when some start fits at all: when the best start's residuals are beyond the χ² test at
:data:`~localizer.FIT_ALPHA` even under :data:`WHEEL_FIT_SCALE` times the error model, nothing fits (a
wheel jammed between two walls reads exactly as rolling in a concave arc of its own radius,
docs/wheel.md), and the belief's mass is 0, ``consistent`` False.

On a drawing (:class:`~localizer.Outline`) the wheel pivots on each convex corner it reaches: its
centre circles the corner, the hand turns through the corner's jump and the rim does not roll, so Ω
runs through the jump while L stands still (docs/wheel.md). Θ is then the drawing's unwrapped angle,
which steps at the corner, and a reading whose contact under a start lies within
:meth:`WheelFilter.corner_window` of a convex corner is compared with the nearest angle the model takes
there, the whole jump included: any turn within the jump fits a wheel on that corner. A disc cannot
reach into a concave corner: it touches both faces r·tan(|jump|/2) before it and would jump across,
which the rolling detects as a jump (beyond a degree or two) and undoes; a jump's evidence
(:meth:`WheelFilter.jumped`) takes a concave corner for the end of where the wheel could have rolled on,
however shallow (the reach's clearance would not). A start on a corner is taken on the face after it
(the angle after the jump): a wheel pressed onto a vertex, the hand anywhere within its jump, is not
modelled (pressing along a face's normal near a corner lands on the face).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import chdtrc, fdtrc

from .._defaults import FIT_ALPHA
from ._belief import Belief, belief_flags, find_modes, flat_top, most_probable
from ._contact_settings import TEMPER
from ._stretches import DEFECT_WINDOW, FIT_MIN_READINGS, FIT_RATIO, FIT_STARTS, FIT_WIDTH, stretch_windows
from ._wheel_scale import PartScale
from ._wheel_state import WHEEL_NOISE_SCALES, WHEEL_SD_SLOPE, WHEEL_SD_TURN, WHEEL_SLOPE_LENGTH, WheelState

__all__ = [
    "WheelFilter",
    "WHEEL_SD_TURN",
    "WHEEL_SD_SLOPE",
    "WHEEL_SLOPE_LENGTH",
    "WHEEL_NOISE_SCALES",
    "WHEEL_FIT_SCALE",
]

#: The error model's factor under which some start must fit the readings for any belief to be stated:
#: the noisiest level the filter is meant to be trusted at (four times the `paper` preset).
WHEEL_FIT_SCALE = 4.0
#: Readings used (one a millimetre) between two fit tests while the belief is not sure.
WHEEL_FIT_EVERY = 10


class WheelFilter(WheelState):
    """Belief over where a wheel's roll started, from cumulative (L, Ω) readings.

    Parameters
    ----------
    part : Part or Outline
    wheel : WheelJaw
    spacing : float, mm
        Grid of starts.
    sd_turn, sd_slope, slope_length : float
        The error model (module notes; rad, rad, mm).
    sd_length : float, mm
        One reading's error of L (the axle encoder's step times the radius, over √12, rounded up).
    sd_scale : float
        Relative error of L (the calibrated radius).
    sd_part_scale : float
        Prior standard deviation of the part's scale against its model, common to the roll, when the part
        is off its model's size (module notes).
    off_scale : float
        Prior probability that the part is off its model's size (default :data:`~localizer.OFF_SCALE`; 0:
        the part is its model's size, the scale not carried).
    off_scale_doubt : float
        With the scale carried, the stated mass is the least also under this prior probability that the part
        is off its size (:data:`~localizer.OFF_SCALE_DOUBT`; not below ``off_scale``).
    thin : float, mm
        Arc between two readings the likelihood uses.
    radius : float, mm
        A belief's mass is taken within this of its estimate (:func:`~localizer.filters._belief.flat_top`).
    confidence, mode_floor : float
        A belief is ambiguous when two or more modes hold ``mode_floor`` each and the first does not
        reach ``confidence``.
    noise_scales : tuple of float
        The stated mass is the least under these factors of the error model.

    Examples
    --------
    On an ellipse of semi-axes 40 and 25 mm, a noise-free roll of 10 mm from s = 20 mm:

    >>> from localizer import WheelJaw, part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    >>> ellipse = part_from_points(np.c_[40 * np.cos(a), 25 * np.sin(a)])
    >>> f = WheelFilter(ellipse, WheelJaw(5.0))
    >>> theta = lambda s: float(ellipse.tangent_angle(ellipse.param_at_arc(s)))
    >>> for L in np.arange(0.5, 10.01, 0.5):
    ...     f.update(L, theta(20.0 + L) - theta(20.0))
    >>> b = f.belief()
    >>> round(abs(float(ellipse.arc_offset(b.map_arc, 30.0))), 1), b.ambiguous
    (0.0, True)
    """

    def belief(self, radius: float | None = None) -> Belief:
        """The belief over the present contact; its mass the least over :attr:`noise_scales`.

        Parameters
        ----------
        radius : float, optional, mm
            The mass is taken within this of the estimate (default: the filter's).
        """
        radius = self.radius if radius is None else float(radius)
        w, spread = self._weighed(self.noise_scales[0])
        present = self.part.wrap_arc(spread.mean)
        i = flat_top(w)
        map_arc = float(present[i])
        mass = 1.0
        for f in self.noise_scales:
            for odds in self.off_scales:
                first = f == self.noise_scales[0] and odds == self.off_scale
                wf, sf = (w, spread) if first else self._weighed(f, odds)
                mass = min(mass, sf.mass(self.part, wf, map_arc, radius))
        consistent = self.consistent()
        if not consistent:
            mass = 0.0
        # do the readings still fit? Before a sure stop, and every FIT_EVERY readings used: a stretch of
        # the rolled arc that no probable start explains is a part that is not its model (a burr the wheel
        # rode over, a dent it dipped into): said where, and never sure
        used = len(self.L_used)
        if (
            consistent
            and self._misfit is None
            and used > self._fit_at
            and (mass >= self.confidence or used >= self._fit_at + WHEEL_FIT_EVERY)
        ):
            self._fit_at = used
            top = [int(h) for h in most_probable(w, FIT_STARTS) if w[h] > 0]
            self._misfit = self.fit_test(top)
        mismatch = self._misfit[0] if self._misfit is not None else None
        # sure only if sure without any one short stretch of the rolled arc (the straight jaw's rule,
        # ContactFilter.stretch_mass): a burr the wheel rode over reads like a bend the model has elsewhere
        if mass >= self.confidence:
            mass = min(mass, self.stretch_mass(map_arc, radius))
        modes = find_modes(self.part, w, present, self.grid, radius)
        prior = self.prior / self.prior.sum()
        informative, ambiguous = belief_flags(w, prior, modes, self.mode_floor, self.confidence)
        return Belief(
            map_arc=map_arc,
            mass=mass,
            radius=radius,
            modes=tuple(modes),
            ambiguous=ambiguous,
            informative=informative,
            steps=self.steps,
            consistent=consistent,
            mismatch=mismatch,
        )

    def part_scale(self) -> PartScale:
        """What the readings used say of the part's size, over the starts (:class:`PartScale`): the posterior
        probability that it is off its model's size, and its size then over its model's, b = 1/(1 + u) (mean
        and standard deviation to first order in u's). Without the scale carried: (0, 1, 0)."""
        if self._terms == 1 or not self.L_used:
            return PartScale(0.0, 1.0, 0.0)
        f = self.noise_scales[0]
        mean, sd, _ = self._scale_evidence(f, None, None, TEMPER)
        posterior, spread = self._weighed(f)
        w = posterior * spread.p_off
        probability = float(w.sum())
        if not probability > 0:
            return PartScale(0.0, 1.0, 0.0)
        u = float(np.dot(w, mean)) / probability
        var = max(float(np.dot(w, sd**2 + mean**2)) / probability - u * u, 0.0)
        return PartScale(probability, 1.0 / (1.0 + u), math.sqrt(var) / (1.0 + u) ** 2)

    def stretch_mass(self, arc: float, radius: float | None = None) -> float:
        """The least probability within ``radius`` of the present contact at ``arc`` (mm) when the readings
        of any one stretch of :data:`~localizer.DEFECT_WINDOW` mm of rolled arc are left out (their
        whitened misfits and variances taken off each start's sums: exact for the stretch's own terms, the
        readings after it still judged given it). Readings that span no more than one stretch are not
        enough to be sure: 0."""
        radius = self.radius if radius is None else float(radius)
        k = len(self.L_used)
        if k == 0:
            return 1.0
        rolled = np.array(self.L_used)
        w = DEFECT_WINDOW
        if float(np.ptp(rolled)) <= w:
            return 0.0
        zz, logvar = self._zz, self._logvar
        allowed = self.prior > 0
        worst = 1.0
        for _, inside in stretch_windows(rolled, w):
            quad = self._quad - zz[inside].sum(axis=0)
            logdet = self._logdet - logvar[inside].sum(axis=0)
            zg = gg = None
            if self._terms > 1:
                zg = self._zg - self._zg_each[inside].sum(axis=0)
                gg = self._gg - self._gg_each[inside].sum(axis=0)
            for f in self.noise_scales:
                base = np.where(allowed, TEMPER * (-0.5 * quad / f**2 - 0.5 * logdet) + self._penalty, -np.inf)
                scale = self._scale_evidence(f, zg, gg, TEMPER) if self._terms > 1 else None
                for odds in self.off_scales:
                    wts, spread = self._mixed(base, scale, odds)
                    worst = min(worst, spread.mass(self.part, wts, arc, radius))
            if worst < self.confidence:
                break
        return worst

    def fit_test(self, starts: list[int]) -> tuple[tuple[float, float], float] | None:
        """Whether the readings used still fit the part under each of the ``starts`` (grid indices): for each
        stretch of twice :data:`~localizer.DEFECT_WINDOW` mm of rolled arc, its readings' whitened misfit per
        reading against the rest's (an F ratio, as the straight jaw's :meth:`ContactFilter.fit_test`: at
        least FIT_RATIO times the rest and the most noise the stated probability allows (the
        largest of ``noise_scales``), Bonferroni-corrected at FIT_ALPHA). None when
        some start fits every stretch; else the stretch on the model under the first start, and its
        p-value."""
        k = len(self.L_used)
        if k < FIT_MIN_READINGS or not starts:
            return None
        zz = self._zz[:, starts]  # (readings, starts)
        if self._terms > 1:  # each start's residuals with its scale fitted (the readings' own likelihood)
            mean, p_off = self._scale_posterior(temper=1.0)
            u = (p_off * mean)[starts]
            zz = np.maximum(zz - 2.0 * u * self._zg_each[:, starts] + u**2 * self._gg_each[:, starts], 0.0)
        rolled = np.array(self.L_used)
        w = DEFECT_WINDOW * FIT_WIDTH
        windows = []
        for a in np.arange(float(rolled.min()) - 0.75 * w, float(rolled.max()) + 1e-9, 0.25 * w):
            inside = (rolled >= a) & (rolled <= a + w)
            if 3 <= inside.sum() <= k - FIT_MIN_READINGS:
                windows.append((float(a), inside))
        if not windows:
            return None
        best = np.ones(len(starts))
        where: list[float] = [math.nan] * len(starts)
        for a, inside in windows:
            kw = int(inside.sum())
            stretch = zz[inside].mean(axis=0)
            rest = np.maximum(zz[~inside].mean(axis=0), 1e-12)
            # the floor is the most noise the stated probability already allows (the largest noise scale):
            # a noise-free pymunk wheel reads 3-5 sigma off the told model over a few readings on a plain
            # convex stretch, which the stated mass takes in and no part's defect needs to be told from
            floor = max(self.noise_scales) ** 2
            pv = np.where(stretch >= FIT_RATIO * np.maximum(rest, floor), fdtrc(kw, k - kw, stretch / rest), 1.0)
            better = pv < best
            best = np.where(better, pv, best)
            for i in np.flatnonzero(better):
                where[i] = a
        if not np.all(best < FIT_ALPHA / len(windows)):
            return None
        s0 = float(self.grid[starts[0]])
        lo = s0 + max(where[0], float(rolled.min()))
        hi = s0 + min(where[0] + w, float(rolled.max()))
        return (float(self.part.wrap_arc(lo)), float(self.part.wrap_arc(hi))), float(best[0])

    def consistent(self, scale: float = WHEEL_FIT_SCALE) -> bool:
        """Whether some start the wheel can touch fits the readings used, under ``scale`` times the error model
        (χ² test at :data:`~localizer.FIT_ALPHA`; by default :data:`WHEEL_FIT_SCALE`, the noisiest level the
        filter is meant to be trusted at)."""
        k = len(self.L_used)
        if k == 0:
            return True
        quad = self._quad / scale**2
        if self._terms > 1:
            # or off its size, by the deviance of the scale weighed out (−2 log of its factor on the likelihood):
            # the misfit with the scale fitted and its prior's u²/σ² at its own size (not widened as the readings'
            # errors are), the prior's width against what the readings tell of u, and the prior's odds against a
            # part off its size where they are against it; under the error model times ``scale`` but at most
            # the noisiest the stated probability allows (the largest of ``noise_scales``): a wheel wedged on the
            # bracket's notch wall reads as rolling a concave arc, which a scale 2.7σ off explains at four times
            # the noise over the four readings before it turns round (18.5 against 31 at the model's size) and
            # not at twice
            f = min(scale, max(self.noise_scales))
            u = self._scale_evidence(f, None, None, 1.0)[0]
            fit = (self._quad - self._zg * u) / f**2
            occam = np.log1p(self._gg * self.sd_part_scale**2 / f**2)
            off = fit + occam + 2.0 * max(0.0, math.log((1.0 - self.off_scale) / self.off_scale))
            quad = np.minimum(quad, off)
        best = float(np.min(np.where(self.prior > 0, quad, np.inf)))
        return bool(chdtrc(k, best) >= FIT_ALPHA)
