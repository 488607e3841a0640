"""Independent brute-force references for the localizer tests.

Written from the problem statement only, not from the solver: scipy's
periodic CubicSpline through the points, arc length by composite Simpson on
a dense parameter grid, tangent angle by unwrapping atan2 on that grid, and
the feasible starts as sign changes of g on the dense grid refined with
brentq on a cubic interpolant of θ(σ).
"""

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq


def random_part_points(rng, n=None, convex=None, harmonics=5, jitter=0.0):
    """Star-shaped random smooth outline (simple by construction).

    ``harmonics`` up to 24 and a radial ``jitter`` (mm, uniform ±) make a rough outline as traced
    from a silhouette, whose curvature changes fast.
    """
    n = n or int(rng.integers(16, 60))
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = np.full(n, 40.0)
    amp = 1.0 if convex else 5.0 if convex is False else rng.uniform(0.5, 5.0)
    for k in range(2, harmonics + 1):
        r += amp / k * rng.uniform(-1, 1) * np.cos(k * a + rng.uniform(0, 2 * np.pi))
    r += rng.uniform(-jitter, jitter, n)
    return np.c_[r * np.cos(a), r * np.sin(a)]


class DenseCurve:
    """Dense tabulation of the closed spline through ``points``."""

    def __init__(self, points, per_piece=600):
        pts = np.asarray(points, float)
        n = len(pts)
        self.n = n
        cs = CubicSpline(np.arange(n + 1), np.vstack([pts, pts[:1]]), bc_type="periodic")
        d1 = cs.derivative()
        m = 2 * per_piece  # even number of intervals for Simpson
        t = np.linspace(0, n, n * m + 1)
        v = np.linalg.norm(d1(t), axis=1)
        h = t[1] - t[0]
        # cumulative Simpson on pairs of intervals
        pair = h / 3 * (v[0:-1:2] + 4 * v[1::2] + v[2::2])
        cum = np.concatenate([[0.0], np.cumsum(pair)])
        self.t = t[::2]
        self.sigma = cum
        self.perimeter = cum[-1]
        d = d1(self.t)
        self.theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
        self._theta_of_sigma = CubicSpline(self.sigma, self.theta)

    def theta_at(self, sigma):
        """Unwrapped tangent angle at any arc position (wraps add 2π per lap)."""
        sigma = np.asarray(sigma, float)
        lap = np.floor(sigma / self.perimeter)
        return self._theta_of_sigma(sigma - lap * self.perimeter) + 2 * np.pi * lap

    def feasible_starts(self, length, turn):
        s = self.sigma[:-1]
        g = self.theta_at(s + length) - self.theta_at(s) - turn
        idx = np.flatnonzero(np.sign(g) != np.sign(np.roll(g, -1)))
        roots = []

        def f(x):
            return float(self.theta_at(x + length) - self.theta_at(x) - turn)

        for i in idx:
            a, b = s[i], (s[i + 1] if i + 1 < len(s) else self.perimeter)
            if g[i] == 0:
                roots.append(a)
            else:
                roots.append(brentq(f, a, b, xtol=1e-13))
        return np.sort(np.mod(roots, self.perimeter))


class ChordAngle:
    """θ by arc position from the directions of a dense polyline's chords (independent of Outline's
    bookkeeping of corners and pieces)."""

    def __init__(self, outline, spacing=0.002):
        self.H = spacing  # mm between the points
        self.P = outline.perimeter
        s = np.arange(0.0, self.P, self.H)
        xy = outline.point_at_arc(s)
        d = np.diff(np.vstack([xy, xy[:1]]), axis=0)
        raw = np.arctan2(d[:, 1], d[:, 0])
        self.theta = raw[0] + np.concatenate([[0.0], np.cumsum((np.diff(raw) + np.pi) % (2 * np.pi) - np.pi)])
        self.mid = s + self.H / 2  # a chord's direction is the tangent's at its middle (to O(H²))

    def __call__(self, sigma):
        sigma = np.asarray(sigma, dtype=float)
        lap = np.floor(sigma / self.P)
        return np.interp(sigma - lap * self.P, self.mid, self.theta) + 2 * np.pi * lap
