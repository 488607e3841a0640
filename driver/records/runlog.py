"""The run log: JSON Lines, one event per line, flushed as it is written.

A killed process leaves a readable log of everything read until then; a
truncated last line is ignored when the log is read back. Events:

``start``
    ``format``, the calibration, and how the run was made (part, rolls, …).
``roll``
    a roll begins: ``roll`` index, ``angle``, ``step`` (rad), ``steps``, ``offset`` (mm).
``reading``
    a contact-location reading: ``roll``, ``step``, ``time``, ``x``, ``y``,
    ``phi_command``, ``phi``, ``dv1``, ``dv2`` (and ``true_arc``,
    ``true_jaw_position`` on a simulated rig).
``sample``, ``retry``, ``safe_stop``
    from the serial rig: every raw reading, every retried command, a safe stop.
``result`` / ``error``
    how the run ended.
"""

from __future__ import annotations

import json
import math
import os
import time
from typing import Any

import numpy as np

from localizer import check_size

from ..rig import RigError

__all__ = ["RunLog", "read_log", "LOG_FORMAT", "check_event", "check_calibration"]

LOG_FORMAT = "rolltouch-log/1"


def _clean(value: object) -> object:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, (np.floating, np.integer)):
        return _clean(value.item())
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


class RunLog:
    """Append events to a JSON Lines file, flushing each one.

    Parameters
    ----------
    path : str or Path
    header : dict
        Written as the ``start`` event (with ``format``).
    """

    def __init__(self, path: str | os.PathLike[str], header: dict[str, Any]) -> None:
        self.path = str(path)
        try:
            # open for the run's whole length, closed by close() (on success and on every failure)
            self._f = open(self.path, "w", encoding="utf-8")  # noqa: SIM115
        except OSError as exc:
            raise RigError(f"cannot write the run log {self.path}: {exc.strerror or exc}") from None
        self({"event": "start", "format": LOG_FORMAT, **header})

    def __call__(self, event: dict[str, Any]) -> None:
        if self._f.closed:
            return
        event = dict(event)
        event.setdefault("time", time.time())
        self._f.write(json.dumps(_clean(event)) + "\n")
        self._f.flush()

    def close(self) -> None:
        if not self._f.closed:
            self._f.close()


#: The largest run log read, bytes (a run's log is a few MB; a day of logging at every sample, ~200 MB).
MAX_LOG_BYTES = 256 * 2**20


def read_log(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The events of a run log, skipping a truncated last line.

    Raises
    ------
    RigError
        Unreadable file, no ``start`` event, a bad line other than the last.
    """
    check_size(path, MAX_LOG_BYTES, "run log", RigError)
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
    except UnicodeDecodeError:
        raise RigError(f"run log {path}: not a text file; not a rolltouch run log") from None
    except OSError as exc:
        raise RigError(f"run log {path}: {exc.strerror or exc}") from None
    events: list[dict[str, Any]] = []
    for k, line in enumerate(lines):
        if not line.strip():
            continue
        try:
            event = json.loads(line)
        except (json.JSONDecodeError, RecursionError):
            if k >= len(lines) - 2:  # the last line, cut off by a killed process
                break
            raise RigError(f"run log {path}: line {k + 1} is not JSON") from None
        if not isinstance(event, dict):
            raise RigError(f"run log {path}: line {k + 1} is not a JSON object (an event)")
        events.append(event)
    if not events or events[0].get("event") != "start" or events[0].get("format") != LOG_FORMAT:
        raise RigError(f"run log {path}: not a rolltouch run log (no '{LOG_FORMAT}' start event)")
    return events


def _number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def check_event(
    path: str | os.PathLike[str],
    k: int,
    event: dict[str, Any],
    whole: tuple[str, ...] = (),
    numbers: tuple[str, ...] = (),
) -> None:
    """Refuse, naming the event and the field, a logged event whose ``whole`` fields are not whole numbers or
    whose ``numbers`` are not numbers (or null: a value the rig could not read), where they are present.

    Raises
    ------
    RigError
    """
    for key in whole:
        if key in event and not (isinstance(event[key], int) and not isinstance(event[key], bool)):
            raise RigError(
                f"run log {path}: event {k + 1} ({event.get('event')}) has {key}={event[key]!r}, not a whole number"
            )
    for key in numbers:
        if key in event and event[key] is not None and not _number(event[key]):
            raise RigError(
                f"run log {path}: event {k + 1} ({event.get('event')}) has {key}={event[key]!r}, not a number"
            )


def check_calibration(path: str | os.PathLike[str], cal: object, keys: tuple[str, ...]) -> dict[str, Any]:
    """A logged calibration: a JSON object holding ``keys``, each a number or a list of numbers; else a RigError
    naming what is wrong."""
    if not isinstance(cal, dict):
        raise RigError(f"run log {path}: its calibration is {type(cal).__name__}, not a JSON object")
    missing = [key for key in keys if key not in cal]
    if missing:
        raise RigError(f"run log {path}: its calibration has no {', '.join(missing)}")
    for key in keys:
        value = cal[key]
        if not (_number(value) or (isinstance(value, list) and all(_number(v) for v in value))):
            raise RigError(f"run log {path}: its calibration's {key}={value!r} is not a number or a list of numbers")
    return cal
