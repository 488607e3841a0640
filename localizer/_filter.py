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

    z_j = c + b·p_j(σ₀) + e_j,   e_j ~ N(0, sd_position²) independent,

where c absorbs the noise of the first reading (flat prior) and b is the
calibration's scale (b ~ N(1, sd_scale²)). Both are integrated out in closed
form, so the log-likelihood of each hypothesis is a function of six running
sums, and one step costs a few vector operations on the grid. The rotations
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

from ._errors import QueryError
from ._part import Part

__all__ = ["ContactFilter", "ParticleFilter", "Belief", "Mode", "ModeTracks"]


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


class ModeTracks:
    """Where each of a set of hypotheses' contacts goes under further rotation (for planning)."""

    def __init__(self, part: Part, spacing: float):
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
        self.convex = rising[a][self._run] & (kappa > 0)

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
    radius : float, mm
        Success radius of :meth:`belief`.
    mode_floor : float
        Probability a mode needs to count in ``ambiguous``.

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

    def __init__(self, part: Part, *, spacing: float = 0.02, sd_position: float = 0.05, sd_scale: float = 0.02,
                 radius: float = 0.3, mode_floor: float = 0.05, confidence: float = 0.95):
        for name, value in (("spacing", spacing), ("sd_position", sd_position), ("radius", radius)):
            if not (math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} mm must be a positive number")
        if not (math.isfinite(sd_scale) and sd_scale >= 0):
            raise QueryError(f"sd_scale={sd_scale!r} must be ≥ 0")
        if not 0 < confidence < 1:
            raise QueryError(f"confidence={confidence!r} must be in (0, 1)")
        self.part = part
        self.tracks = ModeTracks(part, spacing)
        self.sd_position = float(sd_position)
        self.sd_scale = float(sd_scale)
        self.radius = float(radius)
        self.mode_floor = float(mode_floor)
        self.confidence = float(confidence)
        self.index = np.arange(self.tracks.sigma.size)
        self.reset()

    @property
    def grid(self) -> np.ndarray:
        """The hypotheses: starts of the rolling, mm."""
        return self.tracks.sigma

    def reset(self) -> None:
        """Back to the prior: every start the jaw can touch equally likely, nothing measured."""
        n = self.grid.size
        self.current = self.grid.copy()      # present contact of each hypothesis, mm (unwrapped)
        self.feasible = self.tracks.convex.copy()
        self._sp = np.zeros(n)
        self._spp = np.zeros(n)
        self._szp = np.zeros(n)
        self._sz = self._szz = 0.0
        self._n = 1                           # the first reading: z_0 = 0, p_0 = 0
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
        current, ok = self.tracks.advance(self.index, turn)
        self.feasible &= ok
        p = np.where(ok, current - self.grid, 0.0)
        self.current = np.where(ok, current, self.current)
        z = float(arc)
        self._sp += p
        self._spp += p * p
        self._szp += z * p
        self._sz += z
        self._szz += z * z
        self._n += 1
        self.steps += 1
        self.turn, self.arc = float(turn), z

    def log_likelihood(self) -> np.ndarray:
        """Log-likelihood of each start (−inf where infeasible), up to a constant."""
        n = self._n
        spp = self._spp - self._sp ** 2 / n
        szp = self._szp - self._sz * self._sp / n
        szz = self._szz - self._sz ** 2 / n
        srr = szz - 2 * szp + spp
        srp = szp - spp
        s2, t2 = self.sd_position ** 2, self.sd_scale ** 2
        quad = (srr - t2 * srp ** 2 / (s2 + t2 * spp)) / s2
        ll = -0.5 * (quad + np.log1p(t2 * spp / s2))
        return np.where(self.feasible, ll, -np.inf)

    def posterior(self) -> np.ndarray:
        """Posterior probability of each start (sums to 1)."""
        ll = self.log_likelihood()
        top = ll.max()
        if not np.isfinite(top):
            raise QueryError("no start on the part fits the readings (all hypotheses ruled out)")
        w = np.exp(ll - top)
        return w / w.sum()

    def belief(self, radius: float | None = None) -> Belief:
        """The belief over the present contact (see :class:`Belief`)."""
        radius = self.radius if radius is None else float(radius)
        part = self.part
        w = self.posterior()
        present = part.wrap_arc(self.current)
        i = int(np.argmax(w))
        map_arc = float(present[i])
        mass = float(w[np.abs(part.arc_offset(present, map_arc)) <= radius].sum())
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

    Parameters
    ----------
    part : Part
    particles : int
        Number of particles.
    sd_step : float, mm
        Standard deviation of one step's measured arc increment (a difference of two
        readings: about √2 times one reading's).
    process : float, mm
        Standard deviation of the random walk added to each particle per step.
    radius : float, mm
    seed : int
    """

    def __init__(self, part: Part, *, particles: int = 2000, sd_step: float = 0.07, process: float = 0.005,
                 radius: float = 0.3, seed: int = 0, spacing: float = 0.02):
        if particles < 2:
            raise QueryError(f"particles={particles!r} must be at least 2")
        for name, value in (("sd_step", sd_step), ("radius", radius)):
            if not (math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} mm must be a positive number")
        self.part = part
        self.tracks = ModeTracks(part, spacing)
        self.n = int(particles)
        self.sd_step = float(sd_step)
        self.process = float(process)
        self.radius = float(radius)
        self.rng = np.random.default_rng(seed)
        self.reset()

    def reset(self) -> None:
        """Particles drawn uniformly over the stretches the jaw can touch."""
        convex = np.flatnonzero(self.tracks.convex)
        pick = self.rng.choice(convex, size=self.n)
        self.x = self.tracks.sigma[pick] + self.rng.uniform(0, self.tracks.h, size=self.n)
        self.w = np.full(self.n, 1.0 / self.n)
        self._arc = 0.0
        self._turn = 0.0
        self.steps = 0

    def _advance(self, x, turn):
        """Move particles at arc x by a rotation ``turn`` along their convex stretch."""
        t = self.tracks
        f = (np.mod(x, self.part.perimeter) / t.h)
        i = np.minimum(f.astype(int), t.sigma.size - 1)
        frac = f - i
        moved, ok = t.advance(i, turn)
        return moved + frac * t.h, ok

    def update(self, arc: float, turn: float) -> None:
        """Take one reading: cumulative signed arc (mm) and net rotation (rad), as ContactFilter."""
        if not (math.isfinite(arc) and math.isfinite(turn)):
            raise QueryError(f"arc={arc!r} mm and turn={turn!r} rad must be finite")
        d_arc, d_turn = arc - self._arc, turn - self._turn
        self._arc, self._turn = float(arc), float(turn)
        new, ok = self._advance(self.x, d_turn)
        new = np.where(ok, new, self.x)
        moved = new - self.x
        new = new + self.process * self.rng.standard_normal(self.n)
        like = np.exp(-0.5 * ((d_arc - moved) / self.sd_step) ** 2) * ok
        w = self.w * like
        total = w.sum()
        if not total > 0:  # every particle ruled out: start afresh from the prior (a known PF failure)
            self.reset()
            self._arc, self._turn = float(arc), float(turn)
            return
        self.x = np.mod(new, self.part.perimeter)
        self.w = w / total
        self.steps += 1
        if 1.0 / np.sum(self.w ** 2) < self.n / 2:
            u = (self.rng.random() + np.arange(self.n)) / self.n
            idx = np.minimum(np.searchsorted(np.cumsum(self.w), u), self.n - 1)
            self.x = self.x[idx]
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
