"""The pymunk world: a kinematic hand, a dynamic jaw on a compliant wrist, a static polygonised part.

Units inside the space: millimetres, kilograms, seconds, so a force is in
kg·mm/s² = mN. The part is a chain of static segments through the spline,
polygonised to a chord tolerance (an outline from CAD: through its machined
sample, one segment per face, every corner a vertex); the hand is a kinematic
body without shapes, driven only by commands (velocity control with speed limits); the jaw is a
dynamic box whose edge (local y = 0, x in ±half_span) faces the part. The wrist
joins them: a groove lets the jaw slide along the jaw normal only, a damped
spring along that groove gives the wrist's compliance, and a gear joint keeps
the jaw's angle equal to the hand's. Contact force and location come from the
jaw's arbiters after each step. No randomness: a world is deterministic.

It offers the same ``set_hand`` / ``contact`` interface as
:class:`sim2d.quasistatic.QuasiStaticWorld`: ``set_hand`` drives the hand to the
pose at the speed limits and steps the space until the jaw has settled.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pymunk

from localizer import CircularArc, Line, Outline, Part

from ._errors import SimError
from .quasistatic import outline_touch, tangent_point
from .sampled import SampledPart, polygon_vertices
from .world import Contact

__all__ = ["PymunkWorld", "polygonise", "static_chain", "drive_hand", "solver_space", "Settle"]

_MN_PER_N = 1000.0
#: Steps in a row a body must move slower than the settling speed for it to be at rest, and the fewest
#: steps a settling takes (three time constants of the wrist's critically damped spring at 1 N/mm).
QUIET_STEPS = 5
MIN_SETTLE_STEPS = 20
#: The jaw is at rest when every point within its half-span moves slower than this, mm/s.
SETTLE_SPEED = 0.02
#: Polygonisation of a spline part, mm: its contact is refined on the spline itself (:meth:`PymunkWorld.contact`),
#: so the chord's sagitta only errs the jaw's depth by up to a micron.
CHORD_TOLERANCE = 1e-3
#: The share of an overlap, or of a joint's error, left uncorrected after a second (chipmunk's
#: ``collision_bias`` and ``error_bias``). chipmunk's default, 10% corrected every 1/60 s, left the jaw
#: creeping by microns for hundreds of steps after each move, which the settling had to wait out and
#: which kept the world's L 2 µm off the quasi-static equilibrium's; here both are corrected within steps.
SOLVER_BIAS = 1e-9


def solver_space() -> pymunk.Space:
    """An empty space set up for the rig's worlds: no gravity, 0.1 µm of allowed overlap, 30 solver
    iterations, overlaps corrected at :data:`SOLVER_BIAS` (give the same to the joints added)."""
    space = pymunk.Space()
    space.gravity = (0.0, 0.0)
    space.collision_slop = 1e-4
    space.iterations = 30
    space.collision_bias = SOLVER_BIAS
    return space


def polygonise(part: Part | SampledPart, chord_tolerance: float) -> np.ndarray:
    """Points on the spline whose chords stay within ``chord_tolerance`` mm of it (closed, first = last).

    Each piece gets n chords with the sagitta bound κ_max·h²/8 <= tolerance,
    h the longest chord (uniform parameter, speed variation allowed for).
    """
    return _polygon(part, chord_tolerance)[0]


def _polygon(part: Part | SampledPart, chord_tolerance: float):
    """(points, parameters) of :func:`polygonise`."""
    if not chord_tolerance > 0:
        raise SimError(f"chord_tolerance={chord_tolerance!r} mm must be positive")
    if isinstance(part, SampledPart):
        if isinstance(part.model, Outline) and not part.altered:
            return _outline_polygon(part, chord_tolerance)
        return _sample_polygon(part, chord_tolerance)
    ts = []
    for i in range(part.n_knots):
        u = i + np.linspace(0.0, 1.0, 33)
        speed = part.speed(u)
        kappa = np.abs(part.curvature(u)).max()
        length = float(part.arc_length(float(i), float(i + 1)))
        h_max = math.sqrt(8.0 * chord_tolerance / max(kappa, 1e-12))
        n = max(1, math.ceil(length * (speed.max() / speed.mean()) / h_max))
        ts.append(i + np.arange(n) / n)
    t = np.concatenate(ts)
    pts = part.point(t)
    return np.vstack([pts, pts[:1]]), t


def _outline_polygon(machined: SampledPart, chord_tolerance: float):
    """(points, arcs) of the machined outline's polygon: its sample points at every corner and at both
    ends of every line longer than a chord (one chord per such line), and along each curved stretch
    between them vertices spaced so that a chord's sagitta κ·h²/8 on the model meets the tolerance, κ
    the largest curvature of the piece or its neighbours. A curved stretch is spaced as a whole, not
    piece by piece: a faceted drawing read as thousands of short arcs gets the vertices its curve
    needs, not one per arc. The machined deviation between vertices is left to the contact's
    refinement on the dense sample (:func:`sim2d.quasistatic.outline_touch`)."""
    model = machined.model
    assert isinstance(model, Outline)
    n = len(model.pieces)
    starts = np.asarray(model.starts, float)
    lengths = np.diff(starts)
    perimeter = float(starts[-1])
    line = np.zeros(n, bool)
    kappa = np.zeros(n)
    for i, piece in enumerate(model.pieces):
        if isinstance(piece, Line):
            line[i] = True
        elif isinstance(piece, CircularArc):
            kappa[i] = 1.0 / piece.radius
        else:
            kappa[i] = float(np.abs(piece.curvature(np.linspace(0.0, piece.length, 65))).max())
    # a chord across a piece's end lies on both pieces
    kappa = np.maximum(kappa, np.maximum(np.roll(kappa, 1), np.roll(kappa, -1)))
    # the chord the sagitta allows, less one sample step: each vertex is moved to the nearest sample
    chord = np.sqrt(8.0 * chord_tolerance / np.maximum(kappa, 1e-12))
    step = float(np.diff(machined.arcs).max())
    density = 1.0 / np.maximum(chord - step, 0.5 * chord)  # chords per mm
    # a line longer than a chord is one chord, its ends vertices; a shorter one (a faceted curve's
    # remnant between two arcs) is part of the curve: its neighbours' curvature bounds the sagitta
    alone = line & (lengths * density >= 1.0)
    density[alone] = 0.0
    forced = alone | np.roll(alone, 1)
    if model.corners:
        at = np.searchsorted(starts[:-1], [c.arc for c in model.corners]).clip(0, n - 1)
        forced[at] = True
    first = np.flatnonzero(forced)
    if first.size == 0:
        first = np.array([0])
    # two laps of the cumulative chord count, so that a stretch may run on past the seam
    cum = np.concatenate([[0.0], np.cumsum(np.concatenate([density * lengths] * 2))])
    arc2 = np.concatenate([starts[:-1], starts[:-1] + perimeter, [2.0 * perimeter]])
    density2 = np.concatenate([density, density])
    stop = np.append(first[1:], first[0] + n)
    span = cum[stop] - cum[first]
    count = np.maximum(1, np.ceil(span - 1e-9)).astype(int)
    stretch = np.repeat(np.arange(first.size), count)
    k = np.arange(stretch.size) - np.repeat(np.cumsum(count) - count, count)
    target = cum[first[stretch]] + span[stretch] * k / count[stretch]
    j = (np.searchsorted(cum, target, side="right") - 1).clip(0, 2 * n - 1)
    inside = np.where(density2[j] > 0, (target - cum[j]) / np.where(density2[j] > 0, density2[j], 1.0), 0.0)
    want = np.where(k == 0, starts[first[stretch]], arc2[j] + inside) % perimeter
    want = np.sort(want)
    # the nearest sample of the machined boundary (its corners are samples)
    j = np.clip(np.searchsorted(machined.arcs, want), 1, machined.arcs.size - 1)
    j = np.where(want - machined.arcs[j - 1] <= machined.arcs[j] - want, j - 1, j)
    j = np.unique(j)
    pts = machined.xy[j]
    return np.vstack([pts, pts[:1]]), machined.arcs[j]


def _sample_polygon(sampled: SampledPart, chord_tolerance: float):
    """(points, arcs) of a polygon through a sampled part's points within ``chord_tolerance`` of it
    (:func:`sim2d.sampled.polygon_vertices`), every corner of the model a vertex."""
    corners = [c.arc for c in sampled.model.corners]
    keep = np.searchsorted(sampled.arcs, corners) % sampled.arcs.size if corners else None
    j = polygon_vertices(sampled.xy, chord_tolerance, keep)
    pts = sampled.xy[j]
    return np.vstack([pts, pts[:1]]), sampled.arcs[j]


def static_chain(space: pymunk.Space, pts: np.ndarray, friction: float) -> None:
    """Add the closed polygon ``pts`` (first = last, mm) to ``space`` as static segments with ``friction``,
    each told its neighbours so that a body sliding over a vertex does not catch on it."""
    body = space.static_body
    n = len(pts) - 1
    segs = []
    for i in range(n):
        seg = pymunk.Segment(body, tuple(pts[i]), tuple(pts[i + 1]), 0.0)
        seg.friction = friction
        segs.append(seg)
    for i, seg in enumerate(segs):
        seg.set_neighbors(tuple(pts[i - 1]), tuple(pts[(i + 2) % n]))
    space.add(*segs)


class Settle(NamedTuple):
    """How a world settles after the hand reaches a pose: at most ``steps`` steps, fewer once every point
    of ``body`` within ``reach`` mm of its centre moves slower than ``speed`` mm/s for
    :data:`QUIET_STEPS` steps in a row (and :data:`MIN_SETTLE_STEPS` have run); ``speed`` 0 or no body:
    always ``steps``."""

    steps: int
    speed: float = 0.0
    body: pymunk.Body | None = None
    reach: float = 0.0


def drive_hand(
    space: pymunk.Space,
    hand: pymunk.Body,
    pose: tuple[float, float, float],
    dt: float,
    linear_speed: float,
    angular_speed: float,
    settle: Settle,
) -> int:
    """Drive the kinematic ``hand`` to ``pose`` (mm, mm, rad) at the speed limits (mm/s, rad/s), stepping
    ``space`` by ``dt`` s, then let it ``settle``; the number of steps taken."""
    x, y, phi = (float(v) for v in pose)
    target = np.array([x, y], float)
    steps = 0
    for _ in range(1_000_000):
        dp = target - np.array(hand.position)
        da = phi - hand.angle
        dist = float(np.hypot(*dp))
        if dist < 1e-9 and abs(da) < 1e-12:
            break
        # a common time to arrive, within both speed limits
        t = max(dist / linear_speed, abs(da) / angular_speed, dt)
        frac = dt / t
        hand.velocity = tuple(dp * frac / dt)
        hand.angular_velocity = da * frac / dt
        space.step(dt)
        steps += 1
    hand.velocity, hand.angular_velocity = (0.0, 0.0), 0.0
    hand.position, hand.angle = (x, y), phi
    body, still = settle.body, settle.speed * dt  # mm a step
    if body is None or still <= 0:
        for _ in range(settle.steps):
            space.step(dt)
        return steps + settle.steps
    quiet = 0
    last = (body.position.x, body.position.y, body.angle)
    for i in range(settle.steps):
        space.step(dt)
        # moved, not the velocity: chipmunk resolves overlap by a bias velocity the body's does not show
        now = (body.position.x, body.position.y, body.angle)
        moved = math.hypot(now[0] - last[0], now[1] - last[1]) + abs(now[2] - last[2]) * settle.reach
        last = now
        quiet = quiet + 1 if moved < still else 0
        if quiet >= QUIET_STEPS and i + 1 >= MIN_SETTLE_STEPS:
            return steps + i + 1
    return steps + settle.steps


class PymunkWorld:
    """The jaw rolling on the part in a pymunk space.

    Parameters
    ----------
    part : Part or SampledPart
        The real part: a spline, or an outline from CAD as machined. On an outline the contact's
        ``param`` is the model's arc position (mm), as in :class:`QuasiStaticWorld`.
    stiffness : float, N/mm
        Wrist compliance along the jaw normal.
    half_span : float, mm
        Half the jaw's length.
    chord_tolerance : float, mm
        Polygonisation tolerance of the part. pymunk decides whether, how hard and at which polygon
        vertex the jaw touches; the contact location is then refined on the spline the polygon
        approximates. Each step's cost grows with the segments under the jaw.
    friction : float
        Coulomb friction coefficient between jaw and part.
    dt : float, s
        Physics step.
    linear_speed, angular_speed : float, mm/s and rad/s
        The hand's speed limits.
    settle_steps : int
        The most steps run after the hand reaches a commanded pose.
    settle_speed : float, mm/s
        Fewer when the jaw has come to rest (:func:`drive_hand`); 0: always ``settle_steps``.
    """

    def __init__(
        self,
        part: Part | SampledPart,
        *,
        stiffness: float = 1.0,
        half_span: float = 50.0,
        chord_tolerance: float = CHORD_TOLERANCE,
        friction: float = 0.3,
        dt: float = 1e-3,
        linear_speed: float = 20.0,
        angular_speed: float = math.radians(30.0),
        settle_steps: int = 150,
        settle_speed: float = SETTLE_SPEED,
    ):
        if not (stiffness > 0 and half_span > 0 and dt > 0 and friction >= 0):
            raise SimError(
                f"stiffness={stiffness!r}, half_span={half_span!r}, dt={dt!r} must be positive "
                f"and friction={friction!r} >= 0"
            )
        self.part = part
        self.stiffness = float(stiffness)
        self.half_span = float(half_span)
        self.dt = float(dt)
        self.linear_speed = float(linear_speed)
        self.angular_speed = float(angular_speed)
        self.settle_steps = int(settle_steps)
        self.settle_speed = float(settle_speed)
        self.steps = 0
        space = solver_space()
        self.space = space
        pts, self._poly_t = _polygon(part, chord_tolerance)
        self.polygon = pts
        static_chain(space, pts, friction)
        self.hand_body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        mass, width = 0.05, 6.0
        verts = [(-half_span, -width), (half_span, -width), (half_span, 0.0), (-half_span, 0.0)]
        self.jaw_body = pymunk.Body(mass, pymunk.moment_for_poly(mass, verts))
        jaw = pymunk.Poly(self.jaw_body, verts)
        jaw.friction = friction
        rest = 20.0
        k = self.stiffness * _MN_PER_N  # mN/mm
        damping = 2.0 * math.sqrt(k * mass)  # critical
        groove = pymunk.GrooveJoint(self.hand_body, self.jaw_body, (0.0, -200.0), (0.0, 200.0), (0.0, 0.0))
        spring = pymunk.DampedSpring(self.hand_body, self.jaw_body, (0.0, -rest), (0.0, 0.0), rest, k, damping)
        gear = pymunk.GearJoint(self.hand_body, self.jaw_body, 0.0, 1.0)
        for joint in (groove, spring, gear):
            joint.error_bias = SOLVER_BIAS
        space.add(self.hand_body, self.jaw_body, jaw, groove, spring, gear)
        # not placed yet: the first command puts the arm there directly
        self.hand: tuple[float, float, float] | None = None

    def _place(self, x, y, phi):
        for b in (self.hand_body, self.jaw_body):
            b.position = (x, y)
            b.angle = phi
            b.velocity = (0.0, 0.0)
            b.angular_velocity = 0.0
        self.space.reindex_shapes_for_body(self.jaw_body)

    def set_hand(self, x: float, y: float, phi: float) -> None:
        """Drive the hand to the pose at the speed limits, then let the jaw settle.

        The first command places the hand and jaw there directly (the arm's
        start-up pose must be clear of the part).
        """
        if self.hand is None:
            self._place(float(x), float(y), float(phi))
        settle = Settle(self.settle_steps, self.settle_speed, self.jaw_body, self.half_span)
        self.steps += drive_hand(
            self.space, self.hand_body, (x, y, phi), self.dt, self.linear_speed, self.angular_speed, settle
        )
        self.hand = (float(x), float(y), float(phi))

    def step(self) -> None:
        """Advance the world by one time step (``dt`` s)."""
        self.space.step(self.dt)
        self.steps += 1

    def contact(self) -> Contact:
        """Force (N) and location on the jaw (mm) from the jaw's arbiters after the last step."""
        jb = self.jaw_body
        e = np.array([math.cos(jb.angle), math.sin(jb.angle)])
        m = np.array([-math.sin(jb.angle), math.cos(jb.angle)])
        if self.hand is None:
            return Contact(0.0, 0.0, float("nan"), 0.0, False)
        hx, hy, _ = self.hand
        total = 0.0
        points, depths = [], []

        def visit(arb):
            nonlocal total
            total += abs(float(np.dot(arb.total_impulse, m))) / self.dt / _MN_PER_N
            for p in arb.contact_point_set.points:
                if p.distance < 0:
                    points.append(np.array(p.point_a if arb.shapes[0].body is jb else p.point_b))
                    depths.append(-p.distance)

        jb.each_arbiter(visit)
        if total <= 0 or not points:
            return Contact(0.0, 0.0, float("nan"), 0.0, False)
        depth = float(-((np.array(jb.position) - (hx, hy)) @ m))
        if isinstance(self.part, SampledPart):
            # the jaw where the solver settled it against the polygon, laid on the dense machined
            # sample: a corner stays the contact while the jaw pivots, a face flush under the jaw
            # gives its middle (the quasi-static world's rule). At the hand's angle: the gear joint's
            # residual twist, microradians of the solver's, would otherwise decide which end of a
            # flush face bears, a 20 mm jump of the reading that no wrist of the rig's makes
            _, u_o, arc, _, edge = outline_touch(
                self.part, (jb.position.x, jb.position.y), self.hand[2], self.half_span
            )
            return Contact(total, u_o, arc, depth, edge)
        # The solver spreads the force over the polygon vertices that overlap the
        # edge in no particular way; the deepest one is the polygon's contact. The
        # real part is the spline: refine to its tangent point at the jaw's angle
        # (the jaw twists a little against the hand under load, as the paper notes).
        deepest = np.asarray(points)[int(np.argmax(depths))]
        k = int(np.argmin(np.sum((self.polygon[:-1] - deepest) ** 2, axis=1)))
        t = tangent_point(self.part, float(self._poly_t[k]), jb.angle) % self.part.n_knots
        if abs(float((self.part.point(t) - deepest) @ e)) > 2.0:  # a bridge or a corner: keep the vertex
            t = float(self._poly_t[k])
        u = float((self.part.point(t) - np.array(jb.position)) @ e)
        return Contact(total, u, t, depth, abs(u) > self.half_span + 1e-6)
