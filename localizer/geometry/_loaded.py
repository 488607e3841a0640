"""Parts read from files, kept while the file's bytes are the same.

Reading a drawing costs 0.1–0.5 s (ezdxf's parse most of it), and a part's tables (the reach, the
tracks, the wheel's grids; :func:`~localizer.geometry.per_part`) from milliseconds to seconds. A
script, a study's worker or a test session that reads the same file again gets the same part, its
tables with it: a part is frozen, its tables read-only. The key is what the part is made of: the path
as given (the part's name and source), a digest of the file's bytes and the reading's options, so that
a file edited since is read again whatever its size and time stamp; a file that cannot be read, or
whose part is refused, is not kept. At most
:data:`LOADED_PARTS` parts are kept, the least recently read dropped first.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from pathlib import Path
from typing import Any, TypeVar

T = TypeVar("T")

__all__ = ["LOADED_PARTS", "read_once", "forget_loaded"]

#: How many parts read from files are kept (each with its tables: a few MB for a drawing of 10⁵ facets).
LOADED_PARTS = 16

_lock = threading.Lock()
_kept: OrderedDict[tuple[str, bytes, Hashable], Any] = OrderedDict()


def read_once(path: Path, options: Hashable, read: Callable[[], T]) -> T:
    """The part ``read()`` makes of the file at ``path`` with ``options``: the one made before if the
    file's bytes are the same (module notes). The file's size is the caller's to check first."""
    try:
        digest = hashlib.blake2b(path.read_bytes(), digest_size=16).digest()
        key = (str(path), digest, options)
    except OSError:
        return read()  # the reader says what is wrong with the file
    with _lock:
        if key in _kept:
            _kept.move_to_end(key)
            kept: T = _kept[key]
            return kept
    value = read()
    with _lock:
        _kept[key] = value
        while len(_kept) > LOADED_PARTS:
            _kept.popitem(last=False)
    return value


def forget_loaded() -> None:
    """Drop every part kept (the next read of each file parses it again)."""
    with _lock:
        _kept.clear()
