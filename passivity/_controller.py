"""Time-domain passivity observer and controller (Hannaford–Ryu), with the low-velocity fixes.

Series PC, impedance causality (velocity in, force out), sample by sample.
At a port where ``f·v`` is the power the port absorbs (W = N·m/s):

    E(n) = E(n-1) + ΔT·[f(n)·v(n) + α(n-1)·v(n-1)²]      (observer; dissipated energy added back)
    α(n) = -E(n) / (ΔT·v(n)²)  if E(n) < 0 and v(n) ≠ 0, else 0
    f_out(n) = f(n) + α(n)·v(n)

The controller's damping dissipates exactly the energy the observer saw
produced. Ryu et al. (2005) find it noisy at low velocity, where velocity from a
quantized encoder is mostly 0 with single-count spikes; their two fixes are
options here, each separately switchable:

``sign_fix``
    At a velocity sign change the step's observed energy f(n)·v(n)·ΔT, when
    negative (produced), is an artefact of differentiation: it is not added to E.
``hold_fix``
    While v(n) = 0 the controller cannot act (α·v = 0): the last control
    force is held instead (it does no work at v = 0, so E is unchanged).
``force_limit``
    Bound on |α·v| (N); energy the bound leaves undissipated stays in E.

Two bookings of the port energy (``booking``):

``"assumed"`` (default; the running form of Hannaford & Ryu 2002)
    E(n) = E(n-1) + ΔT·[f(n)·v(n) + α(n-1)·v(n-1)²]: the force and velocity of
    the same sample are paired, and the controller's dissipation is assumed to
    have happened as computed.
``"observed"`` (a sampled port with a zero-order hold)
    E(n) = E(n-1) + ΔT·f_out(n-1)·v(n). The output f_out(n-1) = f(n-1) + control
    is held over the interval (t_(n-1), t_n] and v(n), differenced from the
    encoder, is the motion over that same interval, so this is the energy that
    actually crossed the port, the controller's own force included: its
    dissipation is observed, not assumed. A sampled stiff spring f = K·x(n) is
    passive under "assumed" (Σ K·x(n)·Δx(n) ≥ 0 for any sequence) and active
    under "observed" (Σ K·x(n-1)·Δx(n) = ΔU − K·ΣΔx²/2), which is the real
    behaviour of a sampled wall (Colgate). Under "observed" a control force that
    meets a velocity sign change does produce energy, and a controller that
    cannot act while v = 0 leaves E negative: the two cases Ryu et al. name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from localizer import RolltouchError

__all__ = ["PassivityController", "PassivityStep", "ControlError"]


class ControlError(RolltouchError, ValueError):
    """A controller setting or sample that cannot be used; the message names it."""


@dataclass(frozen=True)
class PassivityStep:
    """One sample's outcome.

    Attributes
    ----------
    force : float, N
        f_out = f + control force.
    control : float, N
        The controller's force α·v (or the held one).
    alpha : float, N·s/m
        The damping applied this sample.
    energy : float, J
        Observed energy after this sample, the controller's dissipation included.
    """

    force: float
    control: float
    alpha: float
    energy: float


class PassivityController:
    """A passivity observer/controller on one port.

    Parameters
    ----------
    dt : float, s
        Sample period ΔT.
    sign_fix, hold_fix : bool
        The two fixes of Ryu et al. (see module notes).
    force_limit : float or None, N
        Bound on the control force.
    booking : {"assumed", "observed"}
        How the port energy is booked (see module notes).

    Examples
    --------
    >>> pc = PassivityController(dt=0.001)
    >>> pc.update(f=-2.0, v=0.01).alpha  # 2 N against 10 mm/s produces 2e-5 J: damp it
    200.0
    >>> round(pc.energy, 12)  # the dissipation is booked on the next sample
    -2e-05
    """

    def __init__(
        self,
        dt: float,
        *,
        sign_fix: bool = False,
        hold_fix: bool = False,
        force_limit: float | None = None,
        booking: str = "assumed",
    ):
        if not (math.isfinite(dt) and dt > 0):
            raise ControlError(f"dt={dt!r} s must be a positive number")
        if force_limit is not None and not force_limit > 0:
            raise ControlError(f"force_limit={force_limit!r} N must be positive or None")
        if booking not in ("assumed", "observed"):
            raise ControlError(f"booking={booking!r}: use 'assumed' or 'observed'")
        self.booking = booking
        self.dt = float(dt)
        self.sign_fix = bool(sign_fix)
        self.hold_fix = bool(hold_fix)
        self.force_limit = force_limit
        self.reset()

    def reset(self) -> None:
        """Start afresh: zero energy, no history."""
        self.energy = 0.0
        self._prev_v = 0.0
        self._prev_alpha = 0.0
        self._last_sign = 0.0
        self._held = 0.0
        self._prev_out = 0.0

    def update(self, f: float, v: float) -> PassivityStep:
        """One sample: observe f·v at the port, then damp what was produced.

        Parameters
        ----------
        f : float, N
            Force at the port, signed so that f·v is the power the port absorbs.
        v : float, m/s
            Port velocity.
        """
        if not (math.isfinite(f) and math.isfinite(v)):
            raise ControlError(f"f={f!r} N and v={v!r} m/s must be finite")
        dt = self.dt
        if self.booking == "assumed":
            # the previous sample's dissipation, now booked
            self.energy += dt * self._prev_alpha * self._prev_v**2
            step = dt * f * v
        else:
            # the output held over the last interval, against the motion over it
            step = dt * self._prev_out * v
        sign = math.copysign(1.0, v) if v != 0 else 0.0
        flipped = sign != 0 and self._last_sign != 0 and sign != self._last_sign
        if not (self.sign_fix and flipped and step < 0):
            self.energy += step
        if sign != 0:
            self._last_sign = sign
        alpha = 0.0
        if v != 0 and self.energy < 0:
            alpha = -self.energy / (dt * v * v)
        control = alpha * v
        if self.force_limit is not None and abs(control) > self.force_limit:
            control = math.copysign(self.force_limit, control)
            alpha = control / v
        if v == 0 and self.hold_fix:
            control = self._held
        elif v != 0:
            self._held = control
        self._prev_alpha, self._prev_v = alpha, v
        self._prev_out = f + control
        return PassivityStep(force=f + control, control=control, alpha=alpha, energy=self.energy + dt * alpha * v * v)
