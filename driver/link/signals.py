"""Signal handlers set for the length of a block, and put back after it."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["handling"]


@contextlib.contextmanager
def handling(names: tuple[str, ...], handler: Callable[[int, Any], Any] | signal.Handlers) -> Iterator[None]:
    """Set ``handler`` for the signals ``names`` (those this platform has) while the block runs, then
    restore the previous ones. Only the main thread may set handlers: elsewhere nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    sigs = [getattr(signal, n) for n in names if hasattr(signal, n)]
    old = {sig: signal.signal(sig, handler) for sig in sigs}
    try:
        yield
    finally:
        for sig, previous in old.items():
            signal.signal(sig, previous)
