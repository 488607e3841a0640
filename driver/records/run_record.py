"""Which kind of run a record holds: fixed rolls, a straight jaw's reactive rolling or a wheel's, whether a
trace (``.npz``) or a run log (``.jsonl``, read once), for the commands that read any of them."""

from __future__ import annotations

import os
from typing import Any, NamedTuple

import numpy as np

from ..rig import RigError
from .filter_log import LOG_COLUMNS, REACTIVE_FORMAT, calls_from_events
from .runlog import read_log
from .trace import Trace, read_archive, trace_format
from .wheel_trace import WHEEL_FORMAT, WheelTrace

__all__ = ["RunRecord", "open_record", "reactive_calls", "check_finger", "RECORD_KINDS"]

#: The kinds of run a record can hold.
RECORD_KINDS = ("fixed", "reactive", "wheel")


class RunRecord(NamedTuple):
    """A run's record: its kind (one of :data:`RECORD_KINDS`), its path, a run log's events (None for a
    trace) and a reactive run log's filter calls (:data:`LOG_COLUMNS`; None otherwise)."""

    kind: str
    path: str
    events: list[dict[str, Any]] | None
    calls: dict[str, np.ndarray] | None = None

    def fixed(self) -> Trace:
        """The fixed rolls' trace (a run log made into one)."""
        return Trace.from_log(self.path, self.events) if self.events is not None else Trace.load(self.path)

    def wheel(self) -> WheelTrace:
        """The wheel's trace (a run log made into one)."""
        return WheelTrace.from_log(self.path, self.events) if self.events is not None else WheelTrace.load(self.path)


def open_record(path: str | os.PathLike[str]) -> RunRecord:
    """The record at ``path`` and which kind of run it holds.

    Raises
    ------
    RigError
        Not a rolltouch trace or run log; a reactive run's log that ended before it logged its filter calls
        (its last belief event is its answer, and nothing can be replayed).
    """
    path = str(path)
    if not path.endswith(".jsonl"):
        kind = {WHEEL_FORMAT: "wheel", REACTIVE_FORMAT: "reactive"}.get(trace_format(path), "fixed")
        return RunRecord(kind, path, None)
    events = read_log(path)
    if str(events[0].get("jaw", "straight")).startswith("wheel"):
        return RunRecord("wheel", path, events)
    calls = calls_from_events(events)
    if calls is not None:
        return RunRecord("reactive", path, events, calls)
    if any(e.get("event") == "belief" for e in events):
        raise RigError(
            f"run log {path} is of a reactive run whose filter calls it does not hold (the run ended before its "
            "result, or was logged before they were): its last belief event is its answer"
        )
    return RunRecord("fixed", path, events)


def reactive_calls(
    record: RunRecord,
) -> tuple[dict[str, Any], dict[str, np.ndarray], dict[str, np.ndarray] | None]:
    """A reactive record's run (its JSON object with its part's record), its filter's kept calls
    (:data:`LOG_COLUMNS`) and, for a trace, its readings (``arcs``, ``turns``, ``true_arcs``; None for a log)."""
    if record.events is not None:
        if record.calls is None:
            raise RigError(f"run log {record.path} holds no filter calls")
        events = record.events
        result: dict[str, Any] = next((e for e in reversed(events) if e.get("event") == "result"), {})
        return {**result, "part": events[0].get("part")}, record.calls, None
    meta, columns = read_archive(record.path, LOG_COLUMNS)
    return meta, columns, read_archive(record.path, ("arcs", "turns", "true_arcs"))[1]


def check_finger(path: str | os.PathLike[str], finger: object, jaw: object | None) -> None:
    """Refuse a ``--jaw`` given (``jaw``; None: not given) that is not the ``finger`` the record at ``path`` was
    made with (both as their text, e.g. ``wheel:5``)."""
    if jaw is not None and str(jaw) != str(finger):
        raise RigError(f"trace {path} is of the {finger} finger, not of --jaw {jaw}")
