"""The rig protocol that the simulated and the serial rig both satisfy, and its error."""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from localizer import RolltouchError

__all__ = ["Rig", "RigError", "ProtocolError"]


class RigError(RolltouchError, IOError):
    """A rig that did not do what was asked: no contact, contact off the jaw, a bad reply, a limit."""


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

    def __init__(self, code: str, message: str, seq: int = 0):
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

    def pose(self) -> tuple:
        """The arm's reading of the hand pose, (x, y, φ)."""

    def read(self, n: int = 32) -> tuple:
        """The sensor's (v1, v2) in volts, averaged over ``n`` samples."""
