"""``SimRig``: a simulated arm and wrist sensor that satisfies ``driver.Rig``.

The arm takes hand poses (x, y mm; φ rad) and reports them with the encoder's
quantization; the sensor reports raw (v1, v2) in volts, averaged over a
number of samples. Every reading is logged with the ground truth beside it.
"""

from __future__ import annotations

import math

import numpy as np

from localizer import Outline, Part

from ._errors import SimError
from .arm import SimulatedArm
from .noise import NoiseModel, load_noise
from .quasistatic import QuasiStaticWorld
from .sampled import SampledPart
from .world import World
from .world_part import Spikes, WorldChange, outstanding, world_part
from .wrist import Wrist

__all__ = ["SimRig"]

ENGINES = ("kinematic", "pymunk")


class SimRig(SimulatedArm):
    """A simulated rig.

    Parameters
    ----------
    part : Part or Outline
        The part's model (what the localizer is given); the simulated part is
        this one machined with ``noise.machining_error`` (an outline from CAD as a dense sample
        with its corners, :func:`sim2d.machining.machined_outline`).
    noise : str, Path or NoiseModel
        ``"none"``, ``"paper"`` or a TOML file (see :func:`sim2d.noise.load_noise`).
    seed : int
        Seeds every random draw: the same seed gives the same run.
    engine : {"kinematic", "pymunk"}
        The world that computes contact: "kinematic", the static equilibrium of a rigid edge on a
        linear wrist from the geometry alone (:class:`QuasiStaticWorld`), or "pymunk",
        the rigid-body simulation (dynamic, about ten times slower).
    wrist : Wrist
        Sensor geometry and sensitivity.
    stiffness : float, N/mm
        The wrist's compliance along the jaw normal.
    linear_speed, angular_speed : float, mm/s and rad/s
        Speed limits of the arm (moves take time, which the drift sees).
    sample_period : float, s
        Time between two raw sensor samples.
    world_options : dict, optional
        Further arguments of the world (e.g. ``chord_tolerance``, ``friction``).
    change : WorldChange, optional
        How the real part and the wrist differ from the model beyond machining and noise (a burr, a
        dent, a scale, a part of its own, spikes: :mod:`sim2d.world_part`). The machining and the
        noise draw the same values with it as without.
    """

    def __init__(
        self,
        part: Part | Outline,
        *,
        noise="none",
        seed: int = 0,
        engine: str = "kinematic",
        wrist: Wrist = Wrist(),
        stiffness: float = 1.0,
        linear_speed: float = 20.0,
        angular_speed: float = math.radians(30.0),
        sample_period: float = 1e-3,
        world_options: dict | None = None,
        change: WorldChange | None = None,
    ):
        if engine not in ENGINES:
            raise SimError(f"unknown engine {engine!r}; use one of {list(ENGINES)}")
        self.model = part
        self.noise: NoiseModel = load_noise(noise)
        self.rng = np.random.default_rng(seed)
        self.change = WorldChange() if change is None else change
        self.part: Part | SampledPart = world_part(part, self.change, self.noise, self.rng)
        self.world: World
        self.spikes = Spikes(self.change, self.noise.v2_noise, seed)
        if engine == "pymunk":
            from .pymunk_world import PymunkWorld

            self.world = PymunkWorld(
                self.part,
                stiffness=stiffness,
                linear_speed=linear_speed,
                angular_speed=angular_speed,
                **(world_options or {}),
            )
        else:
            self.world = QuasiStaticWorld(self.part, stiffness=stiffness, **(world_options or {}))
        self.wrist = wrist
        self.linear_speed = float(linear_speed)
        self.angular_speed = float(angular_speed)
        self.sample_period = float(sample_period)
        self.time = 0.0
        self.samples: list[dict] = []
        self._last_arc: tuple | None = None

    # --------------------------------------------------------- Rig: sensor (the arm: SimulatedArm)
    def read(self, n: int = 32) -> tuple:
        """Average of ``n`` raw samples of (v1, v2), V; logged with the truth."""
        c = self.world.contact()
        times = self.time + self.sample_period * np.arange(1, n + 1)
        # the force and place hold over the n samples: the same voltages as arrays of them, elementwise
        v1, v2 = self.wrist.voltages(c.force, c.jaw_position, times, self.noise, self.rng)
        self.time = float(times[-1])
        spike = self.spikes()  # on the twist channel: the contact's place
        out = (float(v1.sum()) / n, float(v2.sum()) / n + spike)  # np.mean's sum and division
        x, y, phi = self.world.hand or (0.0, 0.0, 0.0)
        self.samples.append(
            {
                "time": self.time,
                "x": x,
                "y": y,
                "phi": phi,
                "phi_measured": self.pose()[2],
                "v1": out[0],
                "v2": out[1],
                "force": c.force,
                "jaw_position": c.jaw_position,
                "contact_arc": self._contact_arc(c),
                "at_edge": c.at_edge,
                "spike": spike,
            }
        )
        return out

    # ------------------------------------------------ Rig: force servo
    def servo(
        self, target: float, gain: float, *, guard: bool = True, duration: float = 0.5, seed: int | None = None
    ) -> dict:
        """Hold the contact force with the arm's 1 kHz servo along the jaw normal.

        The arm pushes with the target force plus ``gain`` times the force
        error read by the wrist (:class:`sim2d.haptic.Servo`, an axis of 0.1 kg
        and 5 N·s/m on the wrist's stiffness), for ``duration`` s, starting from
        the present press. With ``guard`` a passivity observer/controller with
        both low-velocity fixes sits on the correction's port
        (:class:`passivity.PassivityController`, "observed" booking). The hand ends where
        the servo left it.

        Parameters
        ----------
        target : float, V
            Δv1 to hold (the paper's 0.4 V).
        gain : float
            Force-error gain (N/N). Above about 8 the bare loop rings; above
            about 15 it loses the part every cycle.
        guard : bool
            The passivity observer/controller on the servo's port.
        duration : float, s
        seed : int, optional
            Seeds the servo's sensor noise (default: drawn from the rig's own generator).

        Returns
        -------
        dict
            ``dv1`` (mean of the last half, V), ``dv1_std`` (V), ``contact_lost`` (samples of the
            last half with no contact), ``min_energy`` (J), ``guard``.
        """
        from passivity import PassivityController

        from .haptic import Axis, Servo, simulate_servo

        if not (math.isfinite(target) and target > 0):
            raise SimError(f"servo target={target!r} V must be positive")
        hand = self.world.hand
        if hand is None:
            raise SimError("servo: the hand has not been placed; move it first")
        c = self.world.contact()
        if c.force <= 0:
            raise SimError("servo: the jaw is not touching the part; press into contact first")
        vpn = self.wrist.volts_per_newton
        stiffness = float(getattr(self.world, "stiffness", 1.0))  # N/mm
        start = c.force / stiffness * 1e-3  # m of press
        axis = Axis(damping=5.0)
        spec = Servo(
            target=target / vpn,
            gain=gain,
            contact_stiffness=stiffness * 1e3,
            start=start,
            sensor_noise=self.noise.v1_noise / vpn,
            sensor_resolution=self.noise.adc_step / vpn,
            duration=duration,
        )
        pc = PassivityController(axis.dt, sign_fix=True, hold_fix=True, booking="observed") if guard else None
        if seed is None:
            seed = int(self.rng.integers(2**31))
        tr = simulate_servo(spec, pc, axis=axis, seed=seed)
        moved = (tr.position[-1] - start) * 1e3  # mm further along the normal
        x, y, phi = hand
        self.world.set_hand(x - moved * math.sin(phi), y + moved * math.cos(phi), phi)
        self.time += duration
        tail = tr.time >= duration / 2
        force = tr.contact_force[tail]
        return {
            "dv1": float(force.mean() * vpn),
            "dv1_std": float(force.std() * vpn),
            "contact_lost": int((force == 0).sum()),
            "min_energy": float(tr.energy.min()),
            "guard": bool(guard),
        }

    def truth(self) -> dict:
        """Ground truth of the present contact (simulation only)."""
        c = self.world.contact()
        return {
            "force": c.force,
            "jaw_position": c.jaw_position,
            "contact_arc": self._contact_arc(c),
            "at_edge": c.at_edge,
        }

    def _contact_arc(self, c) -> float:
        """The model's arc position (mm) of contact ``c`` (nan when clear); the last one is kept, as a
        reading and the truth after it ask for the same contact."""
        if self._last_arc is not None and self._last_arc[0] is c:
            return self._last_arc[1]
        if c.force <= 0:
            arc = float("nan")
        elif isinstance(self.part, SampledPart):  # the contact names the model's arc already
            arc = float(self.model.wrap_arc(c.param))
        else:
            arc = float(self.model.wrap_arc(self.model.arc_at_param(c.param)))
        self._last_arc = (c, arc)
        return arc

    # ------------------------------------------------- simulation helpers
    def calibration_pose(self, standoff: float = 1.0) -> tuple:
        """Where to calibrate on the part itself (paper §III-B): the jaw's centre facing the most curved
        point that the whole jaw reaches (:func:`localizer.calibration_arc`), ``standoff`` mm off."""
        from localizer import calibration_arc

        return self.approach_pose(calibration_arc(self.model), jaw_position=0.0, standoff=standoff)

    def approach_pose(self, arc: float, jaw_position: float = -30.0, standoff: float = 2.0, tilt: float = 0.0) -> tuple:
        """A hand pose with the jaw parallel to the model's tangent at ``arc`` (mm), turned by ``tilt`` rad
        more (a start on a corner of an outline: ``tilt`` within minus its jump and 0, the tangent being
        the one after it), that point facing jaw position ``jaw_position`` (mm), ``standoff`` mm off the part."""
        t = self.model.param_at_arc(arc)
        c = self.model.point(t)
        phi = float(self.model.tangent_angle(t)) + float(tilt)
        e = np.array([math.cos(phi), math.sin(phi)])
        m = np.array([-math.sin(phi), math.cos(phi)])
        # off the real part, not the model: an operator jogs the jaw clear of what is there (a part made
        # large, a burr under the start)
        standoff = standoff + outstanding(self.model, self.part, arc)
        d = c - jaw_position * e - standoff * m
        return float(d[0]), float(d[1]), phi
