"""What a simulated world is to the rig: a hand that can be placed and a contact that can be read.

Two worlds satisfy it: :class:`sim2d.quasistatic.QuasiStaticWorld` (static equilibrium, no
dynamics) and :class:`sim2d.pymunk_world.PymunkWorld` (rigid bodies in pymunk).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

__all__ = ["World", "Contact"]


@dataclass(frozen=True)
class Contact:
    """Where and how hard the jaw touches the part.

    Attributes
    ----------
    force : float, N
        Normal contact force (0 when not touching).
    jaw_position : float, mm
        Contact location along the jaw from the wrist's axis (along e).
    param : float
        Spline parameter of the contact point on the (real) part.
    depth : float, mm
        How far the part would cut into the rigid edge (the wrist's give).
    at_edge : bool
        The contact is at an end of the jaw (outside the calibrated span).
    """

    force: float
    jaw_position: float
    param: float
    depth: float
    at_edge: bool


@runtime_checkable
class World(Protocol):
    """A planar world with a part and a jaw on a compliant wrist, driven by hand poses.

    Attributes
    ----------
    hand : tuple of float or None
        The hand pose last set, (x mm, y mm, φ rad); None before the first.
    """

    hand: tuple[float, float, float] | None

    def set_hand(self, x: float, y: float, phi: float) -> None:
        """Put the hand at (``x``, ``y``) mm, ``phi`` rad, and let the world settle."""
        ...

    def contact(self) -> Contact:
        """Where and how hard the jaw touches the part now."""
        ...
