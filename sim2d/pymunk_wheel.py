"""The pymunk world of the wheel finger: a dynamic disc on a bearing, on a compliant wrist, rolling by friction.

Units as in :mod:`sim2d.pymunk_world` (mm, kg, s; forces in mN). The part is the same chain of static
segments (:func:`sim2d.pymunk_world.polygonise`). The hand is a kinematic body driven at the arm's speed
limits; a carrier body holds the axle, joined to the hand by a spring of rest length zero (the wrist gives
the same way in every direction), two dampers and a gear joint (it turns with the hand); the disc is a
``pymunk.Circle`` on a pivot joint at the carrier's origin (a bearing without friction), with friction
against the part, so it turns only as the contact makes it. The axle encoder reads the disc's angle
less the hand's; the contact force is the disc's arbiters' impulse.

The force's direction is the wrist spring's, along the disc's displacement from the hand (what the
gauges read); where the disc touches is taken from the geometry of the real part at the disc's settled
centre (the kinematic world's nearest point and model arc, :meth:`sim2d.wheel_world.WheelWorld.nearest`),
as the straight jaw's pymunk world refines its polygon contact on the spline.
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from ._errors import SimError
from .pymunk_world import (
    SETTLE_SPEED,
    SOLVER_BIAS,
    Settle,
    drive_hand,
    polygonise,
    solver_space,
    static_chain,
)
from .wheel_world import WheelContact, WheelWorld

__all__ = ["PymunkWheelWorld"]

_MN_PER_N = 1000.0


class PymunkWheelWorld:
    """A disc of ``radius`` mm rolling on the part in a pymunk space.

    Parameters
    ----------
    part : Part or SampledPart
        The real part.
    model : Part or Outline
        The model whose arc positions the contacts report.
    radius : float, mm
    stiffness : float, N/mm
        The wrist's compliance, the same in every direction.
    friction : float
        Coulomb friction between the rim and the part (the disc rolls while the tangential force stays
        within it).
    chord_tolerance : float, mm
        Polygonisation tolerance of the part: finer than the straight jaw's world, since the disc's contact
        is read from where its centre settles on the polygon, not refined on the spline (at 1e-3 mm the
        normal of the contact is 4e-3 rad off the kinematic world's; at 1e-4 mm, 1.4e-3).
    dt : float, s
    linear_speed, angular_speed : float, mm/s and rad/s
    settle_steps : int
        The most steps run after the hand reaches a commanded pose.
    settle_speed : float, mm/s
        Fewer when the disc has come to rest, its rim included (:class:`sim2d.pymunk_world.Settle`); 0:
        always ``settle_steps``.
    """

    def __init__(
        self,
        part,
        model,
        radius: float,
        *,
        stiffness: float = 1.0,
        friction: float = 1.0,
        chord_tolerance: float = 1e-4,
        dt: float = 1e-3,
        linear_speed: float = 20.0,
        angular_speed: float = math.radians(30.0),
        settle_steps: int = 150,
        settle_speed: float = SETTLE_SPEED,
    ):
        if not (radius > 0 and stiffness > 0 and dt > 0 and friction >= 0):
            raise SimError(
                f"radius={radius!r}, stiffness={stiffness!r}, dt={dt!r} must be positive and friction={friction!r} >= 0"
            )
        self.geometry = WheelWorld(part, model, radius, stiffness=stiffness)
        self.radius, self.stiffness, self.dt = float(radius), float(stiffness), float(dt)
        self.linear_speed, self.angular_speed = float(linear_speed), float(angular_speed)
        self.settle_steps, self.settle_speed = int(settle_steps), float(settle_speed)
        space = solver_space()
        self.space = space
        static_chain(space, polygonise(part, chord_tolerance), friction)
        self.hand_body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        carrier_mass, wheel_mass = 0.05, 0.01
        self.carrier = pymunk.Body(carrier_mass, pymunk.moment_for_circle(carrier_mass, 0.0, 5.0))
        self.wheel_body = pymunk.Body(wheel_mass, pymunk.moment_for_circle(wheel_mass, 0.0, radius))
        disc = pymunk.Circle(self.wheel_body, radius)
        disc.friction = friction
        k = self.stiffness * _MN_PER_N  # mN/mm
        damping = 2.0 * math.sqrt(k * (carrier_mass + wheel_mass))  # critical
        # a spring of rest length zero pulls back along the displacement itself, as hard every way (two
        # springs at right angles of finite rest length would add a force across it of order k·d²/rest)
        # (its damping acts along the displacement only), and two dampers without stiffness at right
        # angles damp every way, exerting nothing at rest
        reach = 50.0
        springs = [pymunk.DampedSpring(self.hand_body, self.carrier, (0.0, 0.0), (0.0, 0.0), 0.0, k, 0.0)] + [
            pymunk.DampedSpring(self.hand_body, self.carrier, anchor, (0.0, 0.0), reach, 0.0, damping)
            for anchor in ((-reach, 0.0), (0.0, -reach))
        ]
        gear = pymunk.GearJoint(self.hand_body, self.carrier, 0.0, 1.0)
        bearing = pymunk.PivotJoint(self.carrier, self.wheel_body, (0.0, 0.0), (0.0, 0.0))
        bearing.collide_bodies = False
        for joint in (*springs, gear, bearing):
            joint.error_bias = SOLVER_BIAS
        space.add(self.hand_body, self.carrier, self.wheel_body, disc, *springs, gear, bearing)
        self.hand: tuple[float, float, float] | None = None

    def _place(self, x: float, y: float, phi: float) -> None:
        for b in (self.hand_body, self.carrier, self.wheel_body):
            b.position = (x, y)
            b.angle = phi
            b.velocity = (0.0, 0.0)
            b.angular_velocity = 0.0
        self.space.reindex_shapes_for_body(self.wheel_body)

    def set_hand(self, x: float, y: float, phi: float) -> None:
        """Drive the hand to the pose at the speed limits, then let the disc settle (the first command
        places everything there directly: the arm's start-up pose must be clear of the part)."""
        if self.hand is None:
            self._place(float(x), float(y), float(phi))
        settle = Settle(self.settle_steps, self.settle_speed, self.wheel_body, self.radius)
        drive_hand(self.space, self.hand_body, (x, y, phi), self.dt, self.linear_speed, self.angular_speed, settle)
        self.hand = (float(x), float(y), float(phi))

    @property
    def psi(self) -> float:
        """The disc's angle in the world, rad."""
        return float(self.wheel_body.angle)

    def encoder(self) -> float:
        """The disc's angle relative to the hand, rad."""
        return float(self.wheel_body.angle - self.hand_body.angle)

    def contact(self) -> WheelContact:
        """The contact after the last step: the arbiters' force, the place from the disc's centre."""
        total = 0.0

        def visit(arb):
            nonlocal total
            total += float(np.hypot(*arb.total_impulse)) / self.dt / _MN_PER_N

        self.wheel_body.each_arbiter(visit)
        if self.hand is None or total <= 0:
            return WheelContact(0.0, math.nan, math.nan, 0.0)
        centre = np.array(self.wheel_body.position)
        arc, _, _ = self.geometry.nearest(centre)
        # the wrist's spring pushes back along the disc's displacement from the hand: (sin β, −cos β)
        d = centre - np.array(self.hand[:2])
        return WheelContact(total, math.atan2(d[0], -d[1]), arc, float(np.hypot(*d)))
