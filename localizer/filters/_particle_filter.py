"""The conventional peer method, a particle filter over the present contact.

**ParticleFilter** is the conventional peer method: particles over the present
contact, moved by each measured rotation step with a small process noise,
weighted by each step's measured arc increment, resampled systematically when
the effective sample size drops below half.
"""

from __future__ import annotations

import math

import numpy as np

from .._defaults import SUCCESS_RADIUS
from .._errors import QueryError
from .._types import BoolArray, FloatArray
from ..contact import tracks_for
from ..geometry import MAX_GRID_POINTS, Boundary

__all__ = ["ParticleFilter"]


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
    part : Part or Outline
    particles : int
        Number of particles.
    sd_position : float, mm
        Standard deviation of one reading of the cumulative arc.
    process : float, mm
        Standard deviation of the random walk added to each particle per step.
    radius : float, mm
        The belief's success radius (:data:`localizer.SUCCESS_RADIUS`).
    seed : int
        Seeds the particles' draws and random walk.
    spacing : float, mm
        Grid step of the tracks the particles are moved along (:func:`localizer.tracks_for`).
    """

    def __init__(
        self,
        part: Boundary,
        *,
        particles: int = 2000,
        sd_position: float = 0.04,
        process: float = 0.005,
        radius: float = SUCCESS_RADIUS,
        seed: int = 0,
        spacing: float = 0.02,
    ) -> None:
        if not (isinstance(particles, (int, np.integer)) and 2 <= particles <= MAX_GRID_POINTS):
            raise QueryError(
                f"particles={particles!r} must be a whole number from 2 to {MAX_GRID_POINTS} (as many as the "
                "largest per-part grid; the default 2000 is the conventional peer's setting)"
            )
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

    def _advance(self, x: FloatArray, turn: float) -> tuple[FloatArray, BoolArray]:
        """Move particles at arc x by a rotation ``turn`` along their convex stretch."""
        t = self.tracks
        i = t.node_at(x)
        moved, ok = t.roll(i, turn)
        return moved - t.sigma[i], ok

    def update(self, arc: float, turn: float) -> None:
        """Take one reading: cumulative signed ``arc`` (mm) and net rotation ``turn`` (rad), as
        :meth:`localizer.ContactFilter.update`."""
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
        if 1.0 / np.sum(self.w**2) < self.n / 2:
            u = (self.rng.random() + np.arange(self.n)) / self.n
            idx = np.minimum(np.searchsorted(np.cumsum(self.w), u), self.n - 1)
            self.x, self.rolled, self.offset = self.x[idx], self.rolled[idx], self.offset[idx]
            self.w = np.full(self.n, 1.0 / self.n)

    def estimate(self) -> tuple[float, float]:
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
