"""The wheel's filter, its state: the readings used, each start's whitened residuals (and their derivatives
in the part's scale), and what they say of each start, the part's scale and the present contact. The
model is written down in :mod:`localizer.filters._wheel_filter`; the belief and the fit tests are there.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import solve_triangular
from scipy.special import expit

from .._defaults import CONFIDENCE, PART_SCALE_SD, SUCCESS_RADIUS
from .._errors import QueryError
from .._types import BoolArray, FloatArray
from ..contact import ShiftedGrid, WheelJaw, free_runs, jump_runs, wheel_reach_for
from ..geometry import MAX_ARRAY_BYTES, Outline, Part, bytes_text, check_grid
from ._contact_settings import BRIDGE_MISS, CONTRADICTION, TEMPER
from ._wheel_model import WheelModel
from ._wheel_scale import OFF_SCALE, OFF_SCALE_DOUBT, Spread, relative_weights, weigh_scale

__all__ = [
    "WheelState",
    "WHEEL_SD_TURN",
    "WHEEL_SD_SLOPE",
    "WHEEL_SLOPE_LENGTH",
    "WHEEL_NOISE_SCALES",
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


class WheelState(WheelModel):
    """The readings a :class:`~localizer.WheelFilter` used and each start's sums (its parameters are the
    filter's)."""

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
        sd_part_scale: float = PART_SCALE_SD,
        off_scale: float = OFF_SCALE,
        off_scale_doubt: float = OFF_SCALE_DOUBT,
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
        for name, v in (
            ("sd_turn", sd_turn),
            ("sd_slope", sd_slope),
            ("sd_length", sd_length),
            ("sd_scale", sd_scale),
            ("sd_part_scale", sd_part_scale),
        ):
            if not (math.isfinite(v) and v >= 0):
                raise QueryError(f"{name}={v!r} must be ≥ 0")
        if sd_turn <= 0:
            raise QueryError(f"sd_turn={sd_turn!r} rad must be positive (it keeps the covariance invertible)")
        if not noise_scales or not all(math.isfinite(f) and f >= 1 for f in noise_scales):
            raise QueryError(f"noise_scales={noise_scales!r}: give factors ≥ 1")
        self.part, self.wheel = part, wheel
        self.sd_turn, self.sd_slope, self.slope_length = float(sd_turn), float(sd_slope), float(slope_length)
        self.sd_length, self.sd_scale, self.thin = float(sd_length), float(sd_scale), float(thin)
        self.sd_part_scale = float(sd_part_scale)
        if not (math.isfinite(off_scale) and 0 <= off_scale < 1):
            raise QueryError(f"off_scale={off_scale!r} is a probability: give it in [0, 1)")
        self.off_scale = float(off_scale)
        if not (math.isfinite(off_scale_doubt) and 0 <= off_scale_doubt < 1):
            raise QueryError(f"off_scale_doubt={off_scale_doubt!r} is a probability: give it in [0, 1)")
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
        # a drawing's corners, their arcs (mm) and jumps (rad): every one's for the scale's secant, the convex
        # ones' for the pivots
        corners = list(part.corners) if isinstance(part, Outline) else []
        self._steps = (np.array([c.arc for c in corners]), np.array([c.angle for c in corners]))
        convex = self._steps[1] > 0
        self._convex = (self._steps[0][convex], self._steps[1][convex])
        # a turn beyond this (rad) from a face's angle is not the face's: a reading's error and the faces'
        # machined slope, at the noisiest the stated probability allows
        self._turn_margin = 3.0 * max(self.noise_scales) * math.hypot(self.sd_turn, self.sd_slope)
        self._ahead_jump, self._behind_jump = jump_runs(part, wheel, self.grid, self._ahead, self._behind)
        # each reading used keeps three numbers a start (six with the part's scale) and a row of the Cholesky
        # factor: 24·n·k + 8·k² bytes (48·n·k + 8·k²) for k readings stay within MAX_ARRAY_BYTES (a 1000 mm
        # part: 443 readings at thin=1; 222 with the scale)
        self._terms = (
            2 if self.sd_part_scale > 0 and self.off_scale > 0 else 1
        )  # residuals, and their derivatives in the scale
        # the prior probabilities of a part off its size the stated probability is the least under (the first
        # is the belief's)
        self.off_scales: tuple[float, ...] = (self.off_scale,)
        if self._terms > 1 and off_scale_doubt > self.off_scale:
            self.off_scales += (float(off_scale_doubt),)
        self._per_reading = 24.0 * self._terms * n
        b = self._per_reading
        self.max_readings = int((math.sqrt(b * b + 32.0 * MAX_ARRAY_BYTES) - b) / 16.0)
        self.reset()

    # ------------------------------------------------------------- readings
    def reset(self) -> None:
        """Forget every reading (a new roll from a new start)."""
        self.L_used: list[float] = []
        # the readings' arrays, grown by doubling up to max_readings: the first k rows (columns of _zbuf,
        # each start's whitened residuals and below them, with the part's scale, their derivatives in it, kept
        # contiguous per reading) are those of the readings used
        n = self.grid.size
        self._cholbuf = np.zeros((0, 0))
        self._zbuf = np.zeros((self._terms * n, 0), order="F")
        self._zzbuf = np.zeros((0, n))
        self._lvbuf = np.zeros((0, n))
        self._zgbuf = np.zeros((0, n))
        self._ggbuf = np.zeros((0, n))
        self._quad = np.zeros(n)
        self._zg = np.zeros(n)  # Σ z·g and Σ g²: each start's whitened residuals against their scale derivatives
        self._gg = np.zeros(n)
        self._logdet = np.zeros(self.grid.size)
        self._penalty = np.zeros(self.grid.size)
        # the contradictions of a roll over what the wheel cannot pass (in _penalty, at the model's size): a part
        # off its size may have rolled less of the model than was read (weigh_scale)
        self._penalty_run = np.zeros(self.grid.size)
        self._u_bound = np.full(self.grid.size, math.inf)  # _u_max as at the last reading used, as _penalty_run
        self.current = 0.0
        self.span = (0.0, 0.0)
        self._last: tuple[float, float] | None = None  # the last reading, used or not
        # the scale weighed out on every reading used, per (noise factor, temper): u's mean and sd, and the log
        # of the readings' factor off the model's size against at it, given each start (_scale_evidence)
        self._scale_cache: dict[tuple[float, float], tuple[FloatArray, FloatArray, FloatArray]] = {}
        # each noise factor's tempered log-likelihood at the model's size with the reach's evidence, −inf where
        # the wheel cannot touch (_base), kept until a reading is used or a jump counted
        self._base_cache: dict[float, FloatArray] = {}
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
    def _zg_each(self) -> FloatArray:
        """Each reading's whitened misfit times its scale derivative under each start, (readings, starts)."""
        out: FloatArray = self._zgbuf[: len(self.L_used)]
        return out

    @property
    def _gg_each(self) -> FloatArray:
        """Each reading's squared whitened scale derivative under each start, (readings, starts)."""
        out: FloatArray = self._ggbuf[: len(self.L_used)]
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
                f"({bytes_text(self._per_reading * k + 8.0 * k * k)}): one more passes the "
                f"{bytes_text(MAX_ARRAY_BYTES)} limit. It keeps a reading every thin={self.thin:g} mm rolled: give a "
                "larger thin, or roll less from one start (WheelPolicy.max_arc)"
            )
        cap = min(max(64, 2 * k), self.max_readings)
        chol = np.zeros((cap, cap))
        chol[:k, :k] = self._chol
        z = np.zeros((self._terms * n, cap), order="F")
        z[:, :k] = self._z
        zz, lv = np.zeros((cap, n)), np.zeros((cap, n))
        zz[:k], lv[:k] = self._zz, self._logvar
        self._cholbuf, self._zbuf, self._zzbuf, self._lvbuf = chol, z, zz, lv
        if self._terms > 1:
            zg, gg = np.zeros((cap, n)), np.zeros((cap, n))
            zg[:k], gg[:k] = self._zg_each, self._gg_each
            self._zgbuf, self._ggbuf = zg, gg

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
        before, self._last = self._last, (L, om)
        if abs(L - last) < self.thin and not self._pivot(L, om, before):
            return
        self._scale_cache.clear()
        self._base_cache.clear()
        used = np.array(self.L_used)
        c_new = self._cov(used, np.array([L]))[:, 0] if used.size else np.zeros(0)
        c_nn = float(self._cov(np.array([L]), np.array([L]))[0, 0])
        ell = solve_triangular(self._chol, c_new, lower=True) if used.size else np.zeros(0)
        d2 = max(c_nn - float(ell @ ell), 1e-18)
        model, kappa, slope, ahead = self._model_at(L, om)
        extra = kappa**2 * (self.sd_length**2 + (L * self.sd_scale) ** 2)
        rho = om - model
        var = d2 + extra
        n = self.grid.size
        past = self._z @ ell
        root = np.sqrt(var)
        z = (rho - past[:n]) / root
        self._make_room()
        k = used.size
        if self._terms > 1:
            # the residual falls by slope·u: whitened as the residual is (the same linear map per start)
            zg = (slope - past[n:]) / root
            self._zbuf[n:, k] = zg * np.sqrt(var / d2)
            self._zgbuf[k], self._ggbuf[k] = z * zg, zg**2
            self._zg += self._zgbuf[k]
            self._gg += self._ggbuf[k]
            self._place(L, ahead)
        self._quad += z**2
        self._zzbuf[k] = z**2  # each start's misfit of this reading, for the fit test and the stretches
        self._lvbuf[k] = np.log(var)
        self._logdet += self._lvbuf[k]
        # clear at the model's size where the roll's bound on the scale admits u = 0 (the starts the wheel cannot
        # touch, clear of any roll before there is one, weigh nothing whatever their penalty)
        u_max = self._u_max()
        contradicted = np.where(u_max >= 0.0, 0.0, math.log(CONTRADICTION))
        self._penalty += contradicted
        self._penalty_run += contradicted
        if self._terms > 1:
            self._u_bound = u_max
        self._zbuf[:n, k] = z * np.sqrt(var / d2)  # whitened by the shared part alone
        self._cholbuf[k, :k] = ell
        self._cholbuf[k, k] = math.sqrt(d2)
        self.L_used.append(L)

    def _place(self, length: float, ahead: FloatArray) -> None:
        """A pivot's place, where ``ahead`` is finite (:meth:`_model_at`): the corner ahead by c − x − L·u, within
        the unwidened window's third (the pivot's turn is 0 misfit there), an independent reading of u and the
        start. Kept out of the per-reading terms, as what a reading tells through the later ones' conditioning
        is at the model's size: a stretch left out leaves the corner's place."""
        pivoting = np.isfinite(ahead)
        if not pivoting.any():
            return
        sd = self.corner_window(length) / 3.0
        zp, zgp = ahead[pivoting] / sd, length / sd
        self._quad[pivoting] += zp**2
        self._zg[pivoting] += zp * zgp
        self._gg[pivoting] += zgp**2

    def _pivot(self, length: float, turn: float, before: tuple[float, float] | None) -> bool:
        """Whether a reading within ``thin`` of the last one used is used all the same, with the part's scale
        carried on a drawing: the first of a pivot on a corner (the arc stood still since the reading
        ``before`` and since the last one used, and the hand turned beyond a reading's error), whose place is
        a reading of the scale (:meth:`_place`). The readings used are spaced in arc, so a pivot, all at one
        arc, is seldom one of them otherwise, and its place read for the starts at the corner but its turn
        not for the rest would favour these."""
        if self._terms == 1 or not self._convex[0].size or before is None or not self.L_used:
            return False
        still = abs(length - before[0]) < self.h <= abs(length - self.L_used[-1])
        return still and abs(turn - before[1]) > self._turn_margin

    def jumped(self, direction: int, margin: float = 1.0) -> BoolArray:
        """The wheel jumped (and was taken back) when rolling on from the present contact in
        ``direction`` (+1: counter-clockwise). The starts under which the wheel could still have rolled
        on for ``margin`` mm there are made :data:`~localizer.BRIDGE_MISS` times less likely (soft: a
        jump may be read where there was none); per start, whether it explains the jump (:meth:`explains_jump`)."""
        if direction not in (1, -1):
            raise QueryError(f"direction={direction!r}: give +1 (counter-clockwise) or -1")
        explained = self.explains_jump(direction, margin)
        self._penalty += np.where(explained, 0.0, math.log(BRIDGE_MISS))
        self._base_cache.clear()
        return explained

    def explains_jump(self, direction: int, margin: float = 1.0) -> BoolArray:
        """Per start, whether the wheel rolling on from its present contact ``direction`` (+1: counter-clockwise)
        meets within ``margin`` mm a place it cannot roll over (it would jump there)."""
        here = np.rint(self.present() / self.h).astype(np.intp) % self.grid.size
        out: BoolArray = (self._ahead_jump if direction > 0 else self._behind_jump)[here] <= margin
        return out

    # --------------------------------------------------------------- belief
    def _u_max(self) -> FloatArray:
        """Per start, the largest scale u for which the roll so far, L(1 + u) of the model either way, runs over
        touchable points only (u = 0 within it: the roll is clear at the model's size; a wheel rolled up to a
        place it cannot pass on a part 2% large reads 2% past it). +inf where nothing was rolled that way; below
        −1 where nothing is clear."""
        lo, hi = self.span
        tol = 2 * self.h
        out: FloatArray = np.full(self.grid.size, math.inf)
        if hi > 0:
            out = np.minimum(out, (self._ahead + tol) / hi - 1.0)
        if lo < 0:
            out = np.minimum(out, (self._behind + tol) / -lo - 1.0)
        return out

    def _scale_posterior(self, temper: float = TEMPER) -> tuple[FloatArray, FloatArray]:
        """Per start: the mean of the part's scale u given the start and that the part is off its model's size,
        and the probability, under the prior probability :attr:`off_scale`, that it is off its size; under the
        readings' likelihood raised to ``temper`` with the error model as told. Without the scale: zeros."""
        if self._terms == 1:
            zero = np.zeros(self.grid.size)
            return zero, zero
        mean, _, evidence = self._scale_evidence(1.0, None, None, temper)
        p_off: FloatArray = expit(evidence + (math.log(self.off_scale) - math.log1p(-self.off_scale)))
        return mean, p_off

    def _scale_evidence(
        self, factor: float, zg: FloatArray | None, gg: FloatArray | None, temper: float
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """:func:`~localizer.filters._wheel_scale.weigh_scale` of the sums (default every reading used's, kept
        until the next reading used), as :meth:`_scale_posterior` takes them: before any prior odds."""
        key = (factor, temper)
        own = zg is None and gg is None
        if own and key in self._scale_cache:
            return self._scale_cache[key]
        zg = (self._zg if zg is None else zg) * (temper / factor**2)
        gg = (self._gg if gg is None else gg) * (temper / factor**2)
        out = weigh_scale(zg, gg, self.sd_part_scale, self._u_bound, self._penalty_run)
        if own:
            self._scale_cache[key] = out
        return out

    def _weighed(self, factor: float, odds: float | None = None) -> tuple[FloatArray, Spread]:
        """The posterior over the starts and each start's present contact (:meth:`posterior`,
        :meth:`present_spread`) under the error model times ``factor`` and the prior probability ``odds``
        (default :attr:`off_scale`) that the part is off its size, the scale weighed out once for both."""
        scale = self._scale_evidence(factor, None, None, TEMPER) if self._terms > 1 else None
        return self._mixed(self._base(factor), scale, self.off_scale if odds is None else odds)

    def _mixed(
        self, base: FloatArray, scale: tuple[FloatArray, FloatArray, FloatArray] | None, odds: float
    ) -> tuple[FloatArray, Spread]:
        """The posterior over the starts and each start's present contact, from each start's log-likelihood at
        the model's size ``base`` (−inf where it cannot be) and, with the scale carried, u's posterior mean and
        sd and the evidence off the model's size (:meth:`_scale_evidence`; None without): each start's weight
        at its model's size and off it (by the prior ``odds``), whose sum is the posterior and whose share off
        it the probability it is off its size."""
        if scale is None:
            zero = np.zeros(self.grid.size)
            top = float(base.max())
            if not math.isfinite(top):
                raise QueryError("no start on the part fits the readings (all hypotheses ruled out)")
            w = relative_weights(base, top)
            w /= w.sum()
            return w, self._spread(zero, zero, zero)
        mean, sd, evidence = scale
        at_size = base + math.log1p(-odds)
        off = base + evidence
        off += math.log(odds)
        top = max(float(at_size.max()), float(off.max()))
        if not math.isfinite(top):
            raise QueryError("no start on the part fits the readings (all hypotheses ruled out)")
        w = relative_weights(at_size, top)
        w_off = relative_weights(off, top)
        w += w_off
        p_off = np.divide(w_off, w, out=np.full(w.size, odds), where=w > 0)
        w /= w.sum()
        return w, self._spread(mean, sd, p_off)

    def _base(self, factor: float) -> FloatArray:
        """Each start's tempered log-likelihood at the model's size under the error model times ``factor``, with
        the reach's evidence; −inf where the wheel cannot touch (kept until a reading is used or a jump
        counted)."""
        out = self._base_cache.get(factor)
        if out is None:
            ll = TEMPER * (-0.5 * self._quad / factor**2 - 0.5 * self._logdet) + self._penalty
            out = self._base_cache[factor] = np.where(self.prior > 0, ll, -np.inf)
        return out

    def posterior(self) -> FloatArray:
        """Posterior probability of each start on :attr:`grid` (sums to 1)."""
        return self._weighed(self.noise_scales[0])[0]

    def present(self) -> FloatArray:
        """Each start's present contact, mm: its posterior mean given the start over the part's scale
        (:meth:`present_spread`)."""
        out: FloatArray = self.part.wrap_arc(self.present_spread().mean)
        return out

    def present_spread(self, factor: float = 1.0, odds: float | None = None) -> Spread:
        """Each start's present contact at the model's size and off it (:class:`Spread`), under the error
        model times ``factor`` and the prior probability ``odds`` (default :attr:`off_scale`) that the part is
        off its size."""
        return self._weighed(factor, odds)[1]

    def _spread(self, mean: FloatArray, sd: FloatArray, p_off: FloatArray) -> Spread:
        """Each start's present contact for the part's scale u given the start, off the model's size
        N(``mean``, ``sd``²) with probability ``p_off``: the arc read since the start stretched by 1 + u. (On a
        drawing a pivot on a corner ties u to the start, s + L(1 + u) = c: the starts then spread the present
        contact by the arc read since the corner times u's prior, each start itself little.)"""
        nominal = self.grid + self.current
        return Spread(nominal, nominal + self.current * mean, abs(self.current) * sd, p_off)
