"""How large a file the package reads: checked before reading, so that a huge or crafted file is a
clear error and not the machine's memory."""

from __future__ import annotations

import os
import tomllib
from pathlib import Path
from typing import Any

from ._errors import PartError

__all__ = ["MAX_PART_BYTES", "check_size", "read_toml"]

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
        raise error(f"{path}: {_size(size)} is more than the {_size(limit)} a {what} may have; is it the right file?")


def _size(n: int) -> str:
    """A file size for a message: MB from 1 MB on, kB below."""
    if n >= 2**20:
        return f"{n // 2**20} MB" if n % 2**20 == 0 else f"{n / 2**20:.1f} MB"
    return f"{n / 2**10:.1f} kB"


def read_toml(path: str | os.PathLike[str], limit: int, what: str, error: type[Exception]) -> dict[str, Any]:
    """A settings file's TOML tables, its size checked first (:func:`check_size`).

    Parameters
    ----------
    path : str or Path
    limit : int, bytes
    what : str
        What the file is, for the messages ("study", "world file", "noise file").
    error : type
        The exception raised on a file too large, unreadable, not text or not TOML, naming the file.
    """
    check_size(path, limit, what, error)
    try:
        with open(path, "rb") as f:
            raw = f.read(limit + 1)  # a pipe or a device says size 0: read no more than the limit
        if len(raw) > limit:
            raise error(f"{what} {path}: more than the {_size(limit)} a {what} may have; is it the right file?")
        return tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise error(f"{what} {path}: not a text file (TOML expected)") from None
    except OSError as exc:
        raise error(f"{what} {path}: cannot read ({exc.strerror or exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{what} {path}: not valid TOML ({exc})") from None
