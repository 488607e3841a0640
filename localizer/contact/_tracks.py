"""Where each start's contact goes as the jaw turns, and where the jaw reaches: the tables a
sequential filter moves its hypotheses with, built once per part."""

from __future__ import annotations

import math

import numpy as np

from .._types import ArrayLike, BoolArray, FloatArray, IntArray
from ..geometry import Boundary, check_grid, mod_period, per_part
from ._reach import DEFAULT_JAW, StraightJaw, reach_for
from ._tracks_kernels import step_along

__all__ = ["ModeTracks", "tracks_for", "PIVOT_SPREAD", "PIVOT_KAPPA", "BRIDGE_EXCESS"]

#: How far, mm of the rolling coordinate per radian of jump, a convex corner is spread in the filter's
#: grid: at the grid's 0.02 mm, one start per 0.2° of jaw angle at the corner.
PIVOT_SPREAD = 0.02 / math.radians(0.2)
#: The curvature tabulated on a pivot, 1/mm: the contact stays at the corner as the jaw turns
#: (a radius of 1 µm, finite so that the error terms' ρ stay numbers).
PIVOT_KAPPA = 1e3
#: A net rotation this small, rad, is none (the rounding of a pose's angle after turning back): the
#: contact is where the rolling started, even on a flat face, where the angle does not place it.
NO_TURN = 1e-9
#: A jaw within this of a face's angle, rad, lies flush on it (a millimetre of the jaw then deviates
#: from the face by a nanometre; :data:`sim2d` shares the contact's flush depth of 1 µm).
FLUSH_TURN = 1e-6
#: A concavity the straight jaw bridges without the contact leaving a convex stretch for good (a
#: spline's wiggle along a straight stroke, 1–3 mm wide and microns deep) belongs to the convex
#: stretch around it when the arc it skips is at most this much longer than the jaw's chord across
#: it, mm: the rolling then reads the chord where the model counts the arc, an error a tenth of the
#: ``paper`` preset's reading noise (0.1 mm). Deeper ones stay ends of their stretches (the rig
#: reports their jump as a bridge, or a start rolled into one is ruled out).
BRIDGE_EXCESS = 0.01


def tracks_for(part: Boundary, spacing: float, jaw: StraightJaw = DEFAULT_JAW) -> ModeTracks:
    """The ``part``'s :class:`ModeTracks` at ``spacing`` mm for ``jaw``, built once per part, spacing and jaw.

    Building them takes most of a second (the dense sample, the jaw's reach, the banded
    tangent-angle table); a Monte Carlo trial makes a grid filter and a particle filter on
    the same part. The tables are read-only, so the filters can share them.
    """
    return per_part("tracks", part, (float(spacing), jaw), lambda: ModeTracks(part, spacing, jaw))


def grid_size(part: Boundary, spacing: float) -> int:
    """How many points :class:`ModeTracks` lays over ``part`` at ``spacing`` mm: the perimeter and each
    convex corner's :data:`PIVOT_SPREAD`, at least 64 (known before anything is built)."""
    spread = np.array([PIVOT_SPREAD * c.angle for c in part.corners if c.angle > 0])
    return max(64, int(math.ceil((part.perimeter + float(spread.sum())) / spacing)))


