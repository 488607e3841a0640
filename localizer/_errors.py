"""Exceptions of the localizer: one root, subclassing ``ValueError``."""

__all__ = ["LocalizerError", "PartError", "QueryError"]


class LocalizerError(ValueError):
    """Root of every error raised by :mod:`localizer`."""


class PartError(LocalizerError):
    """A part file or point list that does not describe a valid part.

    The message names the offending value (file, point index, parameter)
    and what to do about it.
    """


class QueryError(LocalizerError):
    """A localization query with an argument out of range or of the wrong kind."""
