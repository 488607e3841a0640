"""A quasi-static world: the jaw as a rigid straight edge on a compliant wrist, no dynamics.

The hand pose (x, y, φ) puts the wrist's axis at (x, y) on the jaw's edge line,
the edge running along e = (cos φ, sin φ) over ±``half_span`` mm; the part lies
on the side of m = (-sin φ, cos φ). Where the edge would cut into the part, the
wrist gives along m by the depth of the deepest point and the contact force is
``stiffness`` times that depth. The deepest point is the part's support point
in the direction -m: a straight edge touches the part's convex hull, so across
a concavity the contact jumps from one side to the other and the jaw bridges.
"""

from __future__ import annotations

import numpy as np

from localizer import Part

from ._errors import SimError
from .world import Contact

__all__ = ["QuasiStaticWorld", "tangent_point"]


class QuasiStaticWorld:
    """Jaw and part at static equilibrium for each commanded hand pose.

    Parameters
    ----------
    part : Part
        The real part (machined, if so).
    stiffness : float, N/mm
        The wrist's compliance along the jaw normal.
    half_span : float, mm
        Half the jaw's length (paper: 50).
    """

    def __init__(self, part: Part, *, stiffness: float = 1.0, half_span: float = 50.0):
        if not (stiffness > 0 and half_span > 0):
            raise SimError(f"stiffness={stiffness!r} N/mm and half_span={half_span!r} mm must be positive")
        self.part = part
        self.stiffness = float(stiffness)
        self.half_span = float(half_span)
        self._t = np.arange(part.n_knots * 32) / 32.0
        self._xy = part.point(self._t)
        self.hand: tuple[float, float, float] | None = (0.0, 0.0, 0.0)

    def set_hand(self, x: float, y: float, phi: float) -> None:
        """Put the hand (wrist axis at (x, y) mm, jaw angle φ rad) there."""
        self.hand = (float(x), float(y), float(phi))

    def contact(self) -> Contact:
        """The contact for the present hand pose (force 0 when the jaw is clear)."""
        x, y, phi = self.hand or (0.0, 0.0, 0.0)
        e = np.array([np.cos(phi), np.sin(phi)])
        m = np.array([-np.sin(phi), np.cos(phi)])
        rel = self._xy - (x, y)
        u = rel @ e
        depth = -(rel @ m)
        inside = np.abs(u) <= self.half_span
        if not inside.any():
            return Contact(0.0, 0.0, float("nan"), 0.0, False)
        k = int(np.argmax(np.where(inside, depth, -np.inf)))
        t = self._refine(self._t[k], phi)
        p = self.part.point(t)
        du = float((p - (x, y)) @ e)
        dd = float(-((p - (x, y)) @ m))
        at_edge = abs(du) > self.half_span + 1e-6
        if at_edge:  # the deepest point lies beyond the jaw: the jaw's end is what touches
            t, du, dd = float(self._t[k]), float(u[k]), float(depth[k])
        if dd <= 0:
            return Contact(0.0, du, float(t) % self.part.n_knots, dd, at_edge)
        return Contact(self.stiffness * dd, du, float(t) % self.part.n_knots, dd, at_edge)

    def _refine(self, t0: float, phi: float) -> float:
        return tangent_point(self.part, t0, phi)


def tangent_point(part: Part, t0: float, phi: float) -> float:
    """Spline parameter near ``t0`` where the part's tangent has angle ``phi`` (mod 2π).

    Newton on the tangent angle: where a straight edge at angle φ touches a
    convex stretch. Returns ``t0`` if the part is concave there.
    """
    t = t0
    for _ in range(8):
        f = float(np.angle(np.exp(1j * (part.tangent_angle(t) - phi))))
        df = float(part.curvature(t) * part.speed(t))
        if df <= 0:
            return t0
        step = float(np.clip(f / df, -1.0 / 32, 1.0 / 32))
        t -= step
        if abs(step) < 1e-13:
            break
    return t
