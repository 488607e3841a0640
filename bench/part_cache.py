"""Part files read once per worker process, their tables kept with them (every trial of a study asks)."""

from __future__ import annotations

import functools

from localizer import Outline, Part, load_part

__all__ = ["cached_part"]


@functools.cache
def cached_part(path: str) -> Part | Outline:
    """The part file at ``path``, read once per process."""
    return load_part(path)
