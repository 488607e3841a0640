"""A quasi-static world: the jaw as a rigid straight edge on a compliant wrist, no dynamics.

The hand pose (x, y, φ) puts the wrist's axis at (x, y) on the jaw's edge line,
the edge running along e = (cos φ, sin φ) over ±``half_span`` mm; the part lies
on the side of m = (-sin φ, cos φ). Where the edge would cut into the part, the
wrist gives along m by the depth of the deepest point and the contact force is
``stiffness`` times that depth. The deepest point is the part's support point
in the direction -m: a straight edge touches the part's convex hull, so across
a concavity the contact jumps from one side to the other and the jaw bridges.

On an outline from CAD (:class:`sim2d.sampled.SampledPart`) the same holds point by point
over its dense sample: at a convex corner the corner stays the deepest point while the jaw turns
through the jump (a pivot). Lying flush on a face the rigid jaw touches a line: the load is
taken as shared evenly by the points within :data:`FLUSH` of the deepest, so the wrist reads their
middle (the centre of pressure) and the contact's arc is theirs. A machined face is wavy by
microns, so flush contact is the exception there, and the jaw rests on the highest bump.
"""

from __future__ import annotations

import math

import numpy as np

from localizer import Part

from ._errors import SimError
from .sampled import BLOCK, SampledPart
from .world import Contact

__all__ = ["QuasiStaticWorld", "tangent_point", "outline_touch", "FLUSH"]

#: Points of an outline within this depth of the deepest share the load (mm): the jaw lies flush. A
#: nanometre: an exactly flat face at its own angle (up to rounding), as the filter takes it
#: (``localizer`` FLUSH_TURN); a compliant contact would spread the load before that, which neither models.
FLUSH = 1e-6
#: A contact this close to the jaw's end (mm), four of the outline's sample steps, is at its edge.
EDGE = 0.02


class QuasiStaticWorld:
    """Jaw and part at static equilibrium for each commanded hand pose.

    Parameters
    ----------
    part : Part or SampledPart
        The real part (machined, if so). On a spline the contact's ``param`` is the spline
        parameter; on an outline it is the model's arc position (mm).
    stiffness : float, N/mm
        The wrist's compliance along the jaw normal.
    half_span : float, mm
        Half the jaw's length (paper: 50).
    """

    def __init__(self, part: Part | SampledPart, *, stiffness: float = 1.0, half_span: float = 50.0):
        if not (stiffness > 0 and half_span > 0):
            raise SimError(f"stiffness={stiffness!r} N/mm and half_span={half_span!r} mm must be positive")
        self.part = part
        self.stiffness = float(stiffness)
        self.half_span = float(half_span)
        self._spline = None if isinstance(part, SampledPart) else part
        if not isinstance(part, SampledPart):
            self._t = np.arange(part.n_knots * 32) / 32.0
            xy = part.point(self._t)
            self._x, self._y = xy[:, 0].copy(), xy[:, 1].copy()
        self.hand: tuple[float, float, float] | None = (0.0, 0.0, 0.0)
        # the contact is a function of the hand's pose alone; a reading and the truth ask for the same one
        self._last: tuple[tuple[float, float, float] | None, Contact] | None = None

    def set_hand(self, x: float, y: float, phi: float) -> None:
        """Put the hand (wrist axis at (x, y) mm, jaw angle φ rad) there."""
        self.hand = (float(x), float(y), float(phi))

    def contact(self) -> Contact:
        """The contact for the present hand pose (force 0 when the jaw is clear)."""
        if self._last is not None and self._last[0] == self.hand:
            return self._last[1]
        c = self._contact()
        self._last = (self.hand, c)
        return c

    def _contact(self) -> Contact:
        x, y, phi = self.hand or (0.0, 0.0, 0.0)
        spline = self._spline
        if spline is None:
            assert isinstance(self.part, SampledPart)
            under, du_o, arc, dd_o, edge = outline_touch(self.part, (x, y), phi, self.half_span)
            if not under:
                return Contact(0.0, 0.0, float("nan"), 0.0, False)
            return Contact(self.stiffness * dd_o if dd_o > 0 else 0.0, du_o, arc, dd_o, edge)
        e = np.array([np.cos(phi), np.sin(phi)])
        m = np.array([-np.sin(phi), np.cos(phi)])
        rx, ry = self._x - x, self._y - y
        u = rx * e[0] + ry * e[1]
        depth = -(rx * m[0] + ry * m[1])
        inside = np.abs(u) <= self.half_span
        if not inside.any():
            return Contact(0.0, 0.0, float("nan"), 0.0, False)
        k = int(np.argmax(np.where(inside, depth, -np.inf)))
        t = tangent_point(spline, self._t[k], phi)
        p = spline.point(t)
        du = float((p - (x, y)) @ e)
        dd = float(-((p - (x, y)) @ m))
        at_edge = abs(du) > self.half_span + 1e-6
        if at_edge:  # the deepest point lies beyond the jaw: the jaw's end is what touches
            t, du, dd = float(self._t[k]), float(u[k]), float(depth[k])
        if dd <= 0:
            return Contact(0.0, du, float(t) % spline.n_knots, dd, at_edge)
        return Contact(self.stiffness * dd, du, float(t) % spline.n_knots, dd, at_edge)


