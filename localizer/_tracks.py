"""Where each start's contact goes as the jaw turns, and where the jaw reaches: the tables a
sequential filter moves its hypotheses with, built once per part."""

from __future__ import annotations

import math

import numpy as np

from ._cache import per_part
from ._part import Part
from ._reach import DEFAULT_JAW, StraightJaw, reach_for
from ._types import ArrayLike, BoolArray, FloatArray, IntArray

__all__ = ["ModeTracks", "tracks_for"]


def tracks_for(part: Part, spacing: float, jaw: StraightJaw = DEFAULT_JAW) -> ModeTracks:
    """The ``part``'s :class:`ModeTracks` at ``spacing`` mm for ``jaw``, built once per part, spacing and jaw.

    Building them takes most of a second (the dense sample, the jaw's reach, the banded
    tangent-angle table); a Monte Carlo trial makes a grid filter and a particle filter on
    the same part. The tables are read-only, so the filters can share them.
    """
    return per_part("tracks", part, (float(spacing), jaw), lambda: ModeTracks(part, spacing, jaw))


class ModeTracks:
    """Where each of a set of hypotheses' contacts goes under further rotation, and where the jaw reaches.

    Attributes
    ----------
    sigma, theta, kappa : ndarray, shape (n,)
        The grid's arc positions (mm), unwrapped tangent angles (rad) and curvatures (1/mm).
    lo, hi : ndarray, shape (n,), mm
        The jaw positions at which the jaw can touch each grid point (:class:`localizer.Reach`).
    touchable : ndarray of bool
        The jaw touches the point at some place along it.
    convex : ndarray of bool
        Where a rolling can be: a convex stretch (θ rising, κ > 0) the jaw touches.

    Parameters
    ----------
    part : Part
    spacing : float, mm
        Grid step (at least 64 points over the perimeter).
    jaw : StraightJaw
        The jaw whose reach is tabulated.
    """

    def __init__(self, part: Part, spacing: float, jaw: StraightJaw = DEFAULT_JAW) -> None:
        self.part = part
        self.jaw = jaw
        p = part.perimeter
        n = max(64, int(math.ceil(p / spacing)))
        self.h = p / n
        # typed float64 (np.asarray is a no-op here: the product is float64 already)
        sigma: FloatArray = np.asarray(np.arange(n) * self.h, dtype=float)
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
            pieces_s.append(arcs[lo : hi + 1])
            vals = th[lo : hi + 1] if rising[lo] else np.full(hi + 1 - lo, th[lo])
            pieces_b.append(vals + r * span)
            at += hi + 1 - lo
        self._s = np.concatenate(pieces_s)
        self._banded = np.concatenate(pieces_b)
        self._first = np.array(offsets)
        self._last = np.array(offsets) + (b - a)
        self._span = span
        run_of_cell = np.repeat(np.arange(a.size), b - a)
        self._run = run_of_cell[np.arange(n) + n]
        # where the jaw reaches, from its geometry (localizer._reach): no fixed tolerance below the hull
        self.reach = reach_for(part, jaw)
        self.lo, self.hi = (np.array(v) for v in self.reach.interval(sigma))
        self.lo_sure, self.hi_sure = (np.array(v) for v in self.reach.interval(sigma, sure=True))
        self.touchable = np.maximum(self.lo, -jaw.half) < np.minimum(self.hi, jaw.half)
        self.convex: BoolArray = rising[a][self._run] & (kappa > 0) & self.touchable
        for arr in (
            self.sigma,
            self.theta,
            self.kappa,
            self.lo,
            self.hi,
            self.lo_sure,
            self.hi_sure,
            self.touchable,
            self.convex,
            self._s,
            self._banded,
            self._first,
            self._last,
            self._run,
        ):
            arr.setflags(write=False)

    def advance(
        self, index: IntArray, turn: FloatArray | float, *, turn_margin: float = 0.0
    ) -> tuple[FloatArray, BoolArray]:
        """Arc positions after a net rotation ``turn`` (rad) of the grid points ``index``, along their
        convex stretches (no check of where the jaw reaches: :meth:`touches`, :meth:`roll`).

        Parameters
        ----------
        index : array of int
            Grid points the rotation starts from.
        turn : float or array, rad
            Net rotation from there (counter-clockwise positive).
        turn_margin : float, rad
            A rotation up to this far past the end of the point's convex stretch keeps the
            contact at the end (the real part's slope differs from the model's near an
            inflection) instead of ruling the point out.

        Returns
        -------
        arc : ndarray, mm
            Unwrapped; ``nan`` where the rotation leaves the point's convex stretch.
        ok : ndarray of bool
        """
        idx = np.asarray(index)
        run = self._run[idx]
        target = self.theta[idx] + turn + run * self._span
        first, last = self._first[run], self._last[run]
        lo_b, hi_b = self._banded[first], self._banded[last]
        ok = self.convex[idx] & (target >= lo_b - turn_margin) & (target <= hi_b + turn_margin)
        target = np.clip(target, lo_b, hi_b)
        j = np.clip(np.searchsorted(self._banded, target, side="left"), first + 1, last)
        b0, b1 = self._banded[j - 1], self._banded[j]
        w = (target - b0) / np.where(b1 > b0, b1 - b0, 1.0)
        arc = self._s[j - 1] + w * (self._s[j] - self._s[j - 1])
        return np.where(ok, arc, np.nan), ok

    def touches(
        self, arc: ArrayLike, jaw: ArrayLike | None = None, margin: float = 0.0, sure: bool = False
    ) -> BoolArray:
        """Whether the jaw can touch at arc positions ``arc`` (mm, unwrapped; nan: no) with the contact
        at jaw position(s) ``jaw`` (mm; None: at some place on the jaw), within ``margin`` mm (negative:
        with that much to spare). ``sure`` takes the reach's sure interval (:meth:`Reach.interval`)."""
        arc = np.asarray(arc, dtype=float)
        finite = np.isfinite(arc)
        land = np.mod(np.rint(np.where(finite, arc, 0.0) / self.h).astype(np.int64), self.sigma.size)
        if jaw is None:
            somewhere: BoolArray = finite & self.touchable[land]
            return somewhere
        lo, hi = (self.lo_sure, self.hi_sure) if sure else (self.lo, self.hi)
        d = np.asarray(jaw, dtype=float)
        there: BoolArray = (
            finite & (lo[land] - margin < d) & (d < hi[land] + margin) & (np.abs(d) <= self.jaw.half + margin)
        )
        return there

    def roll(
        self,
        index: IntArray,
        turn: FloatArray | float,
        *,
        jaw: ArrayLike | None = None,
        at: ArrayLike | None = None,
        margin: float = 0.0,
        turn_margin: float = 0.0,
    ) -> tuple[FloatArray, BoolArray]:
        """:meth:`advance` the hypotheses ``index`` (grid indices) by net rotation ``turn`` (rad, at most
        ``turn_margin`` rad past a convex stretch's end), and the landing must be touchable.

        ``jaw`` (mm) is the contact's place on the jaw at arc ``at`` (mm, default the grid
        points): the landing's place is taken as that plus the arc rolled (the contact moves
        as far along the jaw as along the part, to first order in the step), within
        ``margin`` mm. Without ``jaw`` the landing must be touchable at some place on the jaw.
        Returns (arc mm, nan where not; ok).
        """
        arc, ok = self.advance(index, turn, turn_margin=turn_margin)
        if jaw is not None:
            base = self.sigma[np.asarray(index)] if at is None else np.asarray(at, dtype=float)
            jaw = np.asarray(jaw, dtype=float) + (arc - base)
        ok = ok & self.touches(arc, jaw, margin)
        return np.where(ok, arc, np.nan), ok

    def rollable(self, turns: ArrayLike, jaw: float, margin: float = 0.0) -> BoolArray:
        """Grid points from which the jaw, laid with the contact at ``jaw`` (mm on it), can roll through
        every net rotation of ``turns`` (rad, in order, one sign) without bridging, with ``margin``
        mm to spare on the jaw all along (boolean mask over the grid)."""
        ok: BoolArray = self.convex & self.touches(self.sigma, jaw, -margin, sure=True)
        for t in np.atleast_1d(np.asarray(turns, dtype=float)):
            idx = np.flatnonzero(ok)
            arc, moved = self.advance(idx, float(t))
            ok[idx] = moved & self.touches(arc, jaw + (arc - self.sigma[idx]), -margin, sure=True)
        return ok
