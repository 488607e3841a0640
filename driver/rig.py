"""The rig protocol that the simulated and the serial rig both satisfy, its optional capabilities,
its values and its errors.

A rig moves the hand, reports its pose and reads the wrist (:class:`Rig`). Some rigs can do more,
each a protocol of its own that the procedures check where they need it: hold a force with the
arm's servo (:class:`ForceServo`), keep their own clock (:class:`Clocked`: a simulated rig's time),
know the true contact (:class:`GroundTruth`: a simulated rig) and keep a log of raw samples
(:class:`SampleLog`).
"""

from __future__ import annotations

from typing import Any, NamedTuple, Protocol, runtime_checkable

from localizer import RolltouchError

__all__ = [
    "TransportError",
    "DEVICE_FAULTS",
    "ImplausibleReading",
    "Rig",
    "ForceServo",
    "Clocked",
    "GroundTruth",
    "SampleLog",
    "Pose",
    "Reading",
    "Truth",
    "RigError",
    "ProtocolError",
]


class RigError(RolltouchError, IOError):
    """A rig that did not do what was asked: no contact, contact off the jaw, a bad reply, a limit."""


class ImplausibleReading(RigError):
    """A device reported what cannot be: an arm angle far from the commanded one (a stuck or misread
    encoder), a wrist that reads exactly the same while the jaw moves (a dead DAQ). Never taken for a
    bridge or a lost contact: the run stops on it."""


class TransportError(RigError):
    """A device that did not answer: no reply, only garbled ones, or the connection gone. Never taken
    for a bridge or a lost contact."""


class ProtocolError(RigError):
    """A request or reply the serial protocol refuses, with its error code.

    Parameters
    ----------
    code : str
        The protocol's code (``BADCMD``, ``BADARG``, ``LIMIT``, ...), as an ``ERR`` reply carries it.
    message : str
        What was wrong, naming the value.
    seq : int
        The request's sequence number (0 when it could not be read).
    """

    def __init__(self, code: str, message: str, seq: int = 0) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message
        self.seq = seq


@runtime_checkable
class Rig(Protocol):
    """An arm that places the hand and a wrist sensor that reads two voltages.

    Poses are (x mm, y mm, φ rad): the wrist's axis on the jaw's edge line and
    the jaw's direction; the part lies on the jaw's left, (-sin φ, cos φ).
    """

    def move(self, x: float, y: float, phi: float) -> None:
        """Move the hand to (``x``, ``y``) mm, jaw angle ``phi`` rad, and return when it is there."""

    def pose(self) -> tuple[float, float, float]:
        """The arm's reading of the hand pose, (x mm, y mm, φ rad) (a :class:`Pose` or any 3-tuple)."""

    def read(self, n: int = 32) -> tuple[float, float]:
        """The sensor's (v1, v2) in volts, averaged over ``n`` samples."""


class Pose(NamedTuple):
    """A hand pose: the wrist's axis at (``x``, ``y``) mm on the jaw's edge line, the jaw at angle ``phi`` rad."""

    x: float
    y: float
    phi: float


class Reading(NamedTuple):
    """One contact-location reading while rolling.

    Attributes
    ----------
    dv1, dv2 : float, V
        The wrist's two channels against their values with the jaw clear.
    phi : float, rad
        The arm's reading of the jaw angle.
    time : float, s
        When (the rig's clock).
    x, y : float, mm
        The commanded hand position.
    phi_commanded : float, rad
        The commanded jaw angle.
    """

    dv1: float
    dv2: float
    phi: float
    time: float
    x: float
    y: float
    phi_commanded: float


class Truth(NamedTuple):
    """Where the contact really was at a reading: its arc on the part (mm) and its place on the jaw (mm);
    NaN on a real rig."""

    contact_arc: float
    jaw_position: float


@runtime_checkable
class ForceServo(Protocol):
    """A rig whose arm can hold the contact force with its own servo loop."""

    def servo(self, target: float, gain: float, *, guard: bool = True, duration: float = 0.5) -> dict[str, Any]:
        """Hold Δv1 at ``target`` V with force-error ``gain`` for ``duration`` s, ``guard``: with the passivity
        controller. Returns ``dv1``, ``dv1_std``, ``contact_lost``, ``min_energy``, ``guard``."""
        ...


@runtime_checkable
class Clocked(Protocol):
    """A rig with its own clock (a simulated rig's time, s), which its readings are stamped with."""

    time: float


@runtime_checkable
class GroundTruth(Protocol):
    """A rig that knows where the contact really is (a simulated rig)."""

    def truth(self) -> dict[str, Any]:
        """``contact_arc`` (mm on the part, NaN without contact) and ``jaw_position`` (mm), at least."""
        ...


@runtime_checkable
class SampleLog(Protocol):
    """A rig that keeps every raw sample it read (with ground truth on a simulated rig)."""

    samples: list[dict[str, Any]]


#: What the rolling never takes for a bridge or a lost contact: a device that did not answer, a
#: device's own refusal (``ERR``, e.g. a workspace limit mid-roll) and a reading that cannot be (a
#: stuck encoder).
DEVICE_FAULTS = (TransportError, ProtocolError, ImplausibleReading)
