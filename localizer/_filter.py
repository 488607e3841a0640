"""Sequential localization while rolling: an exact grid filter and a particle-filter baseline.

The jaw rolls on a convex stretch of the part. With the contact at arc
position σ₀ when the rolling starts, a net jaw rotation Ω puts it at the σ
where the tangent angle θ(σ) = θ(σ₀) + Ω (counter-clockwise rotation, contact
moving counter-clockwise), so the whole path is fixed by σ₀ and the
rotations. What the wrist measures along the way is the contact's travel
on the jaw, turned into arc length step by step
(:func:`localizer.arc_from_jaw_positions`).

**ContactFilter** (exact on a grid). The hypotheses are the starts σ₀ on a grid
of ``spacing`` mm over the whole boundary. After k steps, the measured
cumulative signed arcs z_0 = 0, z_1, …, z_k and the predicted ones
p_j(σ₀) = σ(θ(σ₀) + Ω_j) − σ₀ are related by

    z_j = c + b·p_j(σ₀) + ρ̂_j·η(z_j) + e_j,   e_j ~ N(0, sd_position²) independent,

where c absorbs the noise of the first reading (flat prior), b is the
calibration's scale (b ~ N(1, sd_scale²)), and ρ̂·η is the machining error's
effect: a slope error η of the real boundary against its model (rad) moves the
contact for a given jaw angle by ρ·η, ρ the radius of curvature there. η is a
smooth random function along the path, cubic B-splines in z with knots every
``shape_spacing`` mm and coefficients ~ N(0, sd_slope²), and ρ̂_j is the model's
radius of curvature at the present contact of a reference hypothesis, the most
probable one (re-chosen every ``refresh`` readings; the part's median radius
before the first), the same for every hypothesis. ρ̂ must not be measured from
the readings themselves (arc over rotation over the last few steps, as the first
version did): that puts the reading noise into the basis, and the slope term
then fitted the noise and moved the start, by up to 0.5 mm at a stated 99%
(docs/robustness.md). This error repeats when the jaw rolls over the same
stretch again, so more rolling does not average it away; near an inflection,
where ρ grows without bound, it makes the readings say little, as they should.
The same term at the last reading is how far the real present contact is from
where the model puts it (:meth:`ContactFilter.shift`); the belief includes it
and its spread.
c, b and η are integrated out in closed form (Woodbury): each hypothesis keeps
running sums (pᵀp, pᵀz and the basis projections Uᵀp, of which a reading
touches five), so one step costs a few vector operations on the grid, and the
belief a small dense solve. The rotations
are taken as exact; the encoder's 0.03° moves a contact by ρ·5e-4 rad, a few
µm at the parts' radii. A hypothesis that would have to cross an inflection
(where a straight jaw bridges a concavity, which the rolling procedure refuses)
has zero likelihood; so does a start on a concave stretch, which a straight jaw
cannot touch.

The belief over the *present* contact is the push-forward of the posterior over
σ₀. :meth:`ContactFilter.belief` reports its maximum, the probability within the
success radius of it, the separate modes, and whether the data said anything at
all (on a circle every start predicts the same readings).

**ParticleFilter** is the conventional peer method: particles over the present
contact, moved by each measured rotation step with a small process noise,
weighted by each step's measured arc increment, resampled systematically when
the effective sample size drops below half.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull
from scipy.special import ndtr

from ._errors import QueryError
from ._part import Part

__all__ = ["ContactFilter", "ParticleFilter", "Belief", "Mode", "ModeTracks", "machining_slope"]


@dataclass(frozen=True)
class Mode:
    """One separate mode of the belief over the present contact.

    Attributes
    ----------
    arc : float, mm
        Most probable present contact in the mode.
    mass : float
        Probability of the mode.
    start_arc : float, mm
        The corresponding start of the rolling.
    """

    arc: float
    mass: float
    start_arc: float


@dataclass(frozen=True)
class Belief:
    """What the filter believes about the present contact.

    Attributes
    ----------
    map_arc : float, mm
        The most probable present contact.
    mass : float
        Probability that the contact is within ``radius`` of ``map_arc``.
    radius : float, mm
    modes : tuple of Mode
        Separate modes, most probable first.
    ambiguous : bool
        More than one mode holds at least ``mode_floor`` of the probability and the
        first does not reach the confidence: the data cannot tell them apart (yet).
    informative : bool
        False when the posterior is as flat as the prior (e.g. on a circle).
    steps : int
        Updates so far.
    """

    map_arc: float
    mass: float
    radius: float
    modes: tuple
    ambiguous: bool
    informative: bool
    steps: int


def machining_slope(rms: float, wavelength: float, perimeter: float) -> float:
    """RMS slope error (rad) of a boundary deviation of ``rms`` mm made of harmonics of the
    perimeter with 1/k amplitudes down to ``wavelength`` mm (the simulator's machining model)."""
    if rms <= 0:
        return 0.0
    k = np.arange(1, max(1, int(perimeter / wavelength)) + 1)
    return float(rms * 2 * np.pi / perimeter * math.sqrt(len(k) / np.sum(1.0 / k ** 2)))


_TRACKS: dict = {}


def tracks_for(part: Part, spacing: float) -> "ModeTracks":
    """The part's :class:`ModeTracks` at ``spacing`` mm, built once per part and spacing.

    Building them takes most of a second (the dense sample, its convex hull, the banded
    tangent-angle table); a Monte Carlo trial makes a grid filter and a particle filter on
    the same part. The tables are read-only, so the filters can share them.
    """
    key = (part.points.tobytes(), part.cells_per_piece, float(spacing))
    tracks = _TRACKS.get(key)
    if tracks is None:
        if len(_TRACKS) >= 8:
            _TRACKS.pop(next(iter(_TRACKS)))
        tracks = _TRACKS[key] = ModeTracks(part, spacing)
    return tracks


class ModeTracks:
    """Where each of a set of hypotheses' contacts goes under further rotation (for planning)."""

    def __init__(self, part: Part, spacing: float, hull_tolerance: float = 4.0):
        self.part = part
        p = part.perimeter
        n = max(64, int(math.ceil(p / spacing)))
        self.h = p / n
        sigma = np.arange(n) * self.h
        theta = np.asarray(part.tangent_angle_at_arc(sigma), dtype=float)
        kappa = np.asarray(part.curvature_at_arc(sigma), dtype=float)
        self.sigma, self.theta, self.kappa = sigma, theta, kappa
        # three laps so that any rotation of less than a lap stays on the table
        turn = 2.0 * math.pi
        arcs = np.concatenate([sigma - p, sigma, sigma + p, [2 * p]])
        th = np.concatenate([theta - turn, theta, theta + turn, [theta[0] + 2 * turn]])
        rising = np.diff(th) > 0
        # runs of cells with rising θ (convex stretches) or not; run r spans nodes a_r..b_r
        change = np.flatnonzero(np.diff(rising.astype(np.int8)) != 0) + 1
        a = np.concatenate([[0], change])
        b = np.concatenate([change, [rising.size]])
        span = float(th.max() - th.min()) + 1.0
        # each run's nodes, its θ shifted into a band of its own (flat on falling runs), concatenated:
        # one searchsorted then serves every run
        pieces_s, pieces_b, offsets = [], [], []
        at = 0
        for r, (lo, hi) in enumerate(zip(a, b)):
            offsets.append(at)
            pieces_s.append(arcs[lo:hi + 1])
            vals = th[lo:hi + 1] if rising[lo] else np.full(hi + 1 - lo, th[lo])
            pieces_b.append(vals + r * span)
            at += hi + 1 - lo
        self._s = np.concatenate(pieces_s)
        self._banded = np.concatenate(pieces_b)
        self._first = np.array(offsets)
        self._last = np.array(offsets) + (b - a)
        self._span = span
        run_of_cell = np.repeat(np.arange(a.size), b - a)
        self._run = run_of_cell[np.arange(n) + n]
        # a straight jaw touches only the convex hull: keep the boundary within hull_tolerance
        # of the hull of its dense sample. The tolerance is generous (4 mm) because a jaw of
        # finite length reaches well past where the hull leaves the boundary when the
        # obstructing lobe is beyond its end (measured: starts 1.4 mm below the trefoil's hull
        # were touched with the contact 40 mm from the jaw's centre), and the machined part
        # differs from the model.
        pts = np.asarray(part.point_at_arc(sigma))
        eq = ConvexHull(pts).equations                      # n·x + d ≤ 0 inside
        depth = np.full(n, -np.inf)
        for chunk in range(0, len(eq), 256):
            e = eq[chunk:chunk + 256]
            depth = np.maximum(depth, (e[:, :2] @ pts.T + e[:, 2:3]).max(axis=0))
        self.hull = depth > -hull_tolerance
        self.convex = rising[a][self._run] & (kappa > 0) & self.hull
        for arr in (self.sigma, self.theta, self.kappa, self.hull, self.convex, self._s, self._banded,
                    self._first, self._last, self._run):
            arr.setflags(write=False)

    def advance(self, index: np.ndarray, turn: float) -> tuple:
        """Arc positions after a net rotation ``turn`` (rad) of the grid points ``index``.

        Returns (arc mm, unwrapped, ``nan`` where the rotation leaves the point's
        convex stretch), and a feasibility mask.
        """
        idx = np.asarray(index)
        run = self._run[idx]
        target = self.theta[idx] + turn + run * self._span
        first, last = self._first[run], self._last[run]
        ok = self.convex[idx] & (target >= self._banded[first]) & (target <= self._banded[last])
        j = np.clip(np.searchsorted(self._banded, target, side="left"), first + 1, last)
        b0, b1 = self._banded[j - 1], self._banded[j]
        w = (target - b0) / np.where(b1 > b0, b1 - b0, 1.0)
        arc = self._s[j - 1] + w * (self._s[j] - self._s[j - 1])
        # the contact must still be on the hull where it lands (else the jaw bridges)
        land = np.mod(np.rint(arc / self.h).astype(np.int64), self.sigma.size)
        ok &= self.hull[land]
        return np.where(ok, arc, np.nan), ok


class ContactFilter:
    """Exact Bayesian filter over the start of the rolling, on a grid (see the module notes).

    Parameters
    ----------
    part : Part
    spacing : float, mm
        Grid step of the hypotheses (default 0.02 mm, 1/15 of the paper's 0.3 mm radius).
    sd_position : float, mm
        Standard deviation of one contact-location reading, as arc.
    sd_scale : float
        Standard deviation of the calibration's relative scale error (0: none).
    sd_slope : float, rad
        Standard deviation of the B-spline coefficients of the part's slope error
        against its model (0: a perfect part). :func:`machining_slope` gives it for
        the simulator's machining model.
    shape_spacing : float, mm
        Knot spacing of that B-spline basis, in cumulative arc.
    radius : float, mm
        Success radius of :meth:`belief`.
    mode_floor : float
        Probability a mode needs to count in ``ambiguous``.
    confidence : float
        Probability the leading mode needs for the belief not to be ``ambiguous``.
    prune : float
        Hypotheses this many nats below the best are no longer evaluated.
    refresh : int
        Readings between choices of the reference hypothesis whose radius of
        curvature scales the slope-error term (each choice evaluates the likelihood).

    Examples
    --------
    >>> import numpy as np
    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    >>> circle = part_from_points(np.c_[20 * np.cos(a), 20 * np.sin(a)])
    >>> f = ContactFilter(circle, sd_position=0.05)
    >>> for k in range(1, 11):   # ten 0.2° steps: 0.0698 mm of arc each on a 20 mm circle
    ...     f.update(k * 20 * np.radians(0.2), k * np.radians(0.2))
    >>> f.belief().informative   # every start fits equally well
    False
    """

    def __init__(self, part: Part, *, spacing: float = 0.02, sd_position: float = 0.035, sd_scale: float = 0.003,
                 sd_slope: float = 0.001, shape_spacing: float = 5.0, radius: float = 0.3, mode_floor: float = 0.05,
                 confidence: float = 0.95, prune: float = 40.0, refresh: int = 5):
        for name, value in (("spacing", spacing), ("sd_position", sd_position), ("radius", radius)):
            if not (math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} mm must be a positive number")
        for name, value in (("sd_scale", sd_scale), ("sd_slope", sd_slope)):
            if not (math.isfinite(value) and value >= 0):
                raise QueryError(f"{name}={value!r} must be ≥ 0")
        if not (math.isfinite(shape_spacing) and shape_spacing > 0):
            raise QueryError(f"shape_spacing={shape_spacing!r} mm must be positive")
        if not 0 < confidence < 1:
            raise QueryError(f"confidence={confidence!r} must be in (0, 1)")
        if isinstance(refresh, bool) or not isinstance(refresh, (int, np.integer)) or refresh < 1:
            raise QueryError(f"refresh={refresh!r} must be a whole number of readings ≥ 1")
        self.part = part
        self.tracks = tracks_for(part, spacing)
        self.sd_position = float(sd_position)
        self.sd_scale = float(sd_scale)
        self.sd_slope = float(sd_slope)
        self.shape_spacing = float(shape_spacing)
        self.prune = float(prune)
        self.refresh = int(refresh)
        # before the first reference hypothesis: the median radius over the stretches a jaw touches
        convex = self.tracks.kappa[self.tracks.convex]
        self._rho_prior = float(np.clip(np.median(1.0 / convex), 5.0, 500.0)) if convex.size else 50.0
        # basis columns: 0 the constant, then B-splines B_k(z) for knots over z in [-P, P]
        self._k0 = int(math.ceil(part.perimeter / shape_spacing)) + 3
        self._segments = 16                   # offsets: one per contact segment (see regrasp)
        self._m = self._segments + (2 * self._k0 + 4 if sd_slope > 0 else 0)
        self.radius = float(radius)
        self.mode_floor = float(mode_floor)
        self.confidence = float(confidence)
        self.index = np.arange(self.tracks.sigma.size)
        self.reset()

    @property
    def segment(self) -> int:
        """Index of the present contact segment (0, then one more per :meth:`regrasp`)."""
        return self._segment

    @property
    def grid(self) -> np.ndarray:
        """The hypotheses: starts of the rolling, mm."""
        return self.tracks.sigma

    def reset(self) -> None:
        """Back to the prior: every start the jaw can touch equally likely, nothing measured."""
        n = self.grid.size
        self.current = self.grid.copy()      # present contact of each hypothesis, mm (unwrapped)
        self.feasible = self.tracks.convex.copy()
        m = self._m
        self._up = np.zeros((m, n))           # Uᵀp per hypothesis (row 0: Σp)
        self._spp = np.zeros(n)
        self._szp = np.zeros(n)
        self._uz = np.zeros(m)                # Uᵀz
        self._uu = np.zeros((m, m))           # UᵀU
        self._szz = 0.0
        self._touched = {0}
        self._segment = 0
        self._live = self.feasible.copy()     # hypotheses still worth evaluating
        self._live_idx = np.flatnonzero(self._live)
        self._ref = None                      # the hypothesis whose radius scales the slope term
        self._version = 0                     # readings added (the log-likelihood cache's key)
        self._cached = None
        self._last_row = None
        self._add_row(0.0, np.zeros(n))       # the first reading: z_0 = 0, p_0 = 0
        self.steps = 0
        self.turn = 0.0
        self.arc = 0.0

    def update(self, arc: float, turn: float) -> None:
        """Take one reading.

        Parameters
        ----------
        arc : float, mm
            Cumulative *signed* arc the contact has travelled since the first reading
            (counter-clockwise positive): the sum of the steps' arcs, each signed by
            its rotation's direction.
        turn : float, rad
            Net jaw rotation since the first reading (counter-clockwise positive).
        """
        if not (math.isfinite(arc) and math.isfinite(turn)):
            raise QueryError(f"arc={arc!r} mm and turn={turn!r} rad must be finite")
        # only the hypotheses still in the running are moved and summed (the pruned ones are
        # never evaluated again)
        idx = self._live_idx
        current, ok = self.tracks.advance(idx, turn)
        if not ok.all():
            out = idx[~ok]
            self.feasible[out] = False
            self._live[out] = False
            self._live_idx = np.flatnonzero(self._live)
        p = np.where(ok, current - self.grid[idx], 0.0)
        self.current[idx] = np.where(ok, current, self.current[idx])
        z = float(arc)
        self._add_row(z, p, idx)
        self.steps += 1
        self.turn, self.arc = float(turn), z
        if self.steps % self.refresh == 0:
            self._ref = int(np.argmax(self.log_likelihood()))

    def regrasp(self, arc: float, turn: float) -> None:
        """The jaw was lifted and put back (e.g. slid along itself at the end of its span).

        The contact is where the net rotation ``turn`` (rad) puts it, but the next
        reading starts a new segment with its own unknown offset (the arc across the
        lift is not measured). ``arc`` (mm) is the cumulative arc to continue from:
        pass the last reading's, since the contact has not moved along the part. The
        new offset absorbs any error in it; it also places the reading on the slope
        error's basis, so it should be right to a few mm.
        """
        if self._segment + 1 >= self._segments:
            raise QueryError(f"more than {self._segments - 1} regrasps in one localization")
        self._segment += 1
        self.update(arc, turn)

    def _basis(self, z: float) -> tuple:
        """(columns, values) of the basis at cumulative arc z: the segment's offset and four cubic B-splines."""
        seg = np.array([self._segment])
        if self.sd_slope <= 0:
            return seg, np.array([1.0])
        x = z / self.shape_spacing
        i = math.floor(x)
        u = x - i
        vals = np.array([(1 - u) ** 3, 3 * u ** 3 - 6 * u ** 2 + 4, -3 * u ** 3 + 3 * u ** 2 + 3 * u + 1, u ** 3]) / 6
        cols = self._segments + self._k0 + i + np.arange(4)
        if cols[0] < self._segments or cols[-1] >= self._m:
            raise QueryError(f"arc={z!r} mm is more than a perimeter from the first reading")
        return np.concatenate([seg, cols]), np.concatenate([[1.0], vals * self._radius_here()])

    def _radius_here(self) -> float:
        """ρ̂, mm: the model's radius of curvature at the reference hypothesis' present contact
        (5 to 500 mm; the median convex radius before there is a reference)."""
        if self._ref is None:
            return self._rho_prior
        t = self.tracks
        k = t.kappa[int(np.rint(self.current[self._ref] / t.h)) % t.sigma.size]
        return float(np.clip(1.0 / k, 5.0, 500.0)) if k > 0 else 500.0

    def _add_row(self, z: float, p: np.ndarray, idx=None) -> None:
        """Add a reading z with the predictions p of the hypotheses ``idx`` (default: all)."""
        self._version += 1
        cols, vals = self._basis(z)
        self._last_row = (cols, vals)
        sel = slice(None) if idx is None else idx
        for c, v in zip(cols, vals):
            self._up[c, sel] += v * p
        self._touched.update(int(c) for c in cols)
        self._spp[sel] += p * p
        self._szp[sel] += z * p
        self._uz[cols] += vals * z
        self._uu[np.ix_(cols, cols)] += np.outer(vals, vals)
        self._szz += z * z

    def _solved(self) -> dict:
        """The marginalisation over the live hypotheses and their log-likelihoods, once per reading
        (cached: the reference refresh, :meth:`belief` and :meth:`shift` share it)."""
        if self._cached is None or self._cached["version"] != self._version:
            s = self._solve()
            s["version"] = self._version
            s["ll"] = self._log_likelihood(s)
            self._cached = s
        return self._cached

    def _solve(self) -> dict:
        """The closed-form marginalisation over the live hypotheses (see the module notes)."""
        cols = np.array(sorted(self._touched))
        s2 = self.sd_position ** 2
        prior = np.full(cols.size, self.sd_slope ** 2)
        prior[cols < self._segments] = 1e6              # the segments' offsets: flat
        g = self._uu[np.ix_(cols, cols)] + np.diag(s2 / prior)
        live = np.flatnonzero(self._live)
        v = self._up[np.ix_(cols, live)]                # (m, n_live)
        gi_v = np.linalg.solve(g, v)
        wz = self._uz[cols]
        gi_wz = np.linalg.solve(g, wz)
        qpp = (self._spp[live] - np.einsum("ij,ij->j", v, gi_v)) / s2
        qpz = (self._szp[live] - gi_wz @ v) / s2
        qzz = (self._szz - wz @ gi_wz) / s2
        return {"cols": cols, "g": g, "live": live, "gi_v": gi_v, "gi_wz": gi_wz, "qpp": qpp, "qpz": qpz,
                "qzz": qzz}

    def _log_likelihood(self, s: dict) -> np.ndarray:
        """Log-likelihood of each start from a :meth:`_solve`; prunes the hopeless ones."""
        live, qpp, qpz = s["live"], s["qpp"], s["qpz"]
        qrr = s["qzz"] - 2 * qpz + qpp
        t2 = self.sd_scale ** 2
        qpr = qpz - qpp
        ll_live = -0.5 * (qrr - t2 * qpr ** 2 / (1 + t2 * qpp) + np.log1p(t2 * qpp))
        ll = np.full(self.grid.size, -np.inf)
        ll[live] = ll_live
        if self.prune > 0 and live.size:
            # hypotheses this far below the best are dropped from later evaluations
            drop = live[ll_live < ll_live.max() - self.prune]
            if drop.size:
                self._live[drop] = False
                self._live_idx = np.flatnonzero(self._live)
        return ll

    def log_likelihood(self) -> np.ndarray:
        """Log-likelihood of each start (−inf where infeasible or pruned), up to a constant."""
        return self._solved()["ll"].copy()

    def shift(self) -> tuple:
        """How far the real present contact is from each hypothesis' nominal one, mm.

        The slope error η moves the contact for a given jaw angle by ρ·η along the part
        (module notes), so the readings' term ρ̂·η(z) at the last reading is also the
        present contact's offset from where the model puts it. Given the start it is
        Gaussian; with sd_slope = 0 it is zero.

        Returns
        -------
        mean, sd : ndarray, mm
            Over the grid (0 where infeasible or pruned).
        """
        s = self._solved()
        n = self.grid.size
        mean, sd = np.zeros(n), np.zeros(n)
        if self.sd_slope <= 0:
            return mean, sd
        cols, live = s["cols"], s["live"]
        a = np.zeros(cols.size)
        row_cols, row_vals = self._last_row
        a[np.searchsorted(cols, row_cols)] = row_vals
        a[cols < self._segments] = 0.0                  # the offset is the reading's, not the contact's
        t2 = self.sd_scale ** 2
        qpr = s["qpz"] - s["qpp"]
        d_mean = t2 * qpr / (1 + t2 * s["qpp"])         # the scale's posterior, b = 1 + δ
        d_var = t2 / (1 + t2 * s["qpp"])
        a_v = a @ s["gi_v"]
        mean[live] = a @ s["gi_wz"] - (1 + d_mean) * a_v
        var0 = self.sd_position ** 2 * float(a @ np.linalg.solve(s["g"], a))
        sd[live] = np.sqrt(var0 + d_var * a_v ** 2)
        return mean, sd

    def posterior(self) -> np.ndarray:
        """Posterior probability of each start (sums to 1).

        Computed once per reading (a check asks for it several times: the belief and the
        rolling procedure's look-ahead rules)."""
        s = self._solved()
        if "w" not in s:
            ll = s["ll"]
            top = ll.max()
            if not np.isfinite(top):
                raise QueryError("no start on the part fits the readings (all hypotheses ruled out)")
            w = np.exp(ll - top)
            s["w"] = w / w.sum()
        return s["w"].copy()

    def belief(self, radius: float | None = None) -> Belief:
        """The belief over the present contact (see :class:`Belief`)."""
        radius = self.radius if radius is None else float(radius)
        part = self.part
        w = self.posterior()
        mean, sd = self.shift()
        present = part.wrap_arc(self.current + mean)
        i = int(np.argmax(w))
        map_arc = float(present[i])
        # each start's present contact is N(nominal + shift, sd²): the mass within ±radius of the MAP
        sel = np.flatnonzero(w > 1e-12 * w[i])
        off, s = np.asarray(part.arc_offset(present[sel], map_arc)), sd[sel]
        spread = np.where(s > 0, s, 1.0)
        inside = np.where(s > 0, ndtr((radius - off) / spread) - ndtr((-radius - off) / spread),
                          np.abs(off) <= radius)
        mass = float(np.sum(w[sel] * inside))
        modes = self._modes(w, present, radius)
        prior = self.feasible.astype(float) if self.steps == 0 else self.tracks.convex.astype(float)
        prior /= prior.sum()
        # information gained: KL(posterior || prior) in nats; a flat posterior gains ~0
        nz = w > 0
        kl = float(np.sum(w[nz] * np.log(w[nz] / prior[nz])))
        informative = kl > 0.05
        strong = [m for m in modes if m.mass >= self.mode_floor]
        ambiguous = informative and len(strong) > 1 and modes[0].mass < self.confidence
        return Belief(map_arc=map_arc, mass=mass, radius=radius, modes=tuple(modes), ambiguous=ambiguous,
                      informative=informative, steps=self.steps)

    def _modes(self, w, present, radius) -> list:
        """Connected groups of probable present contacts, binned at ``radius``."""
        part = self.part
        nb = max(8, int(part.perimeter / radius))
        b = np.minimum((present / part.perimeter * nb).astype(int), nb - 1)
        mass = np.bincount(b, weights=w, minlength=nb)
        live = mass > 1e-4 * mass.max()
        if live.all():
            labels = np.zeros(nb, dtype=int)
        else:
            # label runs of live bins around the circle
            start = int(np.flatnonzero(~live)[0])
            order = (np.arange(nb) + start) % nb
            labels = np.full(nb, -1)
            label = -1
            prev = False
            for k in order:
                if live[k] and not prev:
                    label += 1
                if live[k]:
                    labels[k] = label
                prev = live[k]
        out = []
        for lab in range(labels.max() + 1):
            bins = labels == lab
            sel = bins[b]
            if not sel.any():
                continue
            k = int(np.argmax(np.where(sel, w, -1.0)))
            out.append(Mode(arc=float(present[k]), mass=float(mass[bins].sum()),
                            start_arc=float(self.grid[k])))
        out.sort(key=lambda m: -m.mass)
        return out


class ParticleFilter:
    """Conventional particle filter over the present contact (the peer baseline).

    Each particle carries the present contact x (mm), the arc P (mm) it has rolled
    since the first reading, and the first reading's error c (mm), so that the
    cumulative reading z_j ~ N(P_j + c, sd_position²) can be weighed directly (a
    filter on the step increments alone would treat the differences of
    neighbouring readings as independent and lose the total travel). Particles
    move by each measured rotation step along their convex stretch, with a small
    random walk, and are resampled systematically when the effective sample
    size drops below half. It models neither the calibration's scale nor the
    part's machining error.

    Parameters
    ----------
    part : Part
    particles : int
        Number of particles.
    sd_position : float, mm
        Standard deviation of one reading of the cumulative arc.
    process : float, mm
        Standard deviation of the random walk added to each particle per step.
    radius : float, mm
    seed : int
    """

    def __init__(self, part: Part, *, particles: int = 2000, sd_position: float = 0.04, process: float = 0.005,
                 radius: float = 0.3, seed: int = 0, spacing: float = 0.02):
        if particles < 2:
            raise QueryError(f"particles={particles!r} must be at least 2")
        for name, value in (("sd_position", sd_position), ("radius", radius)):
            if not (math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} mm must be a positive number")
        if not (math.isfinite(process) and process >= 0):
            raise QueryError(f"process={process!r} mm must be ≥ 0")
        self.part = part
        self.tracks = tracks_for(part, spacing)
        self.n = int(particles)
        self.sd_position = float(sd_position)
        self.process = float(process)
        self.radius = float(radius)
        self.rng = np.random.default_rng(seed)
        self.reset()

    def reset(self) -> None:
        """Particles drawn uniformly over the stretches the jaw can touch."""
        convex = np.flatnonzero(self.tracks.convex)
        pick = self.rng.choice(convex, size=self.n)
        self.x = self.tracks.sigma[pick] + self.rng.uniform(0, self.tracks.h, size=self.n)
        self.rolled = np.zeros(self.n)
        self.offset = self.sd_position * self.rng.standard_normal(self.n)
        self.w = np.full(self.n, 1.0 / self.n)
        self._turn = 0.0
        self.steps = 0

    def _advance(self, x, turn):
        """Move particles at arc x by a rotation ``turn`` along their convex stretch."""
        t = self.tracks
        i = np.minimum(np.rint(np.mod(x, self.part.perimeter) / t.h).astype(int), t.sigma.size - 1)
        moved, ok = t.advance(i, turn)
        return moved - t.sigma[i], ok

    def update(self, arc: float, turn: float) -> None:
        """Take one reading: cumulative signed arc (mm) and net rotation (rad), as ContactFilter."""
        if not (math.isfinite(arc) and math.isfinite(turn)):
            raise QueryError(f"arc={arc!r} mm and turn={turn!r} rad must be finite")
        d_turn = turn - self._turn
        self._turn = float(turn)
        step, ok = self._advance(self.x, d_turn)
        step = np.where(ok, step, 0.0)
        jitter = self.process * self.rng.standard_normal(self.n)
        self.x = np.mod(self.x + step + jitter, self.part.perimeter)
        self.rolled = self.rolled + step + jitter
        like = np.exp(-0.5 * ((arc - self.rolled - self.offset) / self.sd_position) ** 2) * ok
        w = self.w * like
        total = w.sum()
        self.steps += 1
        if not total > 0:  # every particle ruled out: keep the prior weights (a known PF failure)
            return
        self.w = w / total
        if 1.0 / np.sum(self.w ** 2) < self.n / 2:
            u = (self.rng.random() + np.arange(self.n)) / self.n
            idx = np.minimum(np.searchsorted(np.cumsum(self.w), u), self.n - 1)
            self.x, self.rolled, self.offset = self.x[idx], self.rolled[idx], self.offset[idx]
            self.w = np.full(self.n, 1.0 / self.n)

    def estimate(self) -> tuple:
        """(most probable present contact mm, probability within the radius of it).

        The estimate is the particle with the most weight within ``radius`` around it.
        """
        part = self.part
        order = np.argsort(self.x)
        xs, ws = self.x[order], self.w[order]
        # weight within ±radius of every particle, by a cumulative sum over a doubled circle
        xx = np.concatenate([xs, xs + part.perimeter])
        cw = np.concatenate([[0.0], np.cumsum(np.concatenate([ws, ws]))])
        lo = np.searchsorted(xx, xs - self.radius + part.perimeter, side="left")
        hi = np.searchsorted(xx, xs + self.radius + part.perimeter, side="right")
        mass = cw[hi] - cw[lo]
        k = int(np.argmax(mass))
        return float(xs[k]), float(mass[k])
