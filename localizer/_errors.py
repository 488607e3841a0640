"""The package's errors: one root, :class:`RolltouchError`, for every error rolltouch raises on
purpose. Each specific error also subclasses the built-in it is a kind of, so ``except
ValueError`` keeps working; a bug (a ``TypeError`` from our own code, say) is not one of ours
and is never reported as bad input."""

__all__ = ["RolltouchError", "LocalizerError", "PartError", "QueryError"]


class RolltouchError(Exception):
    """Root of every error that rolltouch raises on purpose; the message names the bad value."""


class LocalizerError(RolltouchError, ValueError):
    """Root of the errors raised by :mod:`localizer`."""


class PartError(LocalizerError):
    """A part file or point list that does not describe a valid part.

    The message names the offending value (file, point index, parameter)
    and what to do about it.
    """


class QueryError(LocalizerError):
    """A localization query with an argument out of range or of the wrong kind."""
