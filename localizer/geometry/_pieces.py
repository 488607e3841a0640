"""The exact pieces a CAD outline is made of: straight lines, circular arcs and cubic Béziers.

Each piece is parameterised by its own arc length s ∈ [0, length] (mm) and gives the point, the
tangent angle θ(s) (rad, continuous along the piece, counter-clockwise from +x) and the signed
curvature κ(s) = dθ/ds (1/mm, positive turning left). Lines and arcs are exact in closed form; a
Bézier's arc length is the composite Gauss–Legendre integral of its speed on subintervals halved
until two rules agree to 1e-13 of the length, and its inverse (the Bézier parameter u at arc s) a
safeguarded Newton iteration to 1e-12 mm.

A Bézier may be *rational* (a weight per control point, the point Σ Bᵢwᵢpᵢ / Σ Bᵢwᵢ): it then draws
conics exactly, so an ellipse's arc (:func:`elliptical_arc`, a quadratic rational Bézier per quarter
or less) and a NURBS curve (split at its knots into rational Béziers) are pieces as exact as the
others.

A piece reversed (:meth:`reversed`) is the same curve travelled the other way: its tangent angle
turns by π and its curvature changes sign.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._errors import PartError
from .._types import ArrayLike, FloatArray
from ._bezier_kernels import arc_to_param
from ._numerics import gauss_legendre, wrap_angle

__all__ = ["Line", "CircularArc", "CubicBezier", "Piece", "elliptical_arc"]

_GL_X, _GL_W = gauss_legendre(16)
_G4_X, _G4_W = gauss_legendre(4)  # a Newton step's arc from the last iterate (arc_to_param)


_PLAIN = (float, int, np.float64)


def _xy(p: ArrayLike, what: str) -> tuple[float, float]:
    if isinstance(p, tuple) and len(p) == 2:
        x, y = p  # the common case, without an array: a drawing has 10⁵ points
        if type(x) in _PLAIN and type(y) in _PLAIN and math.isfinite(x) and math.isfinite(y):
            return float(x), float(y)
    a = np.asarray(p, dtype=float)
    if a.shape != (2,) or not np.all(np.isfinite(a)):
        raise PartError(f"{what} must be a finite (x, y) point in mm, got {p!r}")
    return float(a[0]), float(a[1])


@dataclass(frozen=True)
class Line:
    """A straight piece from ``start`` to ``end`` (mm)."""

    start: tuple[float, float]
    end: tuple[float, float]

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", _xy(self.start, "line start"))
        object.__setattr__(self, "end", _xy(self.end, "line end"))
        if self.length <= 0.0:
            raise PartError(f"line from {self.start} to {self.end} has zero length")

    @property
    def length(self) -> float:
        """mm."""
        return math.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1])

    def point(self, s: ArrayLike) -> FloatArray:
        """Points at arc lengths ``s`` (mm) from the start, shape (..., 2)."""
        t = np.asarray(s, dtype=float)[..., None] / self.length
        a, b = np.asarray(self.start), np.asarray(self.end)
        out: FloatArray = a + t * (b - a)
        return out

    def tangent_angle(self, s: ArrayLike) -> FloatArray:
        """θ at arc lengths ``s`` (constant), rad."""
        theta = math.atan2(self.end[1] - self.start[1], self.end[0] - self.start[0])
        return np.full(np.shape(s), theta)

    def curvature(self, s: ArrayLike) -> FloatArray:
        """κ at arc lengths ``s``: zero, 1/mm."""
        return np.zeros(np.shape(s))

    def reversed(self) -> Line:
        """The same line travelled from ``end`` to ``start``."""
        return trusted_lines([self.end], [self.start])[0]  # its own points, checked when it was made


@dataclass(frozen=True)
class CircularArc:
    """A circular arc about ``center`` (mm) of ``radius`` (mm), from polar angle ``start_angle`` (rad)
    through ``sweep`` (rad; positive counter-clockwise, |sweep| ≤ 2π)."""

    center: tuple[float, float]
    radius: float
    start_angle: float
    sweep: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _xy(self.center, "arc centre"))
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise PartError(f"arc radius={self.radius!r} mm must be a positive number")
        if not (math.isfinite(self.sweep) and 0 < abs(self.sweep) <= 2 * math.pi + 1e-12):
            raise PartError(f"arc sweep={self.sweep!r} rad must be nonzero and at most one turn")
        if not math.isfinite(self.start_angle):
            raise PartError(f"arc start_angle={self.start_angle!r} rad must be finite")

    @property
    def length(self) -> float:
        """r·|sweep|, mm."""
        return self.radius * abs(self.sweep)

    @property
    def start(self) -> tuple[float, float]:
        """mm."""
        return self._at_polar(self.start_angle)

    @property
    def end(self) -> tuple[float, float]:
        """mm."""
        return self._at_polar(self.start_angle + math.copysign(1.0, self.sweep) * self.length / self.radius)

    def _at_polar(self, a: float) -> tuple[float, float]:
        """The point at polar angle ``a`` (rad), without arrays: a faceted drawing asks it of 10⁵ arcs."""
        return self.center[0] + self.radius * math.cos(a), self.center[1] + self.radius * math.sin(a)

    def _polar(self, s: ArrayLike) -> FloatArray:
        out: FloatArray = self.start_angle + math.copysign(1.0, self.sweep) * np.asarray(s, dtype=float) / self.radius
        return out

    def point(self, s: ArrayLike) -> FloatArray:
        """Points at arc lengths ``s`` (mm) from the start, shape (..., 2)."""
        a = self._polar(s)
        out: FloatArray = np.stack(
            [self.center[0] + self.radius * np.cos(a), self.center[1] + self.radius * np.sin(a)], -1
        )
        return out

    def tangent_angle(self, s: ArrayLike) -> FloatArray:
        """θ at arc lengths ``s``: the polar angle plus a quarter turn in the sense of travel, rad."""
        out: FloatArray = self._polar(s) + math.copysign(0.5 * math.pi, self.sweep)
        return out

    def curvature(self, s: ArrayLike) -> FloatArray:
        """κ at arc lengths ``s``: ±1/radius (positive counter-clockwise), 1/mm."""
        return np.full(np.shape(s), math.copysign(1.0 / self.radius, self.sweep))

    def reversed(self) -> CircularArc:
        """The same arc travelled the other way."""
        return CircularArc(self.center, self.radius, self.start_angle + self.sweep, -self.sweep)


@dataclass(frozen=True)
class CubicBezier:
    """A cubic Bézier from ``p0`` to ``p3`` with control points ``p1``, ``p2`` (mm).

    ``weights`` (positive, one per control point) make it rational: the point at u is
    Σ Bᵢ(u)wᵢpᵢ / Σ Bᵢ(u)wᵢ. Equal weights give the ordinary polynomial Bézier.
    """

    p0: tuple[float, float]
    p1: tuple[float, float]
    p2: tuple[float, float]
    p3: tuple[float, float]
    weights: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    _breaks: FloatArray = field(init=False, repr=False, compare=False)  # u of the subintervals
    _cum: FloatArray = field(init=False, repr=False, compare=False)  # arc length at the breaks, mm
    _theta: FloatArray = field(init=False, repr=False, compare=False)  # unwrapped θ at 65 u, rad
    _rational: bool = field(init=False, repr=False, compare=False)  # weights not all equal
    _coef: FloatArray = field(init=False, repr=False, compare=False)  # power basis of (wx, wy, w), (4, 3)
    _diff: FloatArray = field(init=False, repr=False, compare=False)  # p1 - p0, p2 - p1, p3 - p2, (3, 2)

    def __post_init__(self) -> None:
        for name in ("p0", "p1", "p2", "p3"):
            object.__setattr__(self, name, _xy(getattr(self, name), f"Bézier {name}"))
        w = np.asarray(self.weights, dtype=float)
        if w.shape != (4,) or not np.all(np.isfinite(w) & (w > 0)):
            raise PartError(f"Bézier weights={self.weights!r} must be four positive numbers")
        object.__setattr__(self, "weights", tuple(float(v) for v in w))
        object.__setattr__(self, "_rational", bool(np.ptp(w) > 0))
        h = np.c_[np.array([self.p0, self.p1, self.p2, self.p3]) * w[:, None], w]
        coef = np.array([h[0], 3 * (h[1] - h[0]), 3 * (h[2] - 2 * h[1] + h[0]), h[3] - 3 * h[2] + 3 * h[1] - h[0]])
        object.__setattr__(self, "_coef", coef)
        p = np.array([self.p0, self.p1, self.p2, self.p3])
        object.__setattr__(self, "_diff", np.diff(p, axis=0))
        u = np.linspace(0.0, 1.0, 257)
        if np.hypot(*self._d1(u).T).min() <= 1e-9 * max(1.0, self._size()):
            raise PartError(f"Bézier {self.p0}…{self.p3} stops (zero speed, a cusp): split it there")
        # subintervals halved until the 16-point rule on each agrees with its two halves
        breaks = np.linspace(0.0, 1.0, 9)
        for _ in range(30):
            whole = self._gauss(breaks[:-1], breaks[1:])
            mid = 0.5 * (breaks[:-1] + breaks[1:])
            halves = self._gauss(breaks[:-1], mid) + self._gauss(mid, breaks[1:])
            bad = np.abs(whole - halves) > 1e-13 * max(1.0, float(halves.sum()))
            if not bad.any():
                break
            breaks = np.sort(np.concatenate([breaks, mid[bad]]))
        seg = self._gauss(breaks[:-1], breaks[1:])
        object.__setattr__(self, "_breaks", breaks)
        object.__setattr__(self, "_cum", np.concatenate([[0.0], np.cumsum(seg)]))
        ut = np.linspace(0.0, 1.0, 65)
        raw = self._raw_angle(ut)
        object.__setattr__(self, "_theta", raw[0] + np.concatenate([[0.0], np.cumsum(wrap_angle(np.diff(raw)))]))

    def _size(self) -> float:
        pts = np.array([self.p0, self.p1, self.p2, self.p3])
        return float(np.ptp(pts, axis=0).max())

    def _homogeneous(self, u: FloatArray, order: int) -> list[FloatArray]:
        """The polynomial Bézier of the homogeneous points (wᵢxᵢ, wᵢyᵢ, wᵢ) and its derivatives up to
        ``order`` at ``u``, each shape (..., 3) (Horner in the power basis)."""
        c0, c1, c2, c3 = self._coef
        u = np.asarray(u, dtype=float)[..., None]
        out = [((c3 * u + c2) * u + c1) * u + c0, (3 * c3 * u + 2 * c2) * u + c1]
        if order >= 2:
            out.append(6 * c3 * u + 2 * c2)
        return out

    def _rational_derivatives(self, u: FloatArray, order: int = 2) -> list[FloatArray]:
        """Point and derivatives (up to ``order``) of the rational curve C = A/W at ``u``:
        C' = (A' − W'C)/W, C'' = (A'' − 2W'C' − W''C)/W."""
        h = self._homogeneous(u, order)
        wt, w1 = h[0][..., 2:], h[1][..., 2:]
        c = h[0][..., :2] / wt
        c1 = (h[1][..., :2] - w1 * c) / wt
        if order < 2:
            return [c, c1]
        c2 = (h[2][..., :2] - 2 * w1 * c1 - h[2][..., 2:] * c) / wt
        return [c, c1, c2]

    def _bezier(self, u: FloatArray) -> FloatArray:
        if self._rational:
            return self._rational_derivatives(u, 1)[0]
        u = u[..., None]
        v = 1.0 - u
        p = [np.asarray(q) for q in (self.p0, self.p1, self.p2, self.p3)]
        out: FloatArray = v**3 * p[0] + 3 * v * v * u * p[1] + 3 * v * u * u * p[2] + u**3 * p[3]
        return out

    def _d1(self, u: FloatArray) -> FloatArray:
        if self._rational:
            return self._rational_derivatives(u, 1)[1]
        u = u[..., None]
        v = 1.0 - u
        p = [np.asarray(q) for q in (self.p0, self.p1, self.p2, self.p3)]
        out: FloatArray = 3 * v * v * (p[1] - p[0]) + 6 * v * u * (p[2] - p[1]) + 3 * u * u * (p[3] - p[2])
        return out

    def _d2(self, u: FloatArray) -> FloatArray:
        if self._rational:
            return self._rational_derivatives(u)[2]
        u = u[..., None]
        p = [np.asarray(q) for q in (self.p0, self.p1, self.p2, self.p3)]
        out: FloatArray = 6 * (1.0 - u) * (p[2] - 2 * p[1] + p[0]) + 6 * u * (p[3] - 2 * p[2] + p[1])
        return out

    def _speed(self, u: FloatArray) -> FloatArray:
        d = self._d1(u)
        out: FloatArray = np.hypot(d[..., 0], d[..., 1])
        return out

    def _gauss(self, a: FloatArray, b: FloatArray) -> FloatArray:
        x = a[:, None] + (b - a)[:, None] * _GL_X
        out: FloatArray = (self._speed(x) * _GL_W).sum(axis=1) * (b - a)
        return out

    def _raw_angle(self, u: FloatArray) -> FloatArray:
        d = self._d1(u)
        out: FloatArray = np.arctan2(d[..., 1], d[..., 0])
        return out

    @property
    def start(self) -> tuple[float, float]:
        """mm."""
        return self.p0

    @property
    def end(self) -> tuple[float, float]:
        """mm."""
        return self.p3

    @property
    def length(self) -> float:
        """mm (to 1e-13 of itself)."""
        return float(self._cum[-1])

    def param(self, s: ArrayLike) -> FloatArray:
        """The Bézier parameter u ∈ [0, 1] at arc lengths ``s`` (mm), to 1e-12 mm."""
        shape = np.shape(s)
        arc: FloatArray = np.clip(np.asarray(s, dtype=float), 0.0, self.length).ravel()
        k = np.clip(np.searchsorted(self._cum, arc, side="right") - 1, 0, len(self._breaks) - 2)
        lo, hi = self._breaks[k], self._breaks[k + 1]
        u: FloatArray = lo + (hi - lo) * (arc - self._cum[k]) / np.maximum(self._cum[k + 1] - self._cum[k], 1e-300)
        arc_to_param(self._coef, self._diff, self._rational, _GL_X, _GL_W, _G4_X, _G4_W, self._cum, k, lo, hi, arc, u)
        return u.reshape(shape)

    def _gauss_to(self, a: FloatArray, b: FloatArray) -> FloatArray:
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
        x = a[..., None] + (b - a)[..., None] * _GL_X
        out: FloatArray = (self._speed(x) * _GL_W).sum(axis=-1) * (b - a)
        return out

    def point(self, s: ArrayLike) -> FloatArray:
        """Points at arc lengths ``s`` (mm) from ``p0``, shape (..., 2)."""
        return self._bezier(self.param(s))

    def tangent_angle(self, s: ArrayLike) -> FloatArray:
        """θ at arc lengths ``s``, unwrapped along the piece from θ at ``p0`` (in [-π, π)), rad."""
        return self._angle_at(self.param(s))

    def _angle_at(self, u: FloatArray) -> FloatArray:
        ref = np.interp(u, np.linspace(0.0, 1.0, 65), self._theta)
        out: FloatArray = ref + wrap_angle(self._raw_angle(u) - ref)
        return out

    def curvature(self, s: ArrayLike) -> FloatArray:
        """κ = (x'y'' − y'x'') / |α'|³ at arc lengths ``s``, 1/mm."""
        return self._curvature_at(self.param(s))

    def _curvature_at(self, u: FloatArray) -> FloatArray:
        d1, d2 = self._d1(u), self._d2(u)
        out: FloatArray = (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]) / self._speed(u) ** 3
        return out

    def angle_and_curvature(self, s: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(:meth:`tangent_angle`, :meth:`curvature`) at arc lengths ``s``, with one inversion of the
        arc length (the costly part of either)."""
        u = self.param(s)
        return self._angle_at(u), self._curvature_at(u)

    @classmethod
    def from_quadratic(
        cls, p0: tuple[float, float], p1: tuple[float, float], p2: tuple[float, float], weight: float = 1.0
    ) -> CubicBezier:
        """The quadratic Bézier ``p0``, ``p1``, ``p2`` (mm), rational with weights (1, ``weight``, 1), as
        the cubic it is exactly (degree elevation of the homogeneous points)."""
        if not (math.isfinite(weight) and weight > 0):
            raise PartError(f"quadratic Bézier weight={weight!r} must be a positive number")
        if weight == 1.0:
            c1 = (p0[0] + 2 / 3 * (p1[0] - p0[0]), p0[1] + 2 / 3 * (p1[1] - p0[1]))
            c2 = (p2[0] + 2 / 3 * (p1[0] - p2[0]), p2[1] + 2 / 3 * (p1[1] - p2[1]))
            return cls(p0, c1, c2, p2)
        a, b, c = (np.asarray(q, dtype=float) for q in (p0, p1, p2))
        w1 = (1.0 + 2.0 * weight) / 3.0
        q1 = (a + 2.0 * weight * b) / (3.0 * w1)
        q2 = (2.0 * weight * b + c) / (3.0 * w1)
        return cls(p0, (float(q1[0]), float(q1[1])), (float(q2[0]), float(q2[1])), p2, (1.0, w1, w1, 1.0))

    def reversed(self) -> CubicBezier:
        """The same curve travelled from ``p3`` to ``p0``."""
        w = self.weights
        return CubicBezier(self.p3, self.p2, self.p1, self.p0, (w[3], w[2], w[1], w[0]))


def elliptical_arc(
    center: tuple[float, float], u: tuple[float, float], v: tuple[float, float], t0: float, t1: float
) -> list[CubicBezier]:
    """The arc c + u·cos t + v·sin t for t from ``t0`` to ``t1`` as exact rational Béziers, one per
    quarter of t or less.

    A piece over [a, b] is the quadratic with end points C(a), C(b), middle point
    c + (u·cos m + v·sin m)/cos h and middle weight cos h, m = (a + b)/2, h = (b − a)/2: the rational
    form of a conic, exact.

    Parameters
    ----------
    center : (float, float), mm
        The ellipse's centre c.
    u, v : (float, float), mm
        Conjugate semi-diameters: the semi-axes when perpendicular (any affine image of a circle,
        e.g. an SVG arc after a skew, is such an arc).
    t0, t1 : float, rad
        The parameter's first and last value; t1 < t0 travels the other way.

    Returns
    -------
    list of CubicBezier
    """
    c, uu, vv = (np.asarray(q, dtype=float) for q in (center, u, v))
    if not (np.all(np.isfinite(np.r_[c, uu, vv, t0, t1])) and t0 != t1):
        raise PartError(f"elliptical arc centre={center!r} u={u!r} v={v!r} t={t0!r}..{t1!r} must be finite and sweep")
    if abs(float(uu[0] * vv[1] - uu[1] * vv[0])) <= 1e-12 * float(np.dot(uu, uu) + np.dot(vv, vv)):
        raise PartError(f"elliptical arc with semi-diameters u={u!r}, v={v!r} mm is flat (they are parallel)")
    if abs(t1 - t0) > 2 * math.pi + 1e-12:
        raise PartError(f"elliptical arc t={t0!r}..{t1!r} rad turns more than once")
    n = max(1, math.ceil(abs(t1 - t0) / (0.5 * math.pi) - 1e-9))
    ts = np.linspace(t0, t1, n + 1)

    def at(t: float, scale: float = 1.0) -> tuple[float, float]:
        q = c + (uu * math.cos(t) + vv * math.sin(t)) * scale
        return float(q[0]), float(q[1])

    out = []
    for a, b in zip(ts[:-1], ts[1:], strict=True):
        h = 0.5 * (b - a)
        out.append(CubicBezier.from_quadratic(at(a), at(0.5 * (a + b), 1.0 / math.cos(h)), at(b), math.cos(h)))
    return out


#: Any of the pieces.
Piece = Line | CircularArc | CubicBezier


# Readers of dense drawings make 10⁵ pieces from numbers they have checked as arrays; the constructors'
# checks, point by point, would cost them most of the reading. These make the same pieces without them.


def as_points(xy: FloatArray) -> list[tuple[float, float]]:
    """Points (n, 2), mm, as the (x, y) tuples of floats the pieces hold."""
    return list(zip(xy[:, 0].tolist(), xy[:, 1].tolist(), strict=True))


def trusted_lines(starts: list[tuple[float, float]], ends: list[tuple[float, float]]) -> list[Line]:
    """``Line(start, end)`` for each pair, unchecked: each point a tuple of two finite floats, each
    ``start != end``."""
    new, out = object.__new__, []
    for a, b in zip(starts, ends, strict=True):
        line = new(Line)
        fields = line.__dict__
        fields["start"] = a
        fields["end"] = b
        out.append(line)
    return out


def trusted_arcs(
    centers: list[tuple[float, float]], radii: FloatArray, start_angles: FloatArray, sweeps: FloatArray
) -> list[CircularArc]:
    """``CircularArc(center, radius, start_angle, sweep)`` for each, unchecked: each centre a tuple of
    two finite floats, each radius finite and positive, each start angle finite, each sweep finite,
    nonzero and at most one turn (:func:`arcs_are_valid`). The numbers are kept as given (numpy's
    floats from an array's elements)."""
    new, out = object.__new__, []
    for c, r, a, w in zip(centers, radii, start_angles, sweeps, strict=True):
        arc = new(CircularArc)
        fields = arc.__dict__
        fields["center"] = c
        fields["radius"] = r
        fields["start_angle"] = a
        fields["sweep"] = w
        out.append(arc)
    return out


def arcs_are_valid(centers: FloatArray, radii: FloatArray, start_angles: FloatArray, sweeps: FloatArray) -> bool:
    """Whether :class:`CircularArc` takes each of these (centres shape (n, 2)), as its constructor checks."""
    return bool(
        np.isfinite(centers).all()
        and np.all(np.isfinite(radii) & (radii > 0))
        and np.isfinite(start_angles).all()
        and np.all(np.isfinite(sweeps) & (np.abs(sweeps) > 0) & (np.abs(sweeps) <= 2 * math.pi + 1e-12))
    )


def lines_are_valid(starts: FloatArray, ends: FloatArray) -> bool:
    """Whether :class:`Line` takes each pair of these (shape (n, 2)) as its constructor checks: finite
    points, distinct (then of nonzero length)."""
    return bool(np.isfinite(starts).all() and np.isfinite(ends).all() and np.all((starts != ends).any(axis=1)))
