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

The first three depend on the readings' L only, the same for every start: their covariance is
factored once, a row per reading (a Cholesky factor grown by one row), and every start's residuals
are whitened against it, so the log-likelihood is exact for them at O(starts × readings) per
reading; the last term is added to each start's innovation variance. Readings closer than ``thin``
mm of arc to the last one used only move the present contact (their errors are not independent of
the last one's: the arm encoder's quantization is a function of the angle).

Where the wheel reaches (:class:`~localizer.WheelReach`) is the prior. A start from which the arc
rolled so far, either way, runs over a point the wheel cannot touch (it would have jumped there,
which the rolling procedure detects and undoes instead) is made :data:`~localizer.CONTRADICTION`
times less likely at each reading used: soft, as the straight jaw's reach is, so that a model error in
the reach does not rule out the truth.

Trust, as the straight jaw's filter (docs/filter.md, "Trust"): the readings' likelihood is raised to the
power :data:`~localizer.TEMPER`, and a stated probability is the least over ``noise_scales`` (the
covariance times each factor squared), so that readings noisier than the filter was told lower it
instead of making it confidently wrong. And a belief is only stated when some start fits at all: when
the best start's residuals are beyond the χ² test at :data:`~localizer.FIT_ALPHA` even under
:data:`WHEEL_FIT_SCALE` times the error model, nothing fits (a wheel jammed between two walls reads
exactly as rolling in a concave arc of its own radius, docs/wheel.md), and the belief's mass is 0,
``consistent`` False.

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
from scipy.linalg import solve_triangular
from scipy.special import chdtrc, fdtrc

from .._defaults import CONFIDENCE, FIT_ALPHA, SUCCESS_RADIUS
from .._errors import QueryError
from .._types import BoolArray, FloatArray
from ..contact import ShiftedGrid, WheelJaw, free_runs, jump_runs, pivot_turn, wheel_reach_for
from ..geometry import MAX_ARRAY_BYTES, Outline, Part, bytes_text, check_grid
from ._belief import Belief, belief_flags, find_modes, flat_top, mass_within, most_probable
from ._contact_settings import BRIDGE_MISS, CONTRADICTION, TEMPER
from ._stretches import DEFECT_WINDOW, FIT_MIN_READINGS, FIT_RATIO, FIT_STARTS, FIT_WIDTH, stretch_windows

__all__ = [
    "WheelFilter",
    "WHEEL_SD_TURN",
    "WHEEL_SD_SLOPE",
    "WHEEL_SLOPE_LENGTH",
    "WHEEL_NOISE_SCALES",
    "WHEEL_FIT_SCALE",
]

#: One reading's independent angle error (rad): the arm encoder's 0.03° step (0.009° rms) and the wrist's
#: residual direction after the servo (0.02°, docs/wheel.md), rounded up.
WHEEL_SD_TURN = math.radians(0.025)
#: The machined part's slope error (rad rms): the straight jaw's reactive studies' measured 0.8e-3 to 1.9e-3.
WHEEL_SD_SLOPE = 0.002
#: Its correlation length along the arc (mm): the machining's shortest wavelength, 20 mm, over 2π.
WHEEL_SLOPE_LENGTH = 20.0 / (2 * math.pi)
#: Noise scales under which a stated probability must hold (its least is stated).
WHEEL_NOISE_SCALES = (1.0, 2.0)
#: The error model's factor under which some start must fit the readings for any belief to be stated:
#: the noisiest level the filter is meant to be trusted at (four times the `paper` preset).
WHEEL_FIT_SCALE = 4.0
#: Readings used (one a millimetre) between two fit tests while the belief is not sure.
WHEEL_FIT_EVERY = 10


