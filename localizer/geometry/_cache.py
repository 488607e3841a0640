"""The one way a table built from a part is kept: with the part, for as long as the part lives.

The arc tables, the march's grid, the filter's tracks and the jaw's reach are read-only and cost
from milliseconds to seconds to build; every user of a part shares them. They live in the part's
own store (so they go when the part goes), and :meth:`localizer.Part.forget_tables` drops them.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import TYPE_CHECKING, TypeVar, cast

if TYPE_CHECKING:
    from ._boundary import Boundary

T = TypeVar("T")

__all__ = ["per_part"]


def per_part(kind: str, part: Boundary, args: Hashable, build: Callable[[], T], *, latest_only: bool = False) -> T:
    """The table ``kind`` of ``part`` for ``args``, built by ``build()`` on first use.

    ``latest_only``: keep only the latest ``args`` of this kind (a table too large to keep several
    of, like the march's grid at a fine step).
    """
    store = part._tables
    key = (kind, args)
    if key in store:
        # the store holds every kind's tables; this key's value is the one ``build`` made
        return cast(T, store[key])
    value = build()
    if latest_only:
        for old in [k for k in store if k[0] == kind]:
            del store[old]
    store[key] = value
    return value
