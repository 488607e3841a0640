"""How large a file the package reads: checked before reading, so that a huge or crafted file is a
clear error and not the machine's memory (issue 18)."""

from __future__ import annotations

import os
from pathlib import Path

from ._errors import PartError

__all__ = ["MAX_PART_BYTES", "check_size"]

#: The largest part file read, bytes: a 90-point part is 3 kB, a detailed DXF drawing a few MB.
MAX_PART_BYTES = 64 * 2**20


def check_size(path: str | os.PathLike[str], limit: int, what: str, error: type[Exception] = PartError) -> None:
    """Raise ``error`` naming ``path`` when the file is larger than ``limit`` bytes (or cannot be
    examined).

    Parameters
    ----------
    path : str or Path
    limit : int, bytes
    what : str
        What the file is, for the message ("part file", "trace", ...).
    error : type
        The exception raised (a :class:`RolltouchError` subclass; default :class:`PartError`).
    """
    try:
        size = Path(path).stat().st_size
    except FileNotFoundError:
        raise error(f"{path}: cannot read {what} (no such file)") from None
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    if size > limit:
        raise error(
            f"{path}: {size / 2**20:.1f} MB is more than the {limit / 2**20:.0f} MB a {what} may have; "
            "is it the right file?"
        )
