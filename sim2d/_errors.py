"""The simulator's error, under the package's one root."""

from localizer import RolltouchError

__all__ = ["SimError"]


class SimError(RolltouchError, ValueError):
    """A bad simulation setting (noise model, world parameter, pose); the message names it."""