class ModeTracks:
    """Where each of a set of hypotheses' contacts goes under further rotation, and where the jaw reaches.

    Attributes
    ----------
    sigma, theta, kappa : ndarray, shape (n,)
        The grid's arc positions (mm), unwrapped tangent angles (rad) and curvatures (1/mm). The
        grid is uniform in the rolling coordinate (step ``h``, mm): the arc itself on a smooth
        boundary; on an outline each convex corner is also spread over :data:`PIVOT_SPREAD` mm per
        radian, its points all at the corner's arc, one per jaw angle within the jump.
    lo, hi : ndarray, shape (n,), mm
        The jaw positions at which the jaw can touch each grid point (:class:`localizer.Reach`).
    touchable : ndarray of bool
        The jaw touches the point at some place along it.
    convex : ndarray of bool
        Where a rolling can be: a convex stretch (θ not falling, κ ≥ 0: a flat face of an outline
        belongs to the stretch around it) the jaw touches.
    pivot : ndarray of bool
        The grid points on a convex corner (one per jaw angle within its jump).
    has_faces : bool
        Some start lies on a flat face, which the jaw crosses in one step (a spline has none).
    bridges : int
        How many shallow concavities (:data:`BRIDGE_EXCESS`) the table carries the contact across
        in one step, like a face; the rolling reads a jump there.

    Parameters
    ----------
    part : Part or Outline
    spacing : float, mm
        Grid step (at least 64 points over the perimeter).
    jaw : StraightJaw
        The jaw whose reach is tabulated.
    """

    def __init__(self, part: Boundary, spacing: float, jaw: StraightJaw = DEFAULT_JAW) -> None:
        check_grid(part, "rolling tracks", spacing, grid_size(part, spacing))
        self.part = part
        self.jaw = jaw
        p = part.perimeter
        # a convex corner is a pivot: the contact stays while the jaw turns through the jump. The grid
        # runs over the rolling coordinate u, the arc with each convex corner spread over
        # PIVOT_SPREAD mm per radian of its jump, so that the starts at a corner (one per jaw angle)
        # are hypotheses like any other; sigma, theta and kappa are tabulated over it
        pivots = [c for c in part.corners if c.angle > 0]
        spread = np.array([PIVOT_SPREAD * c.angle for c in pivots])
        total = p + float(spread.sum())
        n = max(64, int(math.ceil(total / spacing)))
        self.h = total / n
        self._uniform = not pivots
        u = np.arange(n) * self.h
        if pivots:
            corner_arc = np.array([c.arc for c in pivots])
            u_begin = corner_arc + np.concatenate([[0.0], np.cumsum(spread)[:-1]])  # where each pivot starts in u
            k = np.searchsorted(u_begin, u, side="right") - 1  # the last pivot begun (-1: none)
            within = (k >= 0) & (u < u_begin[np.maximum(k, 0)] + spread[np.maximum(k, 0)])
            passed = np.where(k >= 0, np.cumsum(spread)[np.maximum(k, 0)], 0.0)  # spread fully behind u
            sigma = np.where(within, corner_arc[np.maximum(k, 0)], u - passed)
            theta = np.asarray(part.tangent_angle_at_arc(sigma), dtype=float)
            kappa = np.asarray(part.curvature_at_arc(sigma), dtype=float)
            # on a pivot: from the angle before the jump to the angle after it; the contact does not
            # move with the angle (ρ = 0)
            kk = np.maximum(k, 0)
            frac = np.where(within, (u - u_begin[kk]) / spread[kk], 1.0)
            jump = np.array([c.angle for c in pivots])[kk]
            theta = np.where(within, theta - (1.0 - frac) * jump, theta)
            kappa = np.where(within, PIVOT_KAPPA, kappa)
        else:
            within = np.zeros(n, dtype=bool)
            sigma = u
            theta = np.asarray(part.tangent_angle_at_arc(sigma), dtype=float)
            kappa = np.asarray(part.curvature_at_arc(sigma), dtype=float)
        sigma = np.asarray(sigma, dtype=float)
        self.sigma, self.theta, self.kappa = sigma, theta, kappa
        self.pivot: BoolArray = within
        # a shallow concavity the jaw bridges: its stretch rolls at the bridging chord's angle, which
        # the table holds like a flat face's (the contact jumps across at that angle)
        rolled, skipped, self.bridges = _bridge_shallow_dips(part, sigma, theta, jaw.length)
        # three laps so that any rotation of less than a lap stays on the table
        turn = 2.0 * math.pi
        arcs = np.concatenate([sigma - p, sigma, sigma + p, [2 * p]])
        th = np.concatenate([rolled - turn, rolled, rolled + turn, [rolled[0] + 2 * turn]])
        # a flat face (θ constant) belongs to the convex stretch around it: the jaw passes it flush,
        # at one angle, and the contact jumps from one end to the other
        rising = np.diff(th) >= 0
        # runs of cells with rising θ (convex stretches) or not; run r spans nodes a_r..b_r
        change = np.flatnonzero(np.diff(rising.astype(np.int8)) != 0) + 1
        a = np.concatenate([[0], change])
        b = np.concatenate([change, [rising.size]])
        span = float(th.max() - th.min()) + 1.0
        # each run's nodes, its θ shifted into a band of its own (flat on falling runs), concatenated:
        # one searchsorted then serves every run
        pieces_s, pieces_b, pieces_n, offsets = [], [], [], []
        nodes = np.concatenate([np.arange(n)] * 3 + [[0]])
        at = 0
        for r, (lo, hi) in enumerate(zip(a, b)):
            offsets.append(at)
            pieces_s.append(arcs[lo : hi + 1])
            pieces_n.append(nodes[lo : hi + 1])
            vals = th[lo : hi + 1] if rising[lo] else np.full(hi + 1 - lo, th[lo])
            pieces_b.append(vals + r * span)
            at += hi + 1 - lo
        self._s = np.concatenate(pieces_s)
        self._node = np.concatenate(pieces_n)
        # flat faces on the convex stretches: runs of equal angle along rising arc, (first, last) arc
        band = np.concatenate(pieces_b)
        convex_entry = np.concatenate([np.full(hi + 1 - lo, bool(rising[lo])) for lo, hi in zip(a, b)])
        same = (np.diff(band) == 0) & (np.diff(self._s) > 0) & convex_entry[1:] & convex_entry[:-1]
        self._face_a = np.full(band.size, np.nan)
        self._face_b = np.full(band.size, np.nan)
        edges = np.flatnonzero(np.diff(np.concatenate([[0], same.astype(np.int8), [0]])))
        for f0, f1 in zip(edges[::2], edges[1::2]):  # cells f0..f1-1: entries f0..f1
            self._face_a[f0 : f1 + 1] = self._s[f0]
            self._face_b[f0 : f1 + 1] = self._s[f1]
        self._banded = np.concatenate(pieces_b)
        self._first = np.array(offsets)
        self._last = np.array(offsets) + (b - a)
        self._span = span
        run_of_cell = np.repeat(np.arange(a.size), b - a)
        self._run = run_of_cell[np.arange(n) + n]
        self._entry = self._first[self._run] + (np.arange(n) + n - a[self._run])  # each grid point's own
        # where the jaw reaches, from its geometry (localizer.contact._reach): no fixed tolerance below the hull
        self.reach = reach_for(part, jaw)
        self.lo, self.hi = (np.array(v) for v in self.reach.interval(sigma))
        self.lo_sure, self.hi_sure = (np.array(v) for v in self.reach.interval(sigma, sure=True))
        if pivots:
            # on a pivot the jaw lies at the start's own angle, not along the tangent after the corner
            on = np.flatnonzero(within)
            self.lo[on], self.hi[on], self.lo_sure[on], self.hi_sure[on] = self.reach.at_angle(sigma[on], theta[on])
        self.touchable = np.maximum(self.lo, -jaw.half) < np.minimum(self.hi, jaw.half)
        # a start on a flat face (κ = 0 within a convex stretch) is where the jaw lay flush: the wrist
        # read the centre of pressure there, and the first turn takes the contact to the face's end
        # (a start within a bridged dip, or beside it where the jaw along the tangent would cut the
        # far side, is not one the rolling model follows)
        self.convex: BoolArray = rising[a][self._run] & (kappa >= 0) & self.touchable & ~skipped
        self.has_faces = bool(np.any(self.convex & (kappa == 0)))
        for arr in (
            self.sigma,
            self.theta,
            self.kappa,
            self.pivot,
            self.lo,
            self.hi,
            self.lo_sure,
            self.hi_sure,
            self.touchable,
            self.convex,
            self._s,
            self._node,
            self._face_a,
            self._face_b,
            self._banded,
            self._first,
            self._last,
            self._run,
            self._entry,
        ):
            arr.setflags(write=False)

    def node_at(self, arc: ArrayLike) -> IntArray:
        """The grid point nearest arc position(s) ``arc`` (mm, unwrapped; at a pivot, its first)."""
        a = np.asarray(arc, dtype=float)
        if self._uniform:
            uniform: IntArray = np.mod(np.rint(a / self.h).astype(np.int64), self.sigma.size)
            return uniform
        p = self.part.perimeter
        w = mod_period(a, p)
        j = np.clip(np.searchsorted(self.sigma, w), 1, self.sigma.size - 1)
        nearer_left = (w - self.sigma[j - 1]) <= (self.sigma[j] - w)
        node: IntArray = np.where(nearer_left, j - 1, j)
        # the last node is nearer to the lap's end than to its predecessor: it may be the first
        wrap = (p - w) < np.abs(w - self.sigma[node])
        result: IntArray = np.where(wrap, 0, node)
        return result

    def landing_hints(self) -> IntArray:
        """A fresh :meth:`step` ``hint``: each grid point's own entry in the angle table."""
        out: IntArray = self._entry.copy()
        return out

    def advance(
        self, index: IntArray, turn: FloatArray | float, *, turn_margin: float = 0.0
    ) -> tuple[FloatArray, BoolArray]:
        """(arc, ok) of :meth:`step` for the grid points ``index``, net rotation ``turn`` (rad) and
        ``turn_margin`` (rad)."""
        arc, _, ok = self.step(index, turn, turn_margin=turn_margin)
        return arc, ok

    def step(
        self,
        index: IntArray,
        turn: FloatArray | float,
        *,
        turn_margin: float = 0.0,
        jaw: float | None = None,
        at: ArrayLike | None = None,
        hint: IntArray | None = None,
    ) -> tuple[FloatArray, IntArray, BoolArray]:
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
        jaw, at : float and array, mm
            Where the contact was on the jaw, at arc positions ``at`` (unwrapped): a turn that
            lays the jaw flush on a face (within :data:`FLUSH_TURN` of its angle) puts the contact
            at the middle of the face's stretch under the jaw, the centre of pressure of a line
            contact (without them, at the face's start).
        hint : ndarray of int over the grid, optional
            Where the search for each point's landing in the angle table starts (from
            :meth:`landing_hints`), updated in place with the landings found: a caller stepping the
            same points by a growing turn searches a few entries from the last landing instead of
            from the start. The landings do not depend on it.

        Returns
        -------
        arc : ndarray, mm
            Unwrapped; ``nan`` where the rotation leaves the point's convex stretch.
        node : ndarray of int
            The grid point nearest the landing in the rolling coordinate: on a pivot, the one of
            the jaw's angle (where the arc alone names the corner's first).
        ok : ndarray of bool
        """
        idx = np.asarray(index)
        shape = idx.shape
        idx = np.ascontiguousarray(idx, dtype=np.int64).ravel()
        turns = np.ascontiguousarray(turn, dtype=float).ravel()
        arc, node, ok, j, target = step_along(
            idx,
            turns,
            float(turn_margin),
            self.theta,
            self._run,
            float(self._span),
            self._first,
            self._last,
            self._banded,
            self.convex,
            self._s,
            self._node,
            self._entry if hint is None else hint,
        )
        if hint is not None:
            hint[idx] = j
        arc, node, ok = arc.reshape(shape), node.reshape(shape), ok.reshape(shape)
        j, target, idx = j.reshape(shape), target.reshape(shape), idx.reshape(shape)
        # no turn, no move: on a flat face the angle alone does not say where along it the contact is
        still = np.abs(np.asarray(turn)) <= NO_TURN
        if jaw is not None and at is not None and self.has_faces:
            # flush on a face: the entry at or before the landing on a face of (nearly) that angle
            for e in (j, j - 1):
                on = np.isfinite(self._face_a[e]) & (np.abs(self._banded[e] - target) <= FLUSH_TURN) & ~still
                if on.any():
                    fa, fb = self._face_a[e[on]], self._face_b[e[on]]
                    base = np.asarray(at, dtype=float)[on]
                    # the face's point σ lies at jaw + (σ − base) along the jaw (the contact moves as
                    # far along the jaw as along the part)
                    lo = np.maximum(fa, base - self.jaw.half - jaw)
                    hi = np.minimum(fb, base + self.jaw.half - jaw)
                    arc[on] = np.where(hi >= lo, 0.5 * (lo + hi), fa)
                    node[on] = self.node_at(arc[on])
        arc = np.where(still, self.sigma[idx], arc)
        node = np.where(still, idx, node)
        return np.where(ok, arc, np.nan), node, ok

    def touches(
        self,
        arc: ArrayLike,
        jaw: ArrayLike | None = None,
        margin: float = 0.0,
        sure: bool = False,
        node: IntArray | None = None,
    ) -> BoolArray:
        """Whether the jaw can touch at arc positions ``arc`` (mm, unwrapped; nan: no) with the contact
        at jaw position(s) ``jaw`` (mm; None: at some place on the jaw), within ``margin`` mm (negative:
        with that much to spare). ``sure`` takes the reach's sure interval (:meth:`Reach.interval`). ``node``:
        the grid points of those positions (from :meth:`step`), which on a pivot also say the jaw's angle."""
        arc = np.asarray(arc, dtype=float)
        finite = np.isfinite(arc)
        land = self.node_at(np.where(finite, arc, 0.0)) if node is None else np.asarray(node)
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
        arc, node, ok = self.step(index, turn, turn_margin=turn_margin)
        if jaw is not None:
            base = self.sigma[np.asarray(index)] if at is None else np.asarray(at, dtype=float)
            jaw = np.asarray(jaw, dtype=float) + (arc - base)
        ok = ok & self.touches(arc, jaw, margin, node=node)
        return np.where(ok, arc, np.nan), ok

    def rollable(self, turns: ArrayLike, jaw: float, margin: float = 0.0) -> BoolArray:
        """Grid points from which the jaw, laid with the contact at ``jaw`` (mm on it), can roll through
        every net rotation of ``turns`` (rad, in order, one sign) without bridging, with ``margin``
        mm to spare on the jaw all along (boolean mask over the grid)."""
        ok: BoolArray = self.convex & self.touches(self.sigma, jaw, -margin, sure=True, node=np.arange(self.sigma.size))
        for t in np.atleast_1d(np.asarray(turns, dtype=float)):
            idx = np.flatnonzero(ok)
            arc, node, moved = self.step(idx, float(t))
            ok[idx] = moved & self.touches(arc, jaw + (arc - self.sigma[idx]), -margin, sure=True, node=node)
        return ok