class WheelFilter:
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

    >>> from localizer import part_from_points
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

    def __init__(
        self,
        part: Part | Outline,
        wheel: WheelJaw,
        *,
        spacing: float = 0.02,
        sd_turn: float = WHEEL_SD_TURN,
        sd_slope: float = WHEEL_SD_SLOPE,
        slope_length: float = WHEEL_SLOPE_LENGTH,
        sd_length: float = 0.005,
        sd_scale: float = 2e-4,
        thin: float = 1.0,
        radius: float = SUCCESS_RADIUS,
        confidence: float = CONFIDENCE,
        mode_floor: float = 0.05,
        noise_scales: tuple[float, ...] = WHEEL_NOISE_SCALES,
    ) -> None:
        if not isinstance(part, (Part, Outline)):
            raise QueryError(f"the wheel's filter takes a Part or an Outline, not {type(part).__name__}")
        for name, v in (("spacing", spacing), ("slope_length", slope_length), ("thin", thin), ("radius", radius)):
            if not (math.isfinite(v) and v > 0):
                raise QueryError(f"{name}={v!r} mm must be a positive number")
        for name, v in (("sd_turn", sd_turn), ("sd_slope", sd_slope), ("sd_length", sd_length), ("sd_scale", sd_scale)):
            if not (math.isfinite(v) and v >= 0):
                raise QueryError(f"{name}={v!r} must be ≥ 0")
        if sd_turn <= 0:
            raise QueryError(f"sd_turn={sd_turn!r} rad must be positive (it keeps the covariance invertible)")
        if not noise_scales or not all(math.isfinite(f) and f >= 1 for f in noise_scales):
            raise QueryError(f"noise_scales={noise_scales!r}: give factors ≥ 1")
        self.part, self.wheel = part, wheel
        self.sd_turn, self.sd_slope, self.slope_length = float(sd_turn), float(sd_slope), float(slope_length)
        self.sd_length, self.sd_scale, self.thin = float(sd_length), float(sd_scale), float(thin)
        self.radius, self.confidence, self.mode_floor = float(radius), float(confidence), float(mode_floor)
        self.noise_scales = tuple(float(f) for f in noise_scales)
        P = float(part.perimeter)
        n = max(64, int(math.ceil(P / spacing)))
        check_grid(part, "wheel filter", spacing, n)
        self._angles = ShiftedGrid(part, n)
        self.h = self._angles.h
        self.grid: FloatArray = self._angles.grid
        self._theta0 = self._angles.theta
        reach = wheel_reach_for(part, wheel)
        touch = reach.touchable(self.grid)
        self.prior: FloatArray = np.asarray(touch, dtype=float)
        if not touch.any():
            raise QueryError(f"a {wheel} touches {part.name} nowhere")
        self._ahead, self._behind = free_runs(touch, self.h)
        self._ahead_jump, self._behind_jump = jump_runs(part, wheel, self.grid, self._ahead, self._behind)
        # each reading used keeps three numbers a start and a row of the Cholesky factor: 24·n·k + 8·k² bytes
        # for k readings stay within MAX_ARRAY_BYTES (a 1000 mm part: 443 readings, 443 mm rolled at thin=1)
        b = 24.0 * n
        self.max_readings = int((math.sqrt(b * b + 32.0 * MAX_ARRAY_BYTES) - b) / 16.0)
        self.reset()

    # ------------------------------------------------------------- readings
    def reset(self) -> None:
        """Forget every reading (a new roll from a new start)."""
        self.L_used: list[float] = []
        # the readings' arrays, grown by doubling up to max_readings: the first k rows (columns of _zbuf,
        # each start's whitened residuals, kept contiguous per reading) are those of the readings used
        self._cholbuf = np.zeros((0, 0))
        self._zbuf = np.zeros((self.grid.size, 0), order="F")
        self._zzbuf = np.zeros((0, self.grid.size))
        self._lvbuf = np.zeros((0, self.grid.size))
        self._quad = np.zeros(self.grid.size)
        self._logdet = np.zeros(self.grid.size)
        self._penalty = np.zeros(self.grid.size)
        self.current = 0.0
        self.span = (0.0, 0.0)
        self.steps = 0
        self._misfit: tuple[tuple[float, float], float] | None = None  # (stretch on the model, p-value)
        self._fit_at = 0  # readings used at the last fit test

    @property
    def _chol(self) -> FloatArray:
        k = len(self.L_used)
        out: FloatArray = self._cholbuf[:k, :k]
        return out

    @property
    def _z(self) -> FloatArray:
        out: FloatArray = self._zbuf[:, : len(self.L_used)]
        return out

    @property
    def _zz(self) -> FloatArray:
        """Each reading's squared whitened misfit under each start, shape (readings, starts)."""
        out: FloatArray = self._zzbuf[: len(self.L_used)]
        return out

    @property
    def _logvar(self) -> FloatArray:
        """Each reading's log variance under each start, shape (readings, starts)."""
        out: FloatArray = self._lvbuf[: len(self.L_used)]
        return out

    def _make_room(self) -> None:
        """Room for one more reading: the buffers doubled, up to :attr:`max_readings`; refused beyond."""
        k, n = len(self.L_used), self.grid.size
        if k < self._zzbuf.shape[0]:
            return
        if k >= self.max_readings:
            raise QueryError(
                f"the wheel's filter holds {k} readings of {n} starts on {self.part.name!r} "
                f"({bytes_text(24.0 * n * k + 8.0 * k * k)}): one more passes the {bytes_text(MAX_ARRAY_BYTES)} "
                f"limit. It keeps a reading every thin={self.thin:g} mm rolled: give a larger thin, or roll "
                "less from one start (WheelPolicy.max_arc)"
            )
        cap = min(max(64, 2 * k), self.max_readings)
        chol = np.zeros((cap, cap))
        chol[:k, :k] = self._chol
        z = np.zeros((n, cap), order="F")
        z[:, :k] = self._z
        zz, lv = np.zeros((cap, n)), np.zeros((cap, n))
        zz[:k], lv[:k] = self._zz, self._logvar
        self._cholbuf, self._zbuf, self._zzbuf, self._lvbuf = chol, z, zz, lv

    def _cov(self, a: FloatArray, b: FloatArray) -> FloatArray:
        """Covariance of the shared errors of residuals at arcs ``a`` and ``b`` (mm) rolled from the start."""
        a, b = np.asarray(a, dtype=float)[:, None], np.asarray(b, dtype=float)[None, :]
        ell2 = 2 * self.slope_length**2
        slope = self.sd_slope**2 * (
            np.exp(-((a - b) ** 2) / ell2) - np.exp(-(a**2) / ell2) - np.exp(-(b**2) / ell2) + 1.0
        )
        # the start's independent reading error: in every residual
        out: FloatArray = slope + self.sd_turn**2 * (1.0 + (a == b))
        return out

    def corner_window(self, length: float) -> float:
        """How near a convex corner (mm) a start's contact after rolling ``length`` mm may be for the wheel
        to be pivoting on it: three standard errors of L (the encoder's and the calibrated radius's) under
        the largest of :attr:`noise_scales` (the stated probability holds under it), and one grid step (the
        true start lies between two of the grid's)."""
        return self.h + 3.0 * max(self.noise_scales) * math.hypot(self.sd_length, float(length) * self.sd_scale)

    def predicted_turn(self, length: float, turn: float) -> FloatArray:
        """Each start's model turn (rad) after rolling ``length`` mm, the nearest to the reading ``turn`` (rad)
        the model allows: Θ(s + L) − Θ(s), or, within :meth:`corner_window` of a convex corner, any angle
        between the model's there and across the corner's jump (the wheel pivoting on it)."""
        return self._model_at(length, turn)[0]

    def _model_at(self, length: float, turn: float) -> tuple[FloatArray, FloatArray]:
        """:meth:`predicted_turn` and each start's curvature (1/mm) at its contact after ``length`` mm."""
        theta, kappa = self._angles.at(length)
        x, window = self.grid + float(length), self.corner_window(length)
        return pivot_turn(self.part, x, self._theta0, theta - self._theta0, float(turn), window), kappa

    def update(self, length: float, turn: float) -> None:
        """Add a reading: the arc rolled since the start, ``length`` mm (signed: negative rolling
        clockwise), and the hand's net turn since the start, ``turn`` rad."""
        L, om = float(length), float(turn)
        if not (math.isfinite(L) and math.isfinite(om)):
            raise QueryError(f"reading (length={length!r} mm, turn={turn!r} rad) must be finite")
        self.current = L
        self.span = (min(self.span[0], L), max(self.span[1], L))
        self.steps += 1
        last = self.L_used[-1] if self.L_used else 0.0
        if abs(L - last) < self.thin:
            return
        used = np.array(self.L_used)
        c_new = self._cov(used, np.array([L]))[:, 0] if used.size else np.zeros(0)
        c_nn = float(self._cov(np.array([L]), np.array([L]))[0, 0])
        ell = solve_triangular(self._chol, c_new, lower=True) if used.size else np.zeros(0)
        d2 = max(c_nn - float(ell @ ell), 1e-18)
        model, kappa = self._model_at(L, om)
        extra = kappa**2 * (self.sd_length**2 + (L * self.sd_scale) ** 2)
        rho = om - model
        var = d2 + extra
        z = (rho - self._z @ ell) / np.sqrt(var)
        self._make_room()
        k = used.size
        self._quad += z**2
        self._zzbuf[k] = z**2  # each start's misfit of this reading, for the fit test and the stretches
        self._lvbuf[k] = np.log(var)
        self._logdet += self._lvbuf[k]
        self._penalty += np.where(self._clear(), 0.0, math.log(CONTRADICTION))
        self._zbuf[:, k] = z * np.sqrt(var / d2)  # whitened by the shared part alone
        self._cholbuf[k, :k] = ell
        self._cholbuf[k, k] = math.sqrt(d2)
        self.L_used.append(L)

    def jumped(self, direction: int, margin: float = 1.0) -> BoolArray:
        """The wheel jumped (and was taken back) when rolling on from the present contact in
        ``direction`` (+1: counter-clockwise). The starts under which the wheel could still have rolled
        on for ``margin`` mm there are made :data:`~localizer.BRIDGE_MISS` times less likely (soft: a
        jump may be read where there was none); per start, whether it explains the jump (:meth:`explains_jump`)."""
        if direction not in (1, -1):
            raise QueryError(f"direction={direction!r}: give +1 (counter-clockwise) or -1")
        explained = self.explains_jump(direction, margin)
        self._penalty += np.where(explained, 0.0, math.log(BRIDGE_MISS))
        return explained

    def explains_jump(self, direction: int, margin: float = 1.0) -> BoolArray:
        """Per start, whether the wheel rolling on from its present contact ``direction`` (+1: counter-clockwise)
        meets within ``margin`` mm a place it cannot roll over (it would jump there)."""
        here = np.rint(self.part.wrap_arc(self.grid + self.current) / self.h).astype(np.intp) % self.grid.size
        out: BoolArray = (self._ahead_jump if direction > 0 else self._behind_jump)[here] <= margin
        return out

    # --------------------------------------------------------------- belief
    def _clear(self) -> BoolArray:
        """Starts from which the arc rolled so far, both ways, runs over touchable points only."""
        lo, hi = self.span
        tol = 2 * self.h
        ok: BoolArray = (self._ahead + tol >= hi) & (self._behind + tol >= -lo)
        return ok

    def _posterior(self, factor: float) -> FloatArray:
        ll = TEMPER * (-0.5 * self._quad / factor**2 - 0.5 * self._logdet) + self._penalty
        ll = np.where(self.prior > 0, ll, -np.inf)
        top = ll.max()
        if not np.isfinite(top):
            raise QueryError("no start on the part fits the readings (all hypotheses ruled out)")
        w = np.exp(ll - top)
        out: FloatArray = w / w.sum()
        return out

    def posterior(self) -> FloatArray:
        """Posterior probability of each start on :attr:`grid` (sums to 1)."""
        return self._posterior(self.noise_scales[0])

    def present(self) -> FloatArray:
        """Each start's present contact, mm."""
        out: FloatArray = self.part.wrap_arc(self.grid + self.current)
        return out

    def belief(self, radius: float | None = None) -> Belief:
        """The belief over the present contact; its mass the least over :attr:`noise_scales`.

        Parameters
        ----------
        radius : float, optional, mm
            The mass is taken within this of the estimate (default: the filter's).
        """
        radius = self.radius if radius is None else float(radius)
        present = self.present()
        w = self.posterior()
        i = flat_top(w)
        map_arc = float(present[i])
        mass = 1.0
        for f in self.noise_scales:
            wf = w if f == self.noise_scales[0] else self._posterior(f)
            mass = min(mass, mass_within(self.part, present, wf, map_arc, radius))
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
        near = np.abs(np.asarray(self.part.arc_offset(self.present(), arc))) <= radius
        allowed = self.prior > 0
        worst = 1.0
        for _, inside in stretch_windows(rolled, w):
            quad = self._quad - zz[inside].sum(axis=0)
            logdet = self._logdet - logvar[inside].sum(axis=0)
            for f in self.noise_scales:
                ll = TEMPER * (-0.5 * quad / f**2 - 0.5 * logdet) + self._penalty
                ll = np.where(allowed, ll, -np.inf)
                wts = np.exp(ll - ll.max())
                worst = min(worst, float(wts[near].sum() / wts.sum()))
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
        best = float(np.min(np.where(self.prior > 0, self._quad, np.inf)))
        return bool(chdtrc(k, best / scale**2) >= FIT_ALPHA)
