"""The straight jaw's grid filter, its state: the settings it is built with, the grid of starts, and the
running sums over them that each reading adds to and a stretch taken out removes (docs/filter.md)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._defaults import CONFIDENCE, SUCCESS_RADIUS
from .._errors import QueryError
from .._types import ArrayLike, BoolArray, FloatArray, IntArray
from ..contact import DEFAULT_JAW, StraightJaw, grid_size, tracks_for
from ..geometry import Boundary, Line, check_grid
from ._contact_settings import (
    ENCODER_SD,
    LOOKALIKE_SLOPE,
    NOISE_SCALES,
    RHO_MAX,
    SCALE_SD,
    SLOPE_ENVELOPE,
    SLOPE_RHO_MAX,
    STRETCH_WEIGHT,
    TEMPER,
    TURN_MARGIN,
)
from ._filter_kernels import add_row
from ._stretches import (
    DEFECT_WINDOW,
    FIT_EVERY,
    FIT_WIDTH,
    Misfit,
)
from ._sums import _bspline, _Reading

__all__ = ["ContactState"]


#: (live, UᵀU, Uᵀz, zᵀz, Uᵀp, pᵀp, zᵀp) over the live starts and the touched columns
_Gathered = tuple[IntArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]


class ContactState:
    """The filter's settings, its grid of starts and its running sums (:class:`~localizer.ContactFilter` documents the
    parameters)."""

    def __init__(
        self,
        part: Boundary,
        *,
        spacing: float = 0.02,
        sd_position: float = 0.035,
        sd_scale: float = SCALE_SD,
        sd_slope: float = 0.001,
        shape_spacing: float = 5.0,
        radius: float = SUCCESS_RADIUS,
        mode_floor: float = 0.05,
        confidence: float = CONFIDENCE,
        prune: float = 40.0,
        refresh: int = 5,
        jaw: StraightJaw = DEFAULT_JAW,
        jaw_margin: float = 2.0,
        noise_scales: ArrayLike = NOISE_SCALES,
        slope_envelope: ArrayLike = SLOPE_ENVELOPE,
        lookalike_slope: float = LOOKALIKE_SLOPE,
        corner_ends: bool = True,
        sd_jaw: float = 0.015,
        jaw_spacing: float = 5.0,
        sd_turn: float = ENCODER_SD,
        temper: float = TEMPER,
        sd_drift: float = 1e-4,
        defect_window: float = DEFECT_WINDOW,
        stretch_weight: float = STRETCH_WEIGHT,
    ) -> None:
        for name, value in (("spacing", spacing), ("sd_position", sd_position), ("radius", radius)):
            if not (math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} mm must be a positive number")
        for name, value in (
            ("sd_scale", sd_scale),
            ("sd_slope", sd_slope),
            ("sd_jaw", sd_jaw),
            ("sd_turn", sd_turn),
            ("sd_drift", sd_drift),
            ("lookalike_slope", lookalike_slope),
        ):
            if not (math.isfinite(value) and value >= 0):
                raise QueryError(f"{name}={value!r} must be ≥ 0")
        for name, value in (("shape_spacing", shape_spacing), ("jaw_spacing", jaw_spacing)):
            if not (math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} mm must be positive")
        if not 0 < confidence < 1:
            raise QueryError(f"confidence={confidence!r} must be in (0, 1)")
        if isinstance(refresh, bool) or not isinstance(refresh, (int, np.integer)) or refresh < 1:
            raise QueryError(f"refresh={refresh!r} must be a whole number of readings ≥ 1")
        scales = np.asarray(noise_scales, dtype=float).ravel()
        if scales.size == 0 or not np.all(np.isfinite(scales) & (scales > 0)):
            raise QueryError(f"noise_scales={noise_scales!r} must be positive factors")
        envelope = np.asarray(slope_envelope, dtype=float).ravel()
        if not np.all(np.isfinite(envelope) & (envelope > 0)):
            raise QueryError(f"slope_envelope={slope_envelope!r} must be positive factors")
        if not (math.isfinite(temper) and 0 < temper <= 1):
            raise QueryError(f"temper={temper!r} must be in (0, 1]")
        if not (math.isfinite(jaw_margin) and jaw_margin >= 0):
            raise QueryError(f"jaw_margin={jaw_margin!r} mm must be ≥ 0")
        if not (math.isfinite(defect_window) and defect_window >= 0):
            raise QueryError(f"defect_window={defect_window!r} mm must be ≥ 0 (0: trust every stretch)")
        self.defect_window = float(defect_window)
        if isinstance(stretch_weight, bool) or not (
            isinstance(stretch_weight, (int, float, np.number)) and 0 <= stretch_weight <= 1
        ):
            raise QueryError(f"stretch_weight={stretch_weight!r} must be a probability in [0, 1] (1: the least)")
        self.stretch_weight = float(stretch_weight)
        # the stretches the fit test judges: twice the envelope's (a burr's misfit and its edges)
        self._fit_width = FIT_WIDTH * self.defect_window
        self.part = part
        self.jaw = jaw
        self.jaw_margin = float(jaw_margin)
        self.temper = float(temper)
        self.noise_scales = tuple(float(v) for v in scales)
        self.slope_envelope = tuple(float(v) for v in envelope if v != 1.0) if sd_slope > 0 else ()
        self.lookalike_slope = float(lookalike_slope) if sd_slope > 0 else 0.0
        self.corner_ends = bool(corner_ends)
        self.jaw_spacing = float(jaw_spacing)
        # basis columns: 0 the constant, then B-splines B_k(z) for knots over z in [-P, P]
        self._k0 = int(math.ceil(part.perimeter / shape_spacing)) + 3
        self._segments = 48  # offsets: one per contact segment (see regrasp)
        self._jaw0 = self._segments + (2 * self._k0 + 4 if sd_slope > 0 else 0)
        # then the calibration error's B-splines over the jaw's span and the margin beyond it
        self._jaw_lo = -(jaw.half + self.jaw_margin) - self.jaw_spacing
        n_jaw = int(math.ceil(2 * (jaw.half + self.jaw_margin) / self.jaw_spacing)) + 5 if sd_jaw > 0 else 0
        self._jaw_end = self._jaw0 + n_jaw
        # and the sensor's drift: a rate per reading, the same all run long
        self._drift = self._jaw_end
        self._m = self._jaw_end + (1 if sd_drift > 0 else 0)
        # a part too large for the grid of starts or for the sums over it (8 bytes a basis column a start)
        # is refused before either is built
        check_grid(part, "filter", spacing, grid_size(part, spacing), point_bytes=8.0 * self._m)
        self.tracks = tracks_for(part, spacing, jaw)
        # the faces (start mm, length mm, angle rad) and the starts inside a corner's jump, for the belief
        self._faces = [
            (float(a), float(piece.length), float(piece.tangent_angle(0.0)))
            for a, piece in zip(getattr(part, "starts", ()), getattr(part, "pieces", ()))
            if isinstance(piece, Line)
        ]
        self._inside_corner = self.tracks.pivot & np.roll(self.tracks.pivot, 1)
        self.sd_position = float(sd_position)
        self.sd_scale = float(sd_scale)
        self.sd_slope = float(sd_slope)
        self.sd_jaw = float(sd_jaw)
        self.sd_turn = float(sd_turn)
        self.sd_drift = float(sd_drift)
        self.shape_spacing = float(shape_spacing)
        self.prune = float(prune)
        self.refresh = int(refresh)
        # before the first reference hypothesis: the median radius over the stretches a jaw touches
        convex = self.tracks.kappa[self.tracks.convex & (self.tracks.kappa > 0)]
        self._rho_prior = float(np.clip(np.median(1.0 / convex), 5.0, 500.0)) if convex.size else 50.0
        self.radius = float(radius)
        self.mode_floor = float(mode_floor)
        self.confidence = float(confidence)
        self.index = np.arange(self.tracks.sigma.size)
        self._replaying = 0  # > 0 while a call is made by the filter itself (not logged)
        self.reset()

    @property
    def segment(self) -> int:
        """Index of the present contact segment (0, then one more per :meth:`~localizer.ContactFilter.regrasp`)."""
        return self._segment

    @property
    def grid(self) -> FloatArray:
        """The hypotheses: starts of the rolling, mm."""
        return self.tracks.sigma

    def reset(self) -> None:
        """Back to the prior: every start the jaw can touch equally likely, nothing measured."""
        n = self.grid.size
        self.current = self.grid.copy()  # present contact of each hypothesis, mm (unwrapped)
        self.node = np.arange(n)  # ... and its grid point (on a pivot, the jaw's angle too)
        self._hints = self.tracks.landing_hints()  # ... and its entry in the tracks' angle table
        self.feasible = self.tracks.convex.copy()
        m = self._m
        self._up = np.zeros((m, n))  # Uᵀp per hypothesis (row 0: Σp)
        self._spp = np.zeros(n)
        self._szp = np.zeros(n)
        self._uz = np.zeros(m)  # Uᵀz
        self._uu = np.zeros((m, m))  # UᵀU
        self._szz = 0.0
        self._touched = np.zeros(m, dtype=bool)  # basis columns some reading has touched
        self._touched[0] = True
        # the slope priors' reference and readings done
        self._prior_ref: int | None = None
        self._prior_upto = 0
        self._segment = 0
        self._penalty = np.zeros(n)  # log-probability of the reach evidence (touches, bridges)
        self.jaw_position = math.nan  # the contact's last measured place on the jaw, mm
        self._live = self.feasible.copy()  # hypotheses still worth evaluating
        self._live_idx = np.flatnonzero(self._live)
        self._ref: int | None = None  # the hypothesis whose radii set the slope term's prior
        self._slope_var = np.zeros(self._m)  # prior variance of each slope coefficient, mm²
        self._hist: list[tuple[float, float]] = []  # (z, turn) of every reading, for the reference's radii
        self._version = 0  # changes to the likelihood (its cache's key)
        self._rows = 0  # readings added
        self._cached: dict[float, dict[str, Any]] = {}  # per factor on the slope prior
        self._gather: tuple[tuple[int, IntArray], _Gathered] | None = None  # shared by the slope prior's factors
        self._last_row: tuple[IntArray, FloatArray] = (np.zeros(0, dtype=np.int64), np.zeros(0))
        # every reading as added (weighted): columns, values, z, the hypotheses live then and their
        # predictions, its arc and turn; and the readings taken out again (quarantine)
        self._readings: list[_Reading] = []
        self._out: set[int] = set()
        self._stretch_cache: tuple[Any, float] = (None, 1.0)  # (state, least mass without a stretch)
        self._fit_version = -1  # the state of the readings the last fit test judged
        self._spread_at: tuple[int, bool] = (-1, False)  # (readings, whether they span a defect window)
        self._misfits: list[Misfit] = []  # stretches found not to fit, quarantined (the first MAX_QUARANTINE)
        self._fit_next = FIT_EVERY
        self._last_map = math.nan
        self._last_span: tuple[float, float] | None = None
        self._bridges: list[tuple[float, float, float, float]] = []  # (turn before, turn, jaw, jump)
        # every call that changed the state since the reset, so that the filter can be rebuilt with a
        # stretch quarantined from the start (:meth:`~localizer.ContactFilter._rebuild`)
        self._calls: list[tuple[str, tuple[Any, ...]]] = []
        # the rolled arc (mm, from, to) of each quarantined stretch: a reading taken there later (the jaw
        # rolled back onto a burr's crest, where it may stay for tens of degrees) is quarantined as it comes
        self._zones: list[tuple[float, float]] = []
        self._add_row(0.0, np.zeros(n))  # the first reading: z_0 = 0, p_0 = 0
        self.steps = 0
        self.turn = 0.0
        self.arc = 0.0

    def _log(self, name: str, *args: Any) -> None:
        """Keep a call that changes the state (not one the filter makes of itself, nor a replay's)."""
        if not self._replaying:
            self._calls.append((name, args))

    def _basis(self, z: float, jaw: float | None = None) -> tuple[IntArray, FloatArray]:
        """(columns, values) of the basis for a reading at cumulative arc z (mm) and place ``jaw`` (mm)
        on the jaw: the segment's offset, four cubic B-splines of the slope error in z (times ρ̂)
        and four of the calibration's error in the place on the jaw."""
        cols, vals = [np.array([self._segment])], [np.array([1.0])]
        if self.sd_slope > 0:
            c, v = _bspline(z / self.shape_spacing)
            c = c + self._segments + self._k0
            if c[0] < self._segments or c[-1] >= self._jaw0:
                raise QueryError(f"arc={z!r} mm is more than a perimeter from the first reading")
            cols.append(c)
            vals.append(v)
        if self.sd_jaw > 0 and jaw is not None:
            # a place read a little beyond the basis' span takes its end's values
            top = self._jaw_end - self._jaw0 - 3 - 1e-9
            x = float(np.clip((float(jaw) - self._jaw_lo) / self.jaw_spacing, 0.0, top))
            c, v = _bspline(x)
            cols.append(c + self._jaw0)
            vals.append(v)
        if self.sd_drift > 0:
            cols.append(np.array([self._drift]))
            vals.append(np.array([float(self._rows - 1)]))
        return np.concatenate(cols), np.concatenate(vals)

    def _radius_here(self) -> float:
        """ρ̂, mm: the model's radius of curvature at the reference hypothesis' present contact
        (5 mm to RHO_MAX; the median convex radius before there is a reference)."""
        if self._ref is None:
            return self._rho_prior
        t = self.tracks
        k = t.kappa[int(t.node_at(self.current[self._ref]))]
        return float(np.clip(1.0 / k, 5.0, RHO_MAX)) if k > 0 else RHO_MAX

    def _slope_priors(self) -> None:
        """Each slope coefficient's prior from the reference hypothesis' radii where its B-spline is
        nonzero: the contact's offset there is ρ·η, η ~ N(0, sd_slope²). Only the prior changes (the
        sums do not depend on it), so the coefficients stay a smooth function of the arc: scaling the
        basis' values by a radius that jumps when the reference changes would make the offset's
        constant part look measured (it is the segments' offsets' to absorb)."""
        if self.sd_slope <= 0 or self._ref is None or not self._hist:
            return
        before = self._slope_var.copy()
        if self._ref != self._prior_ref:  # a new reference: its radii along the whole path
            self._prior_ref, self._prior_upto = self._ref, 0
            self._slope_var[self._segments : self._jaw0] = 0.0
        new = np.array(self._hist[self._prior_upto :])
        self._prior_upto = len(self._hist)
        if new.size == 0:
            if not np.array_equal(before, self._slope_var):
                self._version += 1
            return
        z, turn = new.T
        arc, ok = self.tracks.advance(np.full(z.size, self._ref), turn, turn_margin=TURN_MARGIN)
        land = self.tracks.node_at(np.where(ok, arc, self.grid[self._ref]))
        kappa = self.tracks.kappa[land]
        rho = np.where(kappa > 0, np.clip(1.0 / np.maximum(kappa, 1e-12), 5.0, SLOPE_RHO_MAX), SLOPE_RHO_MAX)
        # column c (relative) is nonzero for z/spacing in [c - 3, c + 1): the largest radius there
        first = np.floor(z / self.shape_spacing).astype(np.int64) + self._segments + self._k0
        for k in range(4):
            np.maximum.at(self._slope_var, first + k, (rho * self.sd_slope) ** 2)
        # a refresh that changes no prior keeps the solves made since the last reading
        if not np.array_equal(before, self._slope_var):
            self._version += 1

    def _add_row(
        self, z: float, p: FloatArray, idx: IntArray | None = None, jaw: float | None = None, turn: float = 0.0
    ) -> None:
        """Add a reading z at net rotation ``turn`` and place ``jaw`` on the jaw with the predictions p of
        the hypotheses ``idx`` (default: all)."""
        self._version += 1
        self._rows += 1
        cols, vals = self._basis(z, jaw)
        self._last_row = (cols, vals)
        self._hist.append((z, turn))
        fresh = cols[(cols >= self._segments) & (cols < self._jaw0)]
        fresh = fresh[self._slope_var[fresh] == 0]
        rho = self._radius_here()
        self._slope_var[fresh] = (min(rho, SLOPE_RHO_MAX) * self.sd_slope) ** 2
        # the rotation's error moves the contact by ρ·e: the reading's variance grows by (ρ̂·sd_turn)²
        # (weighted least squares: the row times 1/relative sd)
        wt = 1.0 / math.hypot(1.0, rho * self.sd_turn / self.sd_position)
        self._row_weight = wt
        z, p, vals = z * wt, p * wt, vals * wt
        live = np.arange(self.grid.size) if idx is None else np.asarray(idx, dtype=np.int64)
        add_row(self._up, self._uu, self._uz, self._spp, self._szp, self._touched, cols, vals, live, p, z)
        self._szz += z * z
        self._readings.append(
            _Reading(cols, vals, z, live, p, z / wt, turn, self._segment, wt, rho if rho < RHO_MAX else 0.0)
        )

    def _take(self, rows: list[int], sign: float) -> None:
        """Take the readings ``rows`` (indices into the readings added) out of the sums (``sign`` -1) or
        put them back (1), for the hypotheses live now."""
        live = self._live_idx
        for j in rows:
            r = self._readings[j]
            pos = np.searchsorted(r.live, live)
            add_row(
                self._up,
                self._uu,
                self._uz,
                self._spp,
                self._szp,
                self._touched,
                r.cols,
                r.vals,
                live,
                r.p[pos],
                r.z,
                sign,
            )
            self._szz += sign * r.z * r.z
        self._version += 1

    def _take_out(self, j: int) -> None:
        """Quarantine reading ``j``, just added (its sums are those of the starts live now)."""
        self._take([j], -1.0)
        self._out.add(j)

    def set_quarantine(self, rows: set[int] | list[int]) -> None:
        """Trust all readings but ``rows`` (indices of the readings in the order given, 0 the first): those
        are taken out of the likelihood, as if never taken; readings quarantined before and not in
        ``rows`` are put back."""
        new = {int(j) for j in rows if 0 < int(j) < len(self._readings)}
        self._take(sorted(new - self._out), -1.0)
        self._take(sorted(self._out - new), 1.0)
        self._out = new

    def _surely_clear(
        self, idx: IntArray, before: float, turn: float, d0: float, jump: float, at: FloatArray | None = None
    ) -> BoolArray:
        """Whether, for each start ``idx``, turning from net rotation ``before`` to ``turn`` (rad) with the
        contact at ``d0`` mm on the jaw surely keeps the jaw on its convex stretch, the contact moving less
        than half of ``jump`` (mm): a bridge there was not to be expected. ``at``: the starts' contacts at
        ``before`` (mm; default: where the tracks put them)."""
        if at is None:
            at, _, _ = self.tracks.step(idx, before)
        # surely clear: still so a little further on (the real part's convex stretch may end up to
        # TURN_MARGIN before the model's)
        further = turn + math.copysign(TURN_MARGIN, turn - before)
        clear = np.ones(idx.size, dtype=bool)
        for t in (turn, further):
            land, node, ok = self.tracks.step(idx, t)
            moved = land - at
            clear &= ok & self.tracks.touches(land, d0 + moved, -self.jaw_margin, sure=True, node=node)
            if t == turn:
                clear &= np.abs(moved) < 0.5 * jump
        out: BoolArray = clear
        return out
