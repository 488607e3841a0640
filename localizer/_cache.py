"""One small cache of read-only tables built per part (the filter's tracks, the jaw's reach)."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

__all__ = ["per_part"]

_ENTRIES: OrderedDict[tuple, object] = OrderedDict()
_SIZE = 16


def per_part(kind: str, part, args: tuple, build: Callable[[], T]) -> T:
    """The table ``kind`` of ``part`` for ``args``, built by ``build()`` on first use.

    Keyed by the part's points (two Part objects of the same points share their tables)
    and ``args`` (hashable). The tables are read-only, so callers can share them; the
    least recently used of more than 16 is dropped.
    """
    key = (kind, part.points.tobytes(), part.cells_per_piece, args)
    hit = _ENTRIES.get(key)
    if hit is not None:
        _ENTRIES.move_to_end(key)
        return hit  # type: ignore[return-value]
    value = build()
    _ENTRIES[key] = value
    while len(_ENTRIES) > _SIZE:
        _ENTRIES.popitem(last=False)
    return value