def outline_touch(
    outline: SampledPart, origin: tuple[float, float], phi: float, half_span: float
) -> tuple[bool, float, float, float, bool]:
    """Where a straight edge touches a sampled outline: the deepest point, or the middle of a flush line.

    Parameters
    ----------
    outline : SampledPart
    origin : (float, float), mm
        The point of the edge's line from which places along it are measured (the jaw's centre).
    phi : float, rad
        The edge's direction; the part lies on its left.
    half_span : float, mm
        Half the edge's length.

    Returns
    -------
    under, jaw_position, arc, depth, at_edge
        Whether any point lies under the edge; the contact's place along the edge (mm), its
        model arc position (mm), how deep the deepest point lies beyond the edge's line (mm,
        negative: clear), and whether the edge's end is what touches.
    """
    e = np.array([np.cos(phi), np.sin(phi)])
    m = np.array([-np.sin(phi), np.cos(phi)])
    # only the runs of points that may hold the deepest point under the edge or one flush with it: a run
    # lies within its radius r of its middle point, so none of it is deeper than that point's depth plus r,
    # and the deepest point under the edge is at least as deep as any middle point under it (the radii
    # widened by 1e-9 mm, far above the rounding of coordinates of a few hundred mm)
    middle, r = outline.blocks
    r = r + 1e-9
    rel_m = outline.xy[middle] - origin
    u_m, d_m = rel_m @ e, -(rel_m @ m)
    under = np.abs(u_m) <= half_span
    floor = float(d_m[under].max()) - FLUSH if under.any() else -np.inf
    runs = np.flatnonzero((np.abs(u_m) - r <= half_span) & (d_m + r >= floor))
    idx = (runs[:, None] * BLOCK + np.arange(BLOCK)).ravel()
    idx = idx[idx < outline.xy.shape[0]]
    rel = outline.xy[idx] - origin
    u = rel @ e
    depth = -(rel @ m)
    inside = np.abs(u) <= half_span
    if not inside.any():
        return False, 0.0, float("nan"), 0.0, False
    k = int(np.argmax(np.where(inside, depth, -np.inf)))
    flush = inside & (depth >= depth[k] - FLUSH)
    P = outline.perimeter
    arcs = outline.arcs[idx]
    # arcs relative to the deepest point's, so that a face across the first point stays whole
    rel_arc = (arcs[flush] - arcs[k] + P / 2) % P - P / 2
    arc = float((arcs[k] + rel_arc.mean()) % P)
    # the deepest point the last one under the jaw, not a line: the jaw's end is what touches
    line = float(np.ptp(u[flush])) > EDGE
    at_edge = not line and abs(float(u[k])) >= half_span - EDGE
    return True, float(u[flush].mean()), arc, float(depth[k]), at_edge


def tangent_point(part: Part, t0: float, phi: float) -> float:
    """Spline parameter near ``t0`` where the part's tangent has angle ``phi`` (mod 2π).

    Newton on the tangent angle: where a straight edge at angle φ touches a
    convex stretch. Returns ``t0`` if the part is concave there.

    Scalar arithmetic on one piece's derivatives per step: called for every reading of the
    simulated rig, it was a third of a trial's cost as array calls on single values.
    """
    n = part.n_knots
    t = t0
    for _ in range(8):
        tt = t % n
        piece = min(int(tt), n - 1)
        dx, dy, ddx, ddy = (float(v) for v in part.derivatives(piece, tt - piece))
        f = (math.atan2(dy, dx) - phi + math.pi) % math.tau - math.pi
        df = (dx * ddy - dy * ddx) / (dx * dx + dy * dy)  # dθ/dt = κ·speed
        if df <= 0:
            return t0
        step = min(max(f / df, -1.0 / 32), 1.0 / 32)
        t -= step
        if abs(step) < 1e-13:
            break
    return t
