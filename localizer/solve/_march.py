"""Jia's marching algorithm (paper §II-A, §II-B and the Appendix), the reference method.

Everything is evaluated the paper's way: ℓ and Φ by fixed-step numerical
integration (trapezoid rule) with step ``h`` in the parameter domain. The
integrals are accumulated once on the h-grid (``MarchGrid``); between grid
points they are interpolated linearly. The integrals at the two endpoints s
and t are carried along as they march: moving an endpoint over k grid cells
(either way, restarts and bisection included) counts as k numerical steps,
the quantity Theorem 2 bounds by 6τ/h.

The boundary is split into *modes* (Appendix): stretches of start positions
s on which the signs of κ(s) and κ(t) stay fixed, t being the end with
ℓ(s, t) = L. Their ends are the inflections z_j and the starts whose end is
an inflection (ℓ(s, z_j) = L); a zero of κ where κ keeps its sign (a
higher-order zero, footnote 5: κ' decides the side) is not a mode change.

* convex-convex and concave-concave modes: the iteration (7), alternately
  elongating and contracting [s, t] (for concave-concave on -Φ, which has
  the convex signs), with the ε step-over of Theorem 2 after each segment;
* convex-concave and concave-convex modes: Φ along ℓ = L is monotone in s,
  so a mode holds one feasible segment iff Φ at its ends brackets Ω, found
  by bisection.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._defaults import LENGTH_TOL, MIN_SEPARATION, TURN_TOL
from .._errors import QueryError
from .._types import FloatArray
from ..geometry import Part
from ._march_grid import march_grid
from ._segment import Segment

__all__ = ["MarchResult", "MarchOptions", "PAPER_MARCH", "march"]


@dataclass(frozen=True)
class MarchResult:
    """Outcome of :func:`march`.

    Attributes
    ----------
    segments : list of Segment
        Feasible segments found, sorted by start arc; each carries ``iterates``.
    steps : int
        Numerical integration steps taken by the endpoints (Theorem 2 bounds
        it by 6τ/h).
    grid_cells : int
        τ/h, the steps of one perimeter integration.
    restarts : int
        Marches started (the initial one and one per ε step-over and mode).
    """

    segments: list[Segment]
    steps: int
    grid_cells: int
    restarts: int


@dataclass(frozen=True)
class MarchOptions:
    """The settings of the paper's marching algorithm (:func:`march`).

    Attributes
    ----------
    step : float
        h, the integration step in the parameter domain (paper: 1e-5).
    length_tol, turn_tol : float, mm and rad
        Convergence tolerances on ℓ and Φ (paper: 0.004 and 0.0004).
    min_separation : float, mm
        Minimum separation of feasible starts (paper: 0.5); the step-over ε
        is this divided by the largest curve speed.
    max_iterations : int
        Iterations of (7) after which a march that has not met the
        tolerances is reported as ``kind="stalled"`` (κ(s*) ≈ κ(t*)).
    """

    step: float = 1e-5
    length_tol: float = LENGTH_TOL
    turn_tol: float = TURN_TOL
    min_separation: float = MIN_SEPARATION
    max_iterations: int = 100_000

    def __post_init__(self) -> None:
        for name in ("step", "length_tol", "turn_tol", "min_separation"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} must be a positive number")
        if isinstance(self.max_iterations, bool) or not isinstance(self.max_iterations, int) or self.max_iterations < 1:
            raise QueryError(f"max_iterations={self.max_iterations!r} must be a whole number ≥ 1")


#: The paper's settings (h = 1e-5, its tolerances).
PAPER_MARCH = MarchOptions()


def march(part: Part, length: float, turn: float, options: MarchOptions = PAPER_MARCH) -> MarchResult:
    """Counter-clockwise marching over the whole boundary (the paper's algorithm).

    Parameters
    ----------
    part : Part
    length : float, mm
    turn : float, rad
    options : MarchOptions
        The step h, the tolerances, the separation of starts, the iteration limit.

    Returns
    -------
    MarchResult
    """
    return _Marcher(part, length, turn, options).run()


#: A march's find: (s, t, the iterates' starts, iterations, kind).
_Found = tuple[float, float, list[float], int, str]


class _Marcher:
    """One march: the h-grid, the endpoints' integration counter, and the segments found so far.

    Moving an endpoint over k grid cells counts as k integration steps (:meth:`at`); every
    mode is marched by :meth:`march_mode` (iteration (7)) or :meth:`bisect_mode`.
    """

    def __init__(self, part: Part, length: float, turn: float, options: MarchOptions) -> None:
        self.part, self.length, self.turn, self.options = part, length, turn, options
        self.grid = grid = march_grid(part, options.step)
        self.h = grid.h
        self.tau = part.n_knots
        self.perimeter = grid.length[-1]
        if not 0 < length < self.perimeter:
            raise QueryError(f"length={length!r} mm is out of range (0, {self.perimeter:.6g}) mm")
        self.eps = options.min_separation / grid.max_speed
        self.steps = 0
        self.restarts = 0
        self.cur = {"s": 0.0, "t": 0.0}  # where the two endpoints' integrals were last evaluated
        self.found: list[_Found] = []
        # the inflections over four laps, and κ's sign after each (None: κ keeps one sign)
        self.zz: FloatArray | None = None
        self.ss: FloatArray | None = None

    # ------------------------------------------------------------------ endpoints
    def at(self, **ends: float) -> None:
        """Move endpoint s and/or t: integrating over the move costs one step per grid cell."""
        for name, x in ends.items():
            self.steps += int(abs(round(x / self.h) - round(self.cur[name] / self.h)))
            self.cur[name] = x

    def end_of(self, s: float) -> float | None:
        """t with ℓ(s, t) = L (a numerical integration from s)."""
        grid = self.grid
        return grid._search(grid.length, grid._value(grid.length, s) + self.length, s, s + self.tau)

    def end(self, s: float) -> float:
        """:meth:`end_of` where it must exist (every s has one: L is less than the perimeter)."""
        t = self.end_of(s)
        if t is None:
            raise QueryError(f"no end with ℓ(s, t) = {self.length!r} mm from s = {s!r}: the h-grid is inconsistent")
        return t

    def region_end(self, t: float) -> float:
        """The next inflection after t: t may not pass it within a mode."""
        if self.zz is None:
            return t + self.tau
        return float(self.zz[np.searchsorted(self.zz, t, side="right")])

    def sign_at(self, x: float) -> float:
        """The sign of κ at parameter x (the sign after the last inflection before it)."""
        if self.zz is None or self.ss is None:
            raise QueryError("sign_at needs the inflections: call modes() first")
        return float(self.ss[int(np.searchsorted(self.zz, x, side="right")) - 1])

    # ------------------------------------------------------------------ modes
    def modes(self) -> list[tuple[float, float, float, float]]:
        """(sa, sb, sign of κ(s), sign of κ(t)) of each mode (Appendix): the starts cut where s or
        t = s+L meets an inflection."""
        grid, tau, h = self.grid, self.tau, self.h
        z, sign_after = grid.inflections
        if z.size == 0:  # convex (or concave) everywhere: one mode, t is free
            only = float(np.sign(grid.kappa[np.flatnonzero(grid.kappa)[0]]))
            return [(0.0, float(tau), only, only)]
        self.zz = np.concatenate([z - tau, z, z + tau, z + 2 * tau])
        self.ss = np.tile(sign_after, 4)
        back = []  # starts whose end is an inflection: ℓ(s, z_j) = L
        for zj in z:
            target = grid._value(grid.length, zj) - self.length
            if target < 0:
                target += self.perimeter
            sj = grid._search(grid.length, target, 0.0, float(tau))
            if sj is not None:
                back.append(sj)  # found during the march as ℓ(z_k, t) >= L: no extra integration
        cuts = np.unique(np.concatenate([[0.0, float(tau)], z, back]))
        modes = []
        for a, b in zip(cuts[:-1], cuts[1:]):
            if b - a <= 0.5 * h:
                continue
            mid = 0.5 * (a + b)
            modes.append((float(a), float(b), self.sign_at(mid), self.sign_at(self.end(mid))))
        return modes

    def march_mode(self, sa: float, sb: float, sgn: float) -> None:
        """Iteration (7) on sign·Φ for starts in [sa, sb], with the ε step-over after each segment."""
        s = sa
        while s < sb:
            self.restarts += 1
            found = self._iterate(s, sb, sgn)
            if found is None:
                return
            self.found.append(found)
            s = found[0] + self.eps

    def _iterate(self, s: float, sb: float, sgn: float) -> _Found | None:
        """One march of (7) from start s: the segment it converges (or stalls) on, None when it leaves
        the mode."""
        grid, opt, length = self.grid, self.options, self.length
        target = sgn * self.turn
        cum_turn = grid.turn if sgn > 0 else grid.negated_turn
        iterates = [s]
        tL = self.end_of(s)
        if tL is None:
            return None
        self.at(s=s, t=tL)
        psi = sgn * grid.phi(s, tL)
        if abs(psi - target) <= opt.turn_tol:
            return (s, tL, iterates, 0, "simple")
        case_a = psi < target  # the first u with Φ(s, u) = Ω lies beyond tL: ℓ(s, u) > L
        t = tL
        converged = False
        for _it in range(1, opt.max_iterations + 1):
            if case_a:
                # t_i: Φ(s_i, t_i) = Ω (t increases), s_{i+1}: ℓ(s_{i+1}, t_i) = L
                base = grid._value(cum_turn, s)
                t_new = grid._search(cum_turn, base + target, t, self.region_end(t))
                if t_new is None:
                    return None
                self.at(t=t_new)
                t = t_new
                s_new = grid._search(grid.length, grid._value(grid.length, t) - length, s, t)
                if s_new is None:
                    return None
                self.at(s=s_new)
                s = s_new
                iterates.append(s)
                if s > sb:
                    return None
                if abs(sgn * grid.phi(s, t) - target) <= opt.turn_tol:
                    converged = True
                    break
            else:
                # s_{i+1}: Φ(s_{i+1}, t_i) = Ω (s increases), t_{i+1}: ℓ(s_{i+1}, t_{i+1}) = L
                # sign·Φ(s, t) decreases as s grows over a same-sign stretch
                base_t = grid._value(cum_turn, t)
                s_new = grid._search(cum_turn, base_t - target, s, min(t, sb + self.eps))
                if s_new is None:
                    return None
                self.at(s=s_new)
                s = s_new
                iterates.append(s)
                if s > sb:
                    return None
                t_new = self.end_of(s)
                if t_new is None:
                    return None
                self.at(t=t_new)
                t = t_new
                if (
                    abs(sgn * grid.phi(s, t) - target) <= opt.turn_tol
                    and abs(grid.ell(s, t) - length) <= opt.length_tol
                ):
                    converged = True
                    break
        return (s, t, iterates, len(iterates) - 1, "simple" if converged else "stalled")

    def bisect_mode(self, sa: float, sb: float) -> None:
        """Φ along ℓ = L is monotone on a mixed mode: one root iff Φ brackets Ω."""
        grid, turn = self.grid, self.turn
        self.restarts += 1
        ta, tb = self.end(sa), self.end(sb)
        self.at(s=sa, t=ta)
        self.at(s=sb, t=tb)
        fa = grid.phi(sa, ta) - turn
        fb = grid.phi(sb, tb) - turn
        if fa * fb > 0:
            return
        lo, hi = sa, sb
        iterates = []
        for _it in range(200):
            mid = 0.5 * (lo + hi)
            tm = self.end(mid)
            self.at(s=mid, t=tm)
            fm = grid.phi(mid, tm) - turn
            iterates.append(mid)
            if abs(fm) <= self.options.turn_tol or hi - lo <= self.h:
                self.found.append((mid, tm, iterates, len(iterates), "simple"))
                return
            if (fm > 0) == (fa > 0):
                lo, fa = mid, fm
            else:
                hi = mid

    # ------------------------------------------------------------------ the whole march
    def run(self) -> MarchResult:
        """March every mode and collect the segments."""
        for sa, sb, s_sign, t_sign in self.modes():
            if s_sign == t_sign:
                self.march_mode(sa, sb, s_sign)
            else:
                self.bisect_mode(sa, sb)
        return MarchResult(
            segments=self.segments(), steps=self.steps, grid_cells=self.grid.cells, restarts=self.restarts
        )

    def segments(self) -> list[Segment]:
        """The segments found, sorted by start; a root found at the end of one mode and the start of
        the next is one root."""
        part, tau = self.part, self.tau
        arc = part.arc_at_param
        segs = []
        for s, t, iterates, iters, kind in self.found:
            segs.append(
                Segment(
                    start_arc=float(part.wrap_arc(arc(s))),
                    end_arc=float(part.wrap_arc(arc(t))),
                    start_param=float(s % tau),
                    end_param=float(t % tau),
                    length=self.length,
                    turn=self.turn,
                    direction="ccw",
                    kind=kind,
                    span=0.0,
                    residual=float(abs(part.total_curvature(s, t) - self.turn)),
                    iterates=tuple(float(v) for v in part.wrap_arc(arc(np.array(iterates)))),
                    iterations=int(iters),
                )
            )
        segs.sort(key=lambda g: g.start_arc)
        sep = self.options.min_separation
        out: list[Segment] = []
        for g in segs:
            if out and abs(part.arc_offset(g.start_arc, out[-1].start_arc)) < sep:
                continue
            out.append(g)
        if len(out) > 1 and abs(part.arc_offset(out[0].start_arc, out[-1].start_arc)) < sep:
            out.pop()
        return out
