"""A reactive rolling's filter calls, kept so that the belief can be had again from a saved trace.

The reactive rolling (:mod:`driver.jaw.reactive`) tells its :class:`localizer.ContactFilter` what it read
(``update``, ``touch``, ``regrasp``), what it saw (``bridged``), when it started afresh (``reset``) and
when it asked (``belief``: the fit test and the quarantine it may start happen there). The belief at
the end depends on all of them and on their order, so :class:`LoggedFilter` keeps them, the outermost
only (``regrasp`` calls ``update`` itself), as five numeric columns that a trace stores
(:data:`LOG_COLUMNS`), and :func:`replay_log` makes the same calls on a fresh filter: the same
settings give the same belief.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import Any, cast

import numpy as np

from localizer import BRIDGE_JUMP, Belief, ContactFilter

__all__ = [
    "LoggedFilter",
    "replay_log",
    "log_table",
    "Observer",
    "calls_event",
    "calls_from_events",
    "LOG_COLUMNS",
    "CALLS",
    "REACTIVE_FORMAT",
    "FILTER_CALLS_EVENT",
]

#: The ``format`` of a reactive rolling's trace ('simulate --reactive' with the straight jaw): its
#: readings, the filter's calls (:data:`LOG_COLUMNS`) and the run's JSON object as metadata.
REACTIVE_FORMAT = "rolltouch-reactive/1"
#: The run log's event that holds a reactive run's filter calls (:data:`LOG_COLUMNS` as lists, None for
#: NaN), written at the end of 'run --reactive'.
FILTER_CALLS_EVENT = "filter_calls"

#: The filter calls kept, by their code in the ``call`` column.
CALLS = ("reset", "update", "touch", "bridged", "regrasp", "belief")
#: The columns of a kept log: the call's code, then its numeric arguments (NaN where it takes none or
#: was given None): arc (mm), turn (rad), jaw (mm), and ``value``: a bridge's jump (mm) or a belief's
#: radius (mm).
LOG_COLUMNS = ("call", "arc", "turn", "jaw", "value")


def _num(x: float | None) -> float:
    return math.nan if x is None else float(x)


def _arg(x: float) -> float | None:
    return None if math.isnan(x) else float(x)


#: A kept call as :func:`log_table` takes it: its name (one of :data:`CALLS`), then arc, turn, jaw and value
#: (None where it takes none or was given None).
KeptCall = tuple[str, float | None, float | None, float | None, float | None]
#: Told of each call :func:`replay_log` makes: its name, arc, turn, jaw, value (NaN where none) and, for a
#: ``belief`` call, the belief it gave (else None).
Observer = Callable[[str, float, float, float, float, Belief | None], object]


def log_table(calls: Iterable[KeptCall]) -> dict[str, np.ndarray]:
    """Calls as a kept log's columns (:data:`LOG_COLUMNS`; ``call``: int8 codes of :data:`CALLS`, NaN for None)."""
    rows = [(CALLS.index(name), _num(arc), _num(turn), _num(jaw), _num(value)) for name, arc, turn, jaw, value in calls]
    table = np.array(rows, dtype=float).reshape(-1, len(LOG_COLUMNS))
    out = {name: table[:, k] for k, name in enumerate(LOG_COLUMNS)}
    out["call"] = table[:, 0].astype(np.int8)
    return out


class LoggedFilter(ContactFilter):
    """A :class:`localizer.ContactFilter` that keeps the calls made to it (:meth:`columns`)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._kept: list[KeptCall] = []
        self._log_depth = 0
        super().__init__(*args, **kwargs)
        self._kept.clear()  # the constructor's own reset is not a call

    def _keep(self, name: str, arc: float | None = None, turn: float | None = None, jaw: float | None = None,
              value: float | None = None) -> bool:  # fmt: skip
        """Keep the call if it is the outermost one; True then."""
        if self._log_depth:
            return False
        self._kept.append((name, arc, turn, jaw, value))
        return True

    def _call(self, method: Any, *args: Any) -> Any:
        self._log_depth += 1
        try:
            return method(*args)
        finally:
            self._log_depth -= 1

    def reset(self) -> None:
        if hasattr(self, "_kept"):
            self._keep("reset")
        self._call(super().reset)

    def update(self, arc: float, turn: float, jaw: float | None = None) -> None:
        self._keep("update", arc, turn, jaw)
        self._call(super().update, arc, turn, jaw)

    def touch(self, jaw: float) -> None:
        self._keep("touch", jaw=jaw)
        self._call(super().touch, jaw)

    def bridged(self, turn: float, jaw: float | None = None, jump: float = BRIDGE_JUMP) -> float:
        self._keep("bridged", turn=turn, jaw=jaw, value=jump)
        return float(self._call(super().bridged, turn, jaw, jump))

    def regrasp(self, arc: float, turn: float, jaw: float | None = None) -> None:
        self._keep("regrasp", arc, turn, jaw)
        self._call(super().regrasp, arc, turn, jaw)

    def belief(self, radius: float | None = None) -> Belief:
        self._keep("belief", value=radius)
        return cast(Belief, self._call(super().belief, radius))

    def columns(self) -> dict[str, np.ndarray]:
        """The calls kept so far, as the arrays :data:`LOG_COLUMNS` names (:func:`log_table`)."""
        return log_table(self._kept)


def calls_event(columns: dict[str, np.ndarray]) -> dict[str, Any]:
    """The run log's event of a kept log (:meth:`LoggedFilter.columns`): JSON lists, None for NaN."""
    return {
        "event": FILTER_CALLS_EVENT,
        **{k: [None if math.isnan(v) else v for v in columns[k].tolist()] for k in LOG_COLUMNS},
    }


def calls_from_events(events: list[dict[str, Any]]) -> dict[str, np.ndarray] | None:
    """The kept log of a run log's events (the last :data:`FILTER_CALLS_EVENT`), or None if it has none."""
    found = [e for e in events if e.get("event") == FILTER_CALLS_EVENT]
    if not found:
        return None
    return {k: np.array([math.nan if v is None else v for v in found[-1][k]], dtype=float) for k in LOG_COLUMNS}


def replay_log(flt: ContactFilter, columns: dict[str, np.ndarray], observe: Observer | None = None) -> Belief:
    """Make the calls of a kept log (:meth:`LoggedFilter.columns`) on ``flt``, a fresh filter; the belief
    after the last of them (asked once more if the log does not end with one). ``observe`` is told of each
    call after it is made (what a picture of the rolling keeps: :func:`driver.records.replay_beliefs`)."""
    belief = None
    for code, arc, turn, jaw, value in zip(*(np.asarray(columns[c]) for c in LOG_COLUMNS), strict=True):
        name = CALLS[int(code)]
        belief = None
        if name == "reset":
            flt.reset()
        elif name == "update":
            flt.update(float(arc), float(turn), _arg(jaw))
        elif name == "touch":
            flt.touch(float(jaw))
        elif name == "bridged":
            flt.bridged(float(turn), _arg(jaw), float(value))
        elif name == "regrasp":
            flt.regrasp(float(arc), float(turn), _arg(jaw))
        else:
            belief = flt.belief(_arg(value))
        if observe is not None:
            observe(name, float(arc), float(turn), float(jaw), float(value), belief)
    return belief if belief is not None else flt.belief()
