"""Exceptions of the simulator: one root, subclassing ``ValueError``."""

__all__ = ["SimError"]


class SimError(ValueError):
    """A bad simulation setting (noise model, world parameter, pose); the message names it."""