def _bridge_shallow_dips(
    part: Boundary, sigma: FloatArray, theta: FloatArray, jaw_length: float
) -> tuple[FloatArray, BoolArray, int]:
    """The tangent angle the rolling follows at each grid point, with every shallow concavity
    bridged, and the grid points within a bridge.

    A straight jaw rolling over a concavity narrower than itself touches the two convex stretches
    around it on one line, the bitangent, at angle φ: up to φ the contact is on the stretch before,
    past φ on the one after, and the contact jumps the chord between them. So every grid point
    from the first tangent point a to the second b rolls at φ (a table entry of constant angle, as on
    a flat face). The concavity is bridged when the arc from a to b exceeds the chord by at most
    :data:`BRIDGE_EXCESS` and the chord is shorter than the jaw; the bitangent is found by Brent's
    method on the signed distance of b from the tangent line at a, over the angles both stretches
    reach.

    Parameters
    ----------
    part : Boundary
    sigma, theta : ndarray, shape (n,)
        The grid's arc positions (mm, increasing within one lap) and unwrapped tangent angles (rad).
    jaw_length : float, mm

    Returns
    -------
    rolled : ndarray, shape (n,), rad
        ``theta`` with each bridged stretch [a, b] at φ.
    skipped : ndarray of bool, shape (n,)
        Grid points strictly between a and b: no rolling starts there.
    bridged : int
        How many concavities were bridged.
    """
    n = sigma.size
    p = part.perimeter
    turn = 2.0 * math.pi
    rolled = theta.copy()
    skipped = np.zeros(n, dtype=bool)
    # three laps, so that a concavity across the lap's end has both stretches on the table
    s3 = np.concatenate([sigma - p, sigma, sigma + p])
    t3 = np.concatenate([theta - turn, theta, theta + turn])
    falling = np.diff(t3) < 0  # cell i: from node i to node i + 1
    if not falling[n : 2 * n].any():
        return rolled, skipped, 0
    # runs of falling cells: run r covers cells first[r] .. past[r] - 1, so the concavity runs from node
    # first[r] (θ highest) to node past[r] (lowest), between the rising runs that end and begin there
    edge = np.diff(np.concatenate([[0], falling.astype(np.int8), [0]]))
    first, past = np.flatnonzero(edge == 1), np.flatnonzero(edge == -1)
    bridged = 0
    for r in np.flatnonzero((first >= n) & (first < 2 * n)):
        i1, i2 = int(first[r]), int(past[r])
        a0 = int(past[r - 1]) if r > 0 else 0
        b1 = int(first[r + 1]) if r + 1 < first.size else falling.size
        lo, hi = max(t3[i2], t3[a0]), min(t3[i1], t3[b1])
        if not (hi > lo) or i1 - a0 < 2 or b1 - i2 < 2:
            continue
        found = _bitangent(part, (t3[a0 : i1 + 1], s3[a0 : i1 + 1]), (t3[i2 : b1 + 1], s3[i2 : b1 + 1]), lo, hi)
        if found is None:
            continue
        phi, sa, sb = found
        between = np.linspace(sa, sb, 64)
        pts = np.asarray(part.point_at_arc(np.mod(between, p)), dtype=float)
        chord = float(np.hypot(*(pts[-1] - pts[0])))
        # the jaw on the bitangent keeps the whole stretch on the part's side (a support line)
        depth = math.cos(phi) * (pts[:, 1] - pts[0, 1]) - math.sin(phi) * (pts[:, 0] - pts[0, 0])
        if not (chord < jaw_length and (sb - sa) - chord <= BRIDGE_EXCESS and depth.min() >= -1e-6):
            continue
        on = np.flatnonzero((s3 >= sa) & (s3 <= sb))
        rolled[on % n] = phi - (on // n - 1) * turn
        inner = np.flatnonzero((s3 > sa) & (s3 < sb))
        skipped[inner % n] = True
        bridged += 1
    return rolled, skipped, bridged


def _bitangent(
    part: Boundary, before: tuple[FloatArray, FloatArray], after: tuple[FloatArray, FloatArray], lo: float, hi: float
) -> tuple[float, float, float] | None:
    """The line touching two convex stretches at one tangent angle φ within [``lo``, ``hi``] (rad):
    (φ, its arc on the first, its arc on the second, mm), or None when there is not exactly one.

    ``before`` and ``after`` are each stretch's (θ rising, rad; arc, mm) on the grid; the arc of a
    given θ is interpolated between grid points. The root of the signed distance of the second
    point from the tangent line at the first is found by Brent's method.
    """

    def ends(phi: float) -> tuple[float, float]:
        return float(np.interp(phi, *before)), float(np.interp(phi, *after))

    def side(phi: float) -> float:
        sa, sb = ends(phi)
        d = np.asarray(part.point_at_arc(np.mod([sb, sa], part.perimeter)), dtype=float)
        v = d[0] - d[1]
        return float(math.cos(phi) * v[1] - math.sin(phi) * v[0])

    phis = np.linspace(lo, hi, 33)
    g = np.array([side(float(f)) for f in phis])
    change = np.flatnonzero(np.sign(g[:-1]) * np.sign(g[1:]) <= 0)
    if change.size != 1:
        return None
    from scipy.optimize import brentq  # here: scipy.optimize is 0.3 s of every command's start

    k = int(change[0])
    phi = float(brentq(side, phis[k], phis[k + 1], xtol=1e-12)) if g[k] != g[k + 1] else float(phis[k])
    return (phi, *ends(phi))
