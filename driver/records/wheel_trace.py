"""A wheel finger's trace: what a wheel's rolling read, saved as ``.npz`` arrays plus JSON metadata.

One row per reading given to the filter: its segment (the rolling starts afresh when nothing fits),
the arc rolled since the segment's start L (mm, from the axle encoder), the hand's net turn Ω (rad),
and on a simulated rig the true contact (mm). The metadata names the
finger (``jaw``) and holds its calibration, how the run was made and how it ended; a trace is read
back only as a wheel's (:meth:`WheelTrace.load` refuses a straight jaw's trace, and
:meth:`driver.records.trace.Trace.load` a wheel's), and relocalized from its readings with the finger it names.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from localizer import Belief, Outline, Part, WheelFilter, WheelJaw, parse_jaw

from ..rig import RigError
from ..wheel import WheelCalibration, WheelRun
from .trace import read_archive

__all__ = ["WheelTrace", "WHEEL_COLUMNS", "WHEEL_FORMAT"]

WHEEL_COLUMNS = ("segment", "length", "turn", "true_arc")
WHEEL_FORMAT = "rolltouch-wheel-trace/1"


@dataclass(frozen=True)
class WheelTrace:
    """A wheel's readings and metadata.

    Attributes
    ----------
    columns : dict of str -> ndarray
        :data:`WHEEL_COLUMNS`.
    metadata : dict
        ``format``, ``jaw``, ``calibration`` (:meth:`WheelCalibration.as_dict`) and how the run was made.
    """

    columns: dict[str, np.ndarray]
    metadata: dict[str, Any]

    @classmethod
    def from_run(cls, run: WheelRun, calibration: WheelCalibration, **metadata: Any) -> WheelTrace:
        """The readings of a :class:`driver.wheel.WheelRun` with ``metadata`` about how it was made."""
        columns = {
            "segment": np.asarray(run.segments, dtype=np.int64),
            "length": np.asarray(run.lengths, dtype=float),
            "turn": np.asarray(run.turns, dtype=float),
            "true_arc": np.asarray(run.true_arcs, dtype=float),
        }
        meta = {
            "format": WHEEL_FORMAT,
            "jaw": calibration.jaw,
            "calibration": calibration.as_dict(),
            "stopped": run.stopped,
            "rotation_deg": math.degrees(run.rotation),
            "arc_mm": run.arc,
            "jumps": run.jumps,
            "slip_mm": run.slip,
            **metadata,
        }
        return cls(columns, meta)

    @classmethod
    def from_log(cls, path: str | os.PathLike[str], events: list[dict[str, Any]] | None = None) -> WheelTrace:
        """A trace from a wheel's run log (JSON Lines, :mod:`driver.records.runlog`), cut short or not: its
        ``reading`` events (L, Ω) and the calibration it logged."""
        from .runlog import check_event, read_log

        events = read_log(path) if events is None else events  # ``events``: the log already read
        start = events[0]
        jaw = start.get("jaw")
        if not (isinstance(jaw, str) and jaw.startswith("wheel")):
            raise RigError(f"run log {path}: a {jaw or 'straight:100'} finger's log, not a wheel's")
        rows = [e for e in events if e.get("event") == "reading"]
        bad = [
            k for k, e in enumerate(rows) if not all(isinstance(e.get(key), (int, float)) for key in ("length", "turn"))
        ]
        if bad:
            raise RigError(f"run log {path}: reading {bad[0] + 1} has no length and turn")
        for k, e in enumerate(events):
            if e.get("event") == "reading":
                check_event(path, k, e, whole=("segment",), numbers=("length", "turn"))
        cal = start.get("calibration") or next((e for e in events if e.get("event") == "calibration"), None)
        if cal is None:
            raise RigError(f"run log {path}: it logged no calibration")
        if not isinstance(cal, dict):
            raise RigError(f"run log {path}: its calibration is {type(cal).__name__}, not a JSON object")
        columns = {
            "segment": np.array([int(e.get("segment", 0)) for e in rows], dtype=np.int64),
            "length": np.array([e["length"] for e in rows], dtype=float),
            "turn": np.array([e["turn"] for e in rows], dtype=float),
            "true_arc": np.full(len(rows), math.nan),
        }
        meta = {k: v for k, v in start.items() if k not in ("event", "format", "time")}
        meta.update(
            {
                "format": WHEEL_FORMAT,
                "calibration": {k: v for k, v in cal.items() if k not in ("event", "time")},
                "log": str(path),
                "complete": any(e.get("event") == "result" for e in events),
            }
        )
        return cls(columns, meta)

    @property
    def wheel(self) -> WheelJaw:
        finger = parse_jaw(self.metadata["jaw"])
        if not isinstance(finger, WheelJaw):
            raise RigError(f"a wheel trace that names a {finger} finger")
        return finger

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write ``path`` (.npz): the columns and a ``metadata`` JSON string."""
        np.savez(path, metadata=np.array(json.dumps(self.metadata)), **cast(dict[str, Any], self.columns))

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> WheelTrace:
        """Read a trace written by :meth:`save`, or a wheel's run log (``.jsonl``).

        Raises
        ------
        RigError
            Not a wheel's trace (a straight jaw's names its own format), unreadable, crafted.
        """
        if str(path).endswith(".jsonl"):
            return cls.from_log(path)
        meta, columns = read_archive(path, WHEEL_COLUMNS)
        if meta.get("format") != WHEEL_FORMAT:
            raise RigError(f"trace {path}: format {meta.get('format')!r}, expected a wheel's {WHEEL_FORMAT!r}")
        if not isinstance(meta.get("jaw"), str):
            raise RigError(f"trace {path}: its metadata names no finger ('jaw')")
        trace = cls(columns, meta)
        _ = trace.wheel  # the finger it names must be a wheel
        return trace

    def relocalize(self, part: Part | Outline, **filter_options: Any) -> Belief:
        """The belief from the trace's readings, replayed into a :class:`localizer.WheelFilter` for its finger."""
        flt = WheelFilter(part, self.wheel, **filter_options)
        last = self.columns["segment"][-1] if self.columns["segment"].size else 0
        for seg, L, om in zip(self.columns["segment"], self.columns["length"], self.columns["turn"]):
            if seg == last:  # the belief is the last segment's: the rolling started afresh there
                flt.update(float(L), float(om))
        return flt.belief()

    @property
    def true_arc(self) -> float:
        """The last reading's true contact (NaN without truth)."""
        arc = self.columns["true_arc"]
        return float(arc[-1]) if arc.size else math.nan
