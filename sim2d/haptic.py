"""A one-degree-of-freedom sampled device: the haptic interface of Ryu et al. (2005) and the arm's
contact-force servo, both with an optional passivity observer/controller on the sampled port.

SI units throughout this module (m, s, N, J): it is a device model, and the
passivity literature and the interface of ``bench.reports.passivity`` speak joules.

The device is a mass ``m`` with viscous damping ``b`` driven by an actuator
whose force is computed at ``dt`` and held (zero-order hold), saturating at
``force_limit``. Between samples the physics (the operator's hand, a real
contact) is integrated with ``substeps`` semi-implicit Euler steps. The position
is read from an encoder of ``resolution`` metres per count (floor
quantization); the velocity is the backward difference of that reading.

Parameters of the defaults, and why (the seed gives only the paper's first
page, so none of its numbers are known here):

- ``mass`` 0.1 kg, ``damping`` 0.5 N·s/m: the apparent end-point mass and
  friction of a desktop one-axis device (PHANToM class).
- ``resolution`` 10 µm: a 2000-count encoder on a 20 mm capstan radius gives
  60 µm; 10 µm is a good one. At 1 kHz a count per sample is 10 mm/s, so every
  motion slower than that is "low velocity": mostly zero differenced velocity
  with single-count spikes, the regime of the seed.
- ``force_limit`` 10 N: a small DC motor's peak force at the handle.
- the virtual wall, 20 kN/m: stiff; far past the sampled-spring bound
  K < 2(b + b_hand)/ΔT = 17 kN/m for the hand below, so the wall is active.
- the operator's hand, 300 N/m and 8 N·s/m, pulled by a set point that moves
  in at 2 mm/s, holds 1 s and moves out: a relaxed grasp (human arm impedance
  is of the order of 10²–10³ N/m and 2–10 N·s/m).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ._errors import SimError

__all__ = ["Axis", "Operator", "Servo", "AxisTrace", "simulate_wall", "simulate_servo"]


@dataclass(frozen=True)
class Axis:
    """The sampled one-axis device.

    Attributes
    ----------
    mass : float, kg
    damping : float, N·s/m
    resolution : float, m
        Encoder count.
    dt : float, s
        Control period ΔT.
    substeps : int
        Integration steps per control period.
    force_limit : float, N
        Actuator saturation.
    """

    mass: float = 0.1
    damping: float = 0.5
    resolution: float = 1e-5
    dt: float = 1e-3
    substeps: int = 20
    force_limit: float = 10.0

    def __post_init__(self):
        for name in ("mass", "resolution", "dt", "force_limit"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise SimError(f"Axis.{name}={value!r} must be a positive number")
        if not (math.isfinite(self.damping) and self.damping >= 0):
            raise SimError(f"Axis.damping={self.damping!r} N·s/m must be ≥ 0")
        if self.substeps < 1:
            raise SimError(f"Axis.substeps={self.substeps!r} must be ≥ 1")


@dataclass(frozen=True)
class Operator:
    """The operator's hand: a spring-damper to a set point that goes in, holds and comes out.

    Attributes
    ----------
    stiffness : float, N/m
    damping : float, N·s/m
    start : float, m
        Set point at t = 0 (the wall is at 0; negative is free space).
    depth : float, m
        Set point while holding.
    speed : float, m/s
        Set-point speed in and out.
    hold : float, s
        Time at ``depth``.
    """

    stiffness: float = 300.0
    damping: float = 8.0
    start: float = -0.5e-3
    depth: float = 5e-3
    speed: float = 2e-3
    hold: float = 1.0

    @property
    def phases(self) -> tuple:
        """((name, t0, t1), ...) s: "press", "hold", "release"."""
        tp = (self.depth - self.start) / self.speed
        return (("press", 0.0, tp), ("hold", tp, tp + self.hold), ("release", tp + self.hold, 2 * tp + self.hold))

    def set_point(self, t: float) -> tuple:
        """(position m, velocity m/s) of the set point at time ``t`` s."""
        (_, _, tp), (_, _, th), _ = self.phases
        if t < tp:
            return self.start + self.speed * t, self.speed
        if t < th:
            return self.depth, 0.0
        return self.depth - self.speed * (t - th), -self.speed


@dataclass(frozen=True)
class Servo:
    """The arm's contact-force servo along the jaw normal.

    The arm pushes with the target force plus a sampled proportional correction
    from the wrist's reading: F(n) = F_t − f(n), f(n) = gain·(F_meas(n) − F_t).
    The correction is a sampled virtual spring of stiffness gain·k_c on the
    contact; its port (effort f, flow the encoder velocity) is where the
    passivity controller sits. F_t itself is the operator's push, outside the port.

    Attributes
    ----------
    target : float, N
        Contact force to hold (the paper's Δv1 = 0.4 V is 1 N on the default wrist).
    gain : float
        Proportional gain on the force error (N per N).
    contact_stiffness : float, N/m
        The wrist's compliance in series with the part along the normal (the
        rigs' default wrist is 1 N/mm).
    start : float, m
        Position at t = 0; the part's surface is at 0, negative is clear of it.
    sensor_noise : float, N
        Standard deviation of the force reading (per sample).
    sensor_resolution : float, N
        The reading's quantum (ADC).
    duration : float, s
    """

    target: float = 1.0
    gain: float = 2.0
    contact_stiffness: float = 1000.0
    start: float = -0.2e-3
    sensor_noise: float = 0.0
    sensor_resolution: float = 0.0
    duration: float = 1.0

    def __post_init__(self):
        for name in ("target", "contact_stiffness", "duration"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise SimError(f"Servo.{name}={value!r} must be a positive number")
        for name in ("gain", "sensor_noise", "sensor_resolution"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise SimError(f"Servo.{name}={value!r} must be ≥ 0")


@dataclass(frozen=True)
class AxisTrace:
    """A run of the sampled axis, one row per control sample.

    Attributes
    ----------
    time : (n,) s
    position : (n,) m, the true position at the sample
    encoder : (n,) m, the encoder's reading
    velocity : (n,) m/s, differenced from the encoder
    port_force : (n,) N, the port's effort before the controller (the wall's force, or the
        servo's correction)
    control : (n,) N, the passivity controller's force (0 without one)
    energy : (n,) J, the observed energy after the controller (0 without one)
    contact_force : (n,) N, the physical contact force (the wall's for the haptic run)
    phases : ((name, t0, t1), ...)
    """

    time: np.ndarray
    position: np.ndarray
    encoder: np.ndarray
    velocity: np.ndarray
    port_force: np.ndarray
    control: np.ndarray
    energy: np.ndarray
    contact_force: np.ndarray
    phases: tuple = field(default=())

    def noise(self, t0: float = -math.inf, t1: float = math.inf) -> float:
        """Total variation of the control force per second over [t0, t1), N/s."""
        sel = (self.time >= t0) & (self.time < t1)
        c = self.control[sel]
        span = self.time[sel][-1] - self.time[sel][0] if sel.sum() > 1 else 0.0
        return float(np.abs(np.diff(c)).sum() / span) if span > 0 else 0.0


def _run(axis: Axis, n: int, x0: float, physical: Callable, sampled: Callable) -> dict:
    """Integrate the axis for ``n`` samples.

    ``physical(t, x, xd)`` is the continuous force on the device (N);
    ``sampled(k, t, x, x_enc, v)`` returns (actuator force N, row values) at sample k.
    """
    q, dt, h = axis.resolution, axis.dt, axis.dt / axis.substeps
    x, xd = float(x0), 0.0
    enc_prev = math.floor(x / q) * q
    command = 0.0
    rows = []
    for k in range(n):
        t = k * dt
        enc = math.floor(x / q) * q
        v = (enc - enc_prev) / dt
        command, row = sampled(k, t, x, enc, v)
        rows.append((t, x, enc, v) + tuple(row))
        enc_prev = enc
        u = max(-axis.force_limit, min(axis.force_limit, command))
        for j in range(axis.substeps):
            force = u + physical(t + j * h, x, xd) - axis.damping * xd
            xd += h * force / axis.mass
            x += h * xd
            if not math.isfinite(x):
                raise SimError(f"the axis diverged at t = {t:.3f} s")
    a = np.array(rows, dtype=float)
    return {
        "time": a[:, 0],
        "position": a[:, 1],
        "encoder": a[:, 2],
        "velocity": a[:, 3],
        "port_force": a[:, 4],
        "control": a[:, 5],
        "energy": a[:, 6],
        "contact_force": a[:, 7],
    }


def simulate_wall(
    controller=None, *, axis: Axis = Axis(), operator: Operator = Operator(), wall_stiffness: float = 20000.0
) -> AxisTrace:
    """The seed's experiment: an operator presses slowly into a stiff virtual wall and out again.

    The wall at x = 0 pushes back with K·x_enc(n) (N) while the encoder reads
    inside it. With impedance causality the wall's port takes the differenced
    velocity v(n) and gives the force; ``controller`` (a
    :class:`passivity.PassivityController`, or None for the bare wall) sits on
    that port, its force pushed back onto the device with the wall's.

    Returns
    -------
    AxisTrace
        ``port_force`` is the wall's force; ``contact_force`` too.
    """
    if not (math.isfinite(wall_stiffness) and wall_stiffness > 0):
        raise SimError(f"wall_stiffness={wall_stiffness!r} N/m must be a positive number")
    if controller is not None:
        controller.reset()
    phases = operator.phases
    n = int(round(phases[-1][2] / axis.dt))

    def physical(t, x, xd):
        xs, vs = operator.set_point(t)
        return operator.stiffness * (xs - x) + operator.damping * (vs - xd)

    def sampled(k, t, x, enc, v):
        f = wall_stiffness * enc if enc > 0 else 0.0
        if controller is None:
            return -f, (f, 0.0, 0.0, f)
        step = controller.update(f, v)
        return -step.force, (f, step.control, step.energy, f)

    return AxisTrace(**_run(axis, n, operator.start, physical, sampled), phases=phases)


def simulate_servo(servo: Servo, controller=None, *, axis: Axis = Axis(damping=5.0), seed: int = 0) -> AxisTrace:
    """The contact-force servo pressing the jaw on the part (see :class:`Servo`).

    The part is a one-sided spring of ``servo.contact_stiffness`` at x = 0
    (force k_c·x for x > 0, nothing when the jaw is clear). The wrist reads it
    with ``sensor_noise`` and ``sensor_resolution``. ``controller`` guards the
    correction's port; None leaves the loop bare.

    Returns
    -------
    AxisTrace
        ``port_force`` is the correction f(n), ``contact_force`` the true contact force.
    """
    if controller is not None:
        controller.reset()
    rng = np.random.default_rng(seed)
    n = int(round(servo.duration / axis.dt))
    kc = servo.contact_stiffness

    def physical(t, x, xd):
        return -kc * x if x > 0 else 0.0

    def sampled(k, t, x, enc, v):
        true = kc * x if x > 0 else 0.0
        measured = true + servo.sensor_noise * rng.standard_normal()
        if servo.sensor_resolution > 0:
            measured = round(measured / servo.sensor_resolution) * servo.sensor_resolution
        f = servo.gain * (measured - servo.target)
        if controller is None:
            return servo.target - f, (f, 0.0, 0.0, true)
        step = controller.update(f, v)
        return servo.target - step.force, (f, step.control, step.energy, true)

    return AxisTrace(**_run(axis, n, servo.start, physical, sampled), phases=(("servo", 0.0, servo.duration),))
