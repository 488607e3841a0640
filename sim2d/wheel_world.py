"""A kinematic world for the wheel finger: a disc on an axle, pressed on the part through a compliant wrist.

The hand pose (x, y, φ) commands the axle at (x, y); the hand's axis points from the axle towards the
part along m = (−sin φ, cos φ), as the straight jaw's normal does. The rigid disc of radius r cannot
cut into the part: the wrist gives, the disc's centre displaced from the commanded axle to the nearest
place where nothing of the part is nearer than r (pushed out along the contact normal; in a pocket
too narrow for it, the disc rests on both walls). The force is the wrist's stiffness times the
displacement (the depth), along it: its angle β, the displacement being along (sin β, −cos β), is the
contact normal's tangent angle (β = θ on a smooth stretch).

The disc turns on its bearing only by rolling (docs/wheel.md): while the contact runs along the part
by dσ, the disc turns by dθ + dσ/r in the world (its material point at the contact at rest), i.e.
by the change of the direction from the contact to the axle plus the arc over the radius. At a corner
of an outline, or where the disc straddles a pocket it cannot enter and the contact jumps to the far
side, no arc of the part is rolled: the disc pivots about the contact with the axle, ψ turning with
the direction alone. The axle encoder reads ψ − φ (relative to the hand).

The arc rolled is the real part's: a part made 2% larger than its model rolls 2% more arc between two
contacts the model places alike (the contacts are reported in the model's arc positions, the disc
turns by the real ones). Boundary that stands for no arc of the model, the round a drawing's
machining leaves at a corner (:func:`sim2d.offset.offset_boundary` tags it with the corner's one
arc), is pivoted over as the model's sharp corner is: its few µm of rolling are not modelled (a
real part's edge break is: left to a part file of its own).

``slip`` makes the disc lose that fraction of the rolled arc (a slipping rim), which the rolling
procedure must report.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from localizer import Part, check_grid

from ._errors import SimError
from .sampled import SampledPart

__all__ = ["WheelWorld", "WheelContact", "SAMPLE_STEP", "JUMP_EXCESS"]

#: Spacing of the dense sample of the real boundary the disc is pressed on (mm). A chord of the sample
#: lies off a curve of curvature κ by h²κ/8: 3 nm at κ = 0.2/mm.
SAMPLE_STEP = 0.01
#: A contact that moved along the part by more than its straight-line move plus this (mm) jumped across
#: what the disc could not enter (the straight jaw's bridge test, localizer.BRIDGE_EXCESS).
JUMP_EXCESS = 0.01


@dataclass(frozen=True)
class WheelContact:
    """Where and how hard the disc touches the part.

    Attributes
    ----------
    force : float, N
        Contact force (0 when clear).
    normal : float, rad
        Tangent angle of the contact normal β: the contact lies at (−sin β, cos β) from the axle.
    arc : float, mm
        The model's arc position of the contact (NaN when clear).
    depth : float, mm
        How far the part would cut into the rigid disc (the wrist's give); negative: clear by that much.
    """

    force: float
    normal: float
    arc: float
    depth: float


class WheelWorld:
    """A disc of ``radius`` mm at static equilibrium on the part for each commanded axle pose.

    Parameters
    ----------
    part : Part or SampledPart
        The real part (machined, if so).
    model : Part or Outline
        The model whose arc positions the contacts report.
    radius : float, mm
    stiffness : float, N/mm
        The wrist's compliance along the contact normal.
    slip : float
        Fraction of the rolled arc the rim loses (0: pure rolling).
    """

    def __init__(self, part, model, radius: float, *, stiffness: float = 1.0, slip: float = 0.0):
        if not (math.isfinite(radius) and radius > 0):
            raise SimError(f"wheel radius={radius!r} mm must be positive")
        if not (math.isfinite(stiffness) and stiffness > 0):
            raise SimError(f"stiffness={stiffness!r} N/mm must be positive")
        if not (math.isfinite(slip) and 0 <= slip < 1):
            raise SimError(f"slip={slip!r} must be in [0, 1)")
        self.radius, self.stiffness, self.slip = float(radius), float(stiffness), float(slip)
        self.perimeter = float(model.perimeter)
        self._spline: Part | None = None
        if isinstance(part, SampledPart):
            self._xy, self._arc = np.asarray(part.xy, dtype=float), np.asarray(part.arcs, dtype=float)
            rolled = np.hypot(*(np.roll(self._xy, -1, axis=0) - self._xy).T)  # each sample chord's real arc
        elif isinstance(part, Part):
            n = max(256, int(math.ceil(part.perimeter / SAMPLE_STEP)))
            check_grid(part, "wheel world", SAMPLE_STEP, n)
            self._t = np.asarray(part.param_at_arc(np.arange(n) * part.perimeter / n), dtype=float)
            self._xy = np.asarray(part.point(self._t), dtype=float)
            # the machined spline's parameters are the model's (sim2d.machining.machined_part)
            self._arc = np.asarray(model.wrap_arc(model.arc_at_param(self._t)), dtype=float)
            self._spline, self._model = part, model
            rolled = np.full(n, part.perimeter / n)
        else:
            raise SimError(f"a wheel world needs a Part or a SampledPart, not {type(part).__name__}")
        self._model_arc, self._real_arc = _arc_map(self._arc, rolled, self.perimeter)
        self.real_perimeter = float(self._real_arc[-1])
        self._tree = cKDTree(self._xy)
        self.hand: tuple[float, float, float] | None = None
        # (arc, contact, disc centre, depth) of the disc as set_hand seated it: contact() reads it
        self._seated: tuple[float, np.ndarray, np.ndarray, float] = (math.nan, np.zeros(2), np.zeros(2), -math.inf)
        self.psi = 0.0
        self._last: tuple[float, np.ndarray, np.ndarray] | None = None  # (arc, point, axle) of the last contact

    # ----------------------------------------------------------- geometry
    def real_arc(self, arc: float) -> float:
        """The real part's arc (mm from its first sample) at the model's arc ``arc`` (mm)."""
        a0 = float(self._model_arc[0])
        return float(np.interp((arc - a0) % self.perimeter + a0, self._model_arc, self._real_arc))

    def nearest(self, c: np.ndarray) -> tuple[float, np.ndarray, float]:
        """(model arc mm, point, distance mm) of the boundary point nearest to ``c``."""
        _, k = self._tree.query(c)
        n = self._xy.shape[0]
        best = (math.inf, 0.0, self._xy[k])
        t_chord = (int(k), 0.0)
        for j in (k - 1, k):  # the two sample chords at the nearest sample
            a, b = self._xy[j % n], self._xy[(j + 1) % n]
            ab = b - a
            u = float(np.clip((c - a) @ ab / max(float(ab @ ab), 1e-300), 0.0, 1.0))
            p = a + u * ab
            d = float(np.hypot(*(c - p)))
            if d < best[0]:
                a0, a1 = self._arc[j % n], self._arc[(j + 1) % n]
                da = (a1 - a0 + self.perimeter / 2) % self.perimeter - self.perimeter / 2
                best = (d, float((a0 + u * da) % self.perimeter), p)
                t_chord = (j % n, u)
        if self._spline is None:
            return best[1], best[2], best[0]
        return self._on_spline(c, *t_chord)

    def _on_spline(self, c: np.ndarray, j: int, u: float) -> tuple[float, np.ndarray, float]:
        """The nearest point refined on the spline from the chord's (Newton on (P − c)·T = 0)."""
        spline = self._spline
        assert spline is not None
        t0, t1 = self._t[j], self._t[(j + 1) % self._t.size]
        if t1 < t0:
            t1 += spline.n_knots
        t = t0 + u * (t1 - t0)
        for _ in range(3):
            p = spline.point(t)
            th, k, v = float(spline.tangent_angle(t)), float(spline.curvature(t)), float(spline.speed(t))
            rel = p - c
            f = rel[0] * math.cos(th) + rel[1] * math.sin(th)
            df = v * (1.0 + k * (-rel[0] * math.sin(th) + rel[1] * math.cos(th)))
            if df <= 0:
                break
            t -= f / df
        p = spline.point(t)
        arc = float(self._model.wrap_arc(self._model.arc_at_param(t)))
        return arc, p, float(np.hypot(*(c - p)))

    def _seat(self, c: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, float]:
        """Where the disc sits with its axle commanded at ``c``: (model arc of the contact, contact point,
        the disc's centre, depth mm). The wrist gives so that no point of the part comes nearer to the
        disc's centre than r: the centre is pushed out from the nearest point, again until nothing is
        nearer (in a pocket too narrow for the disc it settles touching both walls). Depth ≤ 0: clear."""
        arc, p, d = self.nearest(c)
        if d >= self.radius:
            return arc, p, c, self.radius - d
        if d < 1e-9:
            raise SimError(f"the axle was commanded onto the part at {tuple(np.round(c, 4))}: press less")
        centre = c
        for _ in range(200):
            centre = p + (centre - p) * (self.radius / d)
            arc, p, d = self.nearest(centre)
            if d >= self.radius - 1e-9:
                break
        return arc, p, centre, float(np.hypot(*(centre - c)))

    def set_hand(self, x: float, y: float, phi: float) -> None:
        """Put the axle at (``x``, ``y``) mm and the hand at angle ``phi`` rad; the disc rolls there."""
        self.hand = (float(x), float(y), float(phi))
        arc, p, centre, depth = self._seated = self._seat(np.array([x, y], dtype=float))
        if depth <= 0:  # clear: the disc keeps its angle on the bearing
            self._last = None
            return
        if self._last is not None:
            arc0, p0, c0 = self._last
            turn = _angle(centre - p) - _angle(c0 - p0)
            turn = (turn + math.pi) % (2 * math.pi) - math.pi
            period = self.real_perimeter
            along = (self.real_arc(arc) - self.real_arc(arc0) + period / 2) % period - period / 2
            rolled = abs(along) <= float(np.hypot(*(p - p0))) + JUMP_EXCESS
            self.psi += turn + (along * (1.0 - self.slip) / self.radius if rolled else 0.0)
        self._last = (arc, p, centre)

    def contact(self) -> WheelContact:
        """The contact for the present axle pose (force 0 when the disc is clear). The force is the
        wrist's spring, along the disc's displacement from the commanded axle."""
        if self.hand is None:
            return WheelContact(0.0, math.nan, math.nan, -math.inf)
        c = np.array(self.hand[:2])
        arc, p, centre, depth = self._seated  # where set_hand seated it
        if depth <= 0:
            return WheelContact(0.0, math.nan, math.nan, depth)
        v = c - centre  # the spring pulls the disc back towards the commanded axle: (−sin β, cos β)
        return WheelContact(self.stiffness * depth, math.atan2(-v[0], v[1]), arc, depth)

    def encoder(self) -> float:
        """The disc's angle relative to the hand, rad (unwrapped, as an incremental encoder counts)."""
        return self.psi - (self.hand[2] if self.hand else 0.0)


def _arc_map(arcs: np.ndarray, rolled: np.ndarray, perimeter: float) -> tuple[np.ndarray, np.ndarray]:
    """The real arc as a function of the model's: (model arc, real arc) at each sample and once round.

    ``arcs`` are the samples' model arcs in order round the part (mm, wrapping once), ``rolled`` the real
    arc from each sample to the next (mm). A step that advances no model arc (a corner's round, or a
    registered scan's sample that steps back) adds no real arc: it is pivoted over."""
    step = (np.roll(arcs, -1) - arcs + perimeter / 2) % perimeter - perimeter / 2
    advances = step > 1e-12
    model = arcs[0] + np.concatenate(([0.0], np.cumsum(np.where(advances, step, 0.0))))
    model = np.minimum(np.maximum.accumulate(model), arcs[0] + perimeter)
    model[-1] = arcs[0] + perimeter
    real = np.concatenate(([0.0], np.cumsum(np.where(advances, rolled, 0.0))))
    return model, real


def _angle(v: np.ndarray) -> float:
    return math.atan2(float(v[1]), float(v[0]))
