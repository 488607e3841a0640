"""The simulated arm both simulated rigs share: hand poses at the arm's speed limits, read back with its
encoder's quantization, on the rig's own clock."""

from __future__ import annotations

import math

from ._errors import SimError
from .noise import NoiseModel
from .wrist import encoder_angle

__all__ = ["SimulatedArm"]


class SimulatedArm:
    """The arm of :class:`sim2d.SimRig` and :class:`sim2d.WheelRig`: it needs ``world`` (with ``hand`` and
    ``set_hand``), ``noise``, ``linear_speed`` (mm/s), ``angular_speed`` (rad/s) and ``time`` (s), which
    the rig sets."""

    world: object
    noise: NoiseModel
    linear_speed: float
    angular_speed: float
    time: float

    def move(self, x: float, y: float, phi: float) -> None:
        """Move the hand to (``x``, ``y``) mm at angle ``phi`` rad; blocks until there (the rig's clock
        advances by the move's time at the speed limits)."""
        pose = (float(x), float(y), float(phi))
        if not all(math.isfinite(v) for v in pose):
            raise SimError(f"move to {pose!r}: the pose must be finite")
        world = self.world
        x0, y0, p0 = getattr(world, "hand", None) or pose
        self.time += max(
            math.hypot(pose[0] - x0, pose[1] - y0) / self.linear_speed, abs(pose[2] - p0) / self.angular_speed
        )
        world.set_hand(*pose)  # type: ignore[attr-defined]

    def pose(self) -> tuple:
        """The arm's reading of the hand pose: (x mm, y mm, φ rad quantized by the arm's encoder)."""
        x, y, phi = getattr(self.world, "hand", None) or (0.0, 0.0, 0.0)
        return x, y, float(encoder_angle(phi, self.noise))
