"""``WheelRig``: a simulated arm carrying a wheel finger, with an axle encoder and a two-channel wrist.

The arm takes hand poses (axle x, y mm; hand angle φ rad) and reports them, the angle with the arm
encoder's quantization. The wrist's two strain-gauge channels read the contact force's components
along the hand's axis (v1) and across it (v2): for a disc the force passes through the axle, so
the wrist gives the force's **direction** α = atan2(Δv2, Δv1) relative to the hand, and its size.
The axle encoder reads the disc's angle relative to the hand (docs/wheel.md, the chosen design).
Every reading is logged with the ground truth beside it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from localizer import Outline, Part, WheelJaw

from ._errors import SimError
from .arm import SimulatedArm
from .noise import NoiseModel, load_noise
from .wheel_world import WheelWorld
from .world_part import Spikes, WorldChange, outstanding, world_part
from .wrist import Wrist

if TYPE_CHECKING:
    from .pymunk_wheel import PymunkWheelWorld

__all__ = ["WheelRig"]


class WheelRig(SimulatedArm):
    """A simulated rig with a wheel finger.

    Parameters
    ----------
    part : Part or Outline
        The part's model; the simulated part is this one machined with ``noise.machining_error``.
    wheel : WheelJaw
    noise : str, Path or NoiseModel
        ``"none"``, ``"paper"`` or a TOML file (:func:`sim2d.noise.load_noise`); the wrist's channels
        take its v1/v2 noise, offsets, drift, ADC and cross-talk, the arm its ``encoder_step``, the
        axle its ``axle_encoder_step``.
    seed : int
    stiffness : float, N/mm
    volts_per_newton : float, V/N
        Channel gain (the straight jaw's wrist: 0.4 V at 1 N).
    true_radius : float, optional, mm
        The real disc's radius (default the wheel's nominal): what the calibration finds.
    direction_zero : float, rad
        The channels' mounting rotation about the axle: what the calibration finds too.
    slip : float
        Fraction of the rolled arc the rim loses (:class:`sim2d.wheel_world.WheelWorld`; the kinematic
        world only).
    engine : {"kinematic", "pymunk"}
        The kinematic world (:class:`sim2d.wheel_world.WheelWorld`) or the rigid bodies of
        :class:`sim2d.pymunk_wheel.PymunkWheelWorld` (a disc rolling by friction on a bearing).
    linear_speed, angular_speed : float, mm/s and rad/s
    sample_period : float, s
    change : WorldChange, optional
        How the real part and the wrist differ from the model beyond machining and noise
        (:mod:`sim2d.world_part`); the spikes fall on the channel across the hand (v2).
    """

    def __init__(
        self,
        part: Part | Outline,
        wheel: WheelJaw,
        *,
        noise="none",
        seed: int = 0,
        stiffness: float = 1.0,
        volts_per_newton: float = Wrist.volts_per_newton,
        true_radius: float | None = None,
        direction_zero: float = 0.0,
        slip: float = 0.0,
        engine: str = "kinematic",
        linear_speed: float = 20.0,
        angular_speed: float = math.radians(30.0),
        sample_period: float = 1e-3,
        change: WorldChange | None = None,
    ):
        if not isinstance(wheel, WheelJaw):
            raise SimError(f"a WheelRig needs a WheelJaw, not {wheel!r}")
        self.model = part
        self.wheel = wheel
        self.noise: NoiseModel = load_noise(noise)
        self.rng = np.random.default_rng(seed)
        self.change = WorldChange() if change is None else change
        real = self.part = world_part(part, self.change, self.noise, self.rng)
        self.spikes = Spikes(self.change, self.noise.v2_noise, seed)
        radius = wheel.radius if true_radius is None else float(true_radius)
        self.world: WheelWorld | PymunkWheelWorld
        if engine == "pymunk":
            from .pymunk_wheel import PymunkWheelWorld

            if slip:
                raise SimError("slip is the kinematic world's: in pymunk the rim slips by its friction alone")
            self.world = PymunkWheelWorld(
                real, part, radius, stiffness=stiffness, linear_speed=linear_speed, angular_speed=angular_speed
            )
        elif engine == "kinematic":
            self.world = WheelWorld(real, part, radius, stiffness=stiffness, slip=slip)
        else:
            raise SimError(f"unknown engine {engine!r}; use kinematic or pymunk")
        self.volts_per_newton = float(volts_per_newton)
        self.direction_zero = float(direction_zero)
        self.linear_speed, self.angular_speed = float(linear_speed), float(angular_speed)
        self.sample_period = float(sample_period)
        self.time = 0.0
        self.samples: list[dict] = []

    # ------------------------------------------------------------ Rig: arm (SimulatedArm)
    def axle(self) -> float:
        """The axle encoder: the disc's angle relative to the hand, rad, quantized by its step."""
        psi = self.world.encoder()
        step = self.noise.axle_encoder_step
        return float(np.round(psi / step) * step) if step else float(psi)

    # --------------------------------------------------------- Rig: sensor
    def read(self, n: int = 32) -> tuple:
        """Average of ``n`` raw samples of (v1, v2), V; logged with the truth."""
        c = self.world.contact()
        phi = (self.world.hand or (0.0, 0.0, 0.0))[2]
        alpha = c.normal - phi - self.direction_zero if c.force > 0 else 0.0
        f = c.force * self.volts_per_newton
        times = self.time + self.sample_period * np.arange(1, n + 1)
        nz = self.noise
        d1, d2 = f * math.cos(alpha), f * math.sin(alpha)
        v1 = nz.v1_offset + d1 + nz.crosstalk * d2 + nz.v1_drift * times
        v2 = nz.v2_offset + d2 + nz.crosstalk * d1 + nz.v2_drift * times
        if nz.v1_noise:
            v1 = v1 + self.rng.normal(0.0, nz.v1_noise, n)
        if nz.v2_noise:
            v2 = v2 + self.rng.normal(0.0, nz.v2_noise, n)
        if nz.adc_step:
            v1, v2 = np.round(v1 / nz.adc_step) * nz.adc_step, np.round(v2 / nz.adc_step) * nz.adc_step
        self.time = float(times[-1])
        spike = self.spikes()
        out = (float(np.mean(v1)), float(np.mean(v2)) + spike)
        self.samples.append({"time": self.time, "v1": out[0], "v2": out[1], "spike": spike, **self.truth()})
        return out

    def truth(self) -> dict:
        """Ground truth of the present contact (simulation only): ``contact_arc`` (mm, NaN when clear),
        ``force`` (N), ``normal`` (rad), and the disc's world angle ``psi`` (rad)."""
        c = self.world.contact()
        return {"contact_arc": c.arc, "force": c.force, "normal": c.normal, "psi": self.world.psi}

    # ------------------------------------------------- simulation helpers
    def approach_pose(self, arc: float, standoff: float = 1.0) -> tuple:
        """The hand pose with the axle on the model's outward normal at ``arc`` (mm), ``standoff`` mm more
        than the wheel's radius off the part, the hand's axis pointing at that point."""
        p = np.asarray(self.model.point_at_arc(arc), dtype=float)
        theta = float(self.model.tangent_angle_at_arc(arc))
        standoff = standoff + outstanding(self.model, self.part, arc)  # off the real part, not the model
        c = p + (self.wheel.radius + standoff) * np.array([math.sin(theta), -math.cos(theta)])
        return float(c[0]), float(c[1]), theta
