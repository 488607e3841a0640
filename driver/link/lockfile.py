"""An exclusive lock held through a small file, between processes (POSIX ``flock``): one host per
device, one Monte Carlo run per output folder."""

from __future__ import annotations

import os
from pathlib import Path
from typing import IO

from localizer import RolltouchError

__all__ = ["LockHeld", "hold_lock"]


class LockHeld(RolltouchError, BlockingIOError):
    """Another process holds the lock; ``holder`` is what it wrote in the file."""

    def __init__(self, path: Path, holder: str) -> None:
        super().__init__(f"{path} is held by {holder}")
        self.path = path
        self.holder = holder


def hold_lock(path: str | os.PathLike[str], me: str) -> IO[str]:
    """Open ``path`` and hold an exclusive lock on it for as long as the returned file is open, with
    ``me`` written in it for whoever finds it taken. Raises :class:`LockHeld` when another process
    holds it. Without ``fcntl`` (not POSIX) the file is opened and nothing is locked."""
    path = Path(path)
    handle = open(path, "a+")  # noqa: SIM115 - the caller holds it open as the lock
    try:
        import fcntl
    except ImportError:
        return handle
    try:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        handle.seek(0)
        holder = handle.read().strip() or "another process"
        handle.close()
        raise LockHeld(path, holder) from None
    handle.seek(0)
    handle.truncate()
    handle.write(me)
    handle.flush()
    return handle
