"""A run as an MCAP file (the format of ROS 2 bags and Foxglove): JSON messages on named topics.

Every kind of record a run leaves is read as timestamped messages (:func:`run_messages`) on the topics of
:data:`TOPICS`, each with a JSON schema (:data:`SCHEMAS`), and written by :func:`write_mcap` with the
``mcap`` library:

``/rolltouch/wrist``
    one message per reading: what the wrist read (``dv1``, ``dv2`` V against its zero; a serial rig's raw
    samples ``v1``, ``v2``), the contact's place on the jaw (``jaw_position`` mm) or, for a reactive
    rolling or a wheel, the contact travel given to the filter (``arc`` mm, ``segment``);
``/rolltouch/arm``
    one message per reading: the hand's commanded and measured pose (``x``, ``y`` mm, ``phi_command``,
    ``phi`` rad) or its net turn (``turn`` rad);
``/rolltouch/truth``
    on a simulated rig, one message per reading: the true contact (``true_arc`` mm on the part,
    ``true_jaw_position`` mm on the jaw);
``/rolltouch/belief``
    at every check of a reactive rolling: ``rotation`` (rad rolled), ``map_arc`` (mm), ``mass``, and the
    leading ``modes`` where the record has them;
``/rolltouch/roll``, ``/rolltouch/event``
    a roll's start (angle, step, offset); any other event of a run log (start, calibration, result,
    error, retry, safe stop) as it was logged.

Times: a run log's clock (Unix time, s), a two-roll trace's own (s from its start); a reactive or wheel
trace holds none, and its readings are numbered at :data:`READING_PERIOD` apart from 0. The run's
description (the log's start event, a trace's metadata) is written as MCAP metadata ``rolltouch``.
"""

from __future__ import annotations

import json
import math
import os
from collections import Counter
from collections.abc import Iterable
from typing import Any, NamedTuple

import numpy as np

from ..rig import RigError
from .filter_log import REACTIVE_FORMAT
from .runlog import _clean, check_event, read_log
from .trace import COLUMNS, FORMAT, Trace, read_archive, trace_format
from .wheel_trace import WHEEL_FORMAT, WheelTrace

__all__ = ["TOPICS", "SCHEMAS", "READING_PERIOD", "Message", "run_messages", "write_mcap", "export_mcap"]

#: The topics, by what they carry.
TOPICS = {
    "wrist": "/rolltouch/wrist",
    "arm": "/rolltouch/arm",
    "truth": "/rolltouch/truth",
    "belief": "/rolltouch/belief",
    "roll": "/rolltouch/roll",
    "event": "/rolltouch/event",
}
#: Seconds between readings where a record keeps no clock (a reactive rolling's or a wheel's trace).
READING_PERIOD = 0.1


def _schema(title: str, fields: dict[str, str]) -> dict[str, Any]:
    kinds = {"number": {"type": ["number", "null"]}, "integer": {"type": "integer"}, "array": {"type": "array"}}
    return {"title": title, "type": "object", "properties": {k: kinds[v] for k, v in fields.items()}}


#: The JSON schema of each topic's messages (jsonschema, as Foxglove reads them).
SCHEMAS = {
    TOPICS["wrist"]: _schema(
        "rolltouch.Wrist",
        {
            "roll": "integer",
            "step": "integer",
            "dv1": "number",
            "dv2": "number",
            "v1": "number",
            "v2": "number",
            "jaw_position": "number",
            "arc": "number",
            "segment": "integer",
        },
    ),
    TOPICS["arm"]: _schema(
        "rolltouch.Arm", {"x": "number", "y": "number", "phi_command": "number", "phi": "number", "turn": "number"}
    ),
    TOPICS["truth"]: _schema("rolltouch.Truth", {"true_arc": "number", "true_jaw_position": "number"}),
    TOPICS["belief"]: _schema(
        "rolltouch.Belief", {"rotation": "number", "map_arc": "number", "mass": "number", "modes": "array"}
    ),
    TOPICS["roll"]: _schema(
        "rolltouch.Roll", {"roll": "integer", "angle": "number", "step": "number", "offset": "number"}
    ),
    TOPICS["event"]: {"title": "rolltouch.Event", "type": "object"},
}


class Message(NamedTuple):
    """One message: its topic, its time (s) and its fields (JSON-able)."""

    topic: str
    time: float
    data: dict[str, Any]


def _pick(row: dict[str, Any], keys: Iterable[str]) -> dict[str, Any]:
    return {k: row[k] for k in keys if k in row}


def _finite(x: object) -> bool:
    return isinstance(x, (int, float)) and math.isfinite(x)


#: The fields of a logged reading, sample, check or roll that must be numbers where present.
_NUMBERS = (
    *COLUMNS[2:],
    "jaw_position",
    "length",
    "turn",
    "v1",
    "v2",
    "rotation",
    "map_arc",
    "mass",
    "angle",
    "offset",
)


def _log_messages(path: str | os.PathLike[str]) -> tuple[list[Message], dict[str, Any]]:
    events = read_log(path)
    t = float(events[0]["time"]) if _finite(events[0].get("time")) else 0.0
    out: list[Message] = []
    for k, e in enumerate(events[1:], start=1):
        t = float(e["time"]) if _finite(e.get("time")) else t  # an event without a clock: the last one's time
        kind = e.get("event")
        if kind in ("reading", "sample", "belief", "roll"):
            check_event(path, k, e, whole=("roll", "segment"), numbers=_NUMBERS)
        if kind == "reading" and "dv1" in e:  # a straight jaw's reading
            out.append(Message(TOPICS["wrist"], t, _pick(e, ("roll", "step", "dv1", "dv2", "jaw_position"))))
            out.append(Message(TOPICS["arm"], t, _pick(e, ("x", "y", "phi_command", "phi"))))
            if _finite(e.get("true_arc")):
                out.append(Message(TOPICS["truth"], t, _pick(e, ("true_arc", "true_jaw_position"))))
        elif kind == "reading":  # a wheel's: the axle's arc and the hand's turn
            out.append(Message(TOPICS["wrist"], t, {"arc": e.get("length"), "segment": int(e.get("segment", 0))}))
            out.append(Message(TOPICS["arm"], t, {"turn": e.get("turn")}))
        elif kind == "sample":
            out.append(Message(TOPICS["wrist"], t, _pick(e, ("v1", "v2"))))
        elif kind == "belief":
            data = _pick(e, ("rotation", "map_arc", "mass"))
            if isinstance(e.get("modes"), list):
                data["modes"] = [{"arc": m[0], "mass": m[1]} for m in e["modes"] if isinstance(m, list) and len(m) == 2]
            out.append(Message(TOPICS["belief"], t, data))
            if _finite(e.get("true_arc")):
                out.append(Message(TOPICS["truth"], t, {"true_arc": e["true_arc"]}))
        elif kind == "roll":
            out.append(Message(TOPICS["roll"], t, _pick(e, ("roll", "angle", "step", "offset"))))
        else:
            out.append(Message(TOPICS["event"], t, {k: v for k, v in e.items() if k != "time"}))
    meta = {k: v for k, v in events[0].items() if k not in ("event", "time")}
    return out, meta


def _trace_messages(trace: Trace) -> list[Message]:
    c = trace.columns
    jaw = trace.jaw_positions()
    out: list[Message] = []
    for k in range(c["time"].size):
        t = float(c["time"][k])
        row = {name: float(c[name][k]) for name in COLUMNS}
        wrist = {"roll": int(c["roll"][k]), "step": int(c["step"][k]), "dv1": row["dv1"], "dv2": row["dv2"]}
        out.append(Message(TOPICS["wrist"], t, {**wrist, "jaw_position": float(jaw[k])}))
        out.append(Message(TOPICS["arm"], t, _pick(row, ("x", "y", "phi_command", "phi"))))
        if math.isfinite(row["true_arc"]):
            out.append(Message(TOPICS["truth"], t, _pick(row, ("true_arc", "true_jaw_position"))))
    return out


def _reactive_messages(path: str | os.PathLike[str]) -> tuple[list[Message], dict[str, Any]]:
    meta, c = read_archive(path, ("arcs", "turns", "true_arcs", "segments"))
    try:
        with np.load(path, allow_pickle=False) as data:
            history = np.array(data["history"], dtype=float).reshape(-1, 4) if "history" in data.files else None
    except (OSError, ValueError):
        raise RigError(f"trace {path}: its belief history is damaged") from None
    out = _rolling_messages(c["arcs"], c["segments"], c["turns"], c["true_arcs"])
    if history is not None and history.size:
        # each check at the first reading by which the jaw had rolled its rotation
        rolled = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(c["turns"])))])
        at = np.minimum(np.searchsorted(rolled, history[:, 0] - 1e-9), max(rolled.size - 1, 0))
        for (rotation, map_arc, mass, _), k in zip(history, at):
            out.append(
                Message(
                    TOPICS["belief"],
                    float(k) * READING_PERIOD,
                    {"rotation": float(rotation), "map_arc": float(map_arc), "mass": float(mass)},
                )
            )
    return out, meta


def _wheel_messages(trace: WheelTrace) -> list[Message]:
    c = trace.columns
    return _rolling_messages(c["length"], c["segment"], c["turn"], c["true_arc"])


def _rolling_messages(arc: np.ndarray, segment: np.ndarray, turn: np.ndarray, true_arc: np.ndarray) -> list[Message]:
    """A reactive rolling's or a wheel's readings, numbered :data:`READING_PERIOD` apart: the contact travel
    given to the filter and its segment, the net turn, the truth where known."""
    out: list[Message] = []
    for k in range(arc.size):
        t = k * READING_PERIOD
        out.append(Message(TOPICS["wrist"], t, {"arc": float(arc[k]), "segment": int(segment[k])}))
        out.append(Message(TOPICS["arm"], t, {"turn": float(turn[k])}))
        if math.isfinite(float(true_arc[k])):
            out.append(Message(TOPICS["truth"], t, {"true_arc": float(true_arc[k])}))
    return out


def run_messages(path: str | os.PathLike[str]) -> tuple[list[Message], dict[str, Any]]:
    """The messages of a run's record, in time order, and the run's description.

    ``path`` is a run log (``.jsonl``) or a trace (``.npz``) of a fixed-rolls run, a reactive rolling or a
    wheel.

    Raises
    ------
    RigError
        Not a rolltouch run log or trace (its message says which and why).
    """
    if str(path).endswith(".jsonl"):
        messages, meta = _log_messages(path)
    else:
        kind = trace_format(path)
        if kind == FORMAT:
            trace = Trace.load(path)
            messages, meta = _trace_messages(trace), dict(trace.metadata)
        elif kind == REACTIVE_FORMAT:
            messages, meta = _reactive_messages(path)
        elif kind == WHEEL_FORMAT:
            wheel = WheelTrace.load(path)
            messages, meta = _wheel_messages(wheel), dict(wheel.metadata)
        else:
            raise RigError(
                f"trace {path}: format {kind!r} is none of a run's records "
                f"({FORMAT}, {REACTIVE_FORMAT}, {WHEEL_FORMAT})"
            )
    return sorted(messages, key=lambda m: m.time), meta


def write_mcap(messages: Iterable[Message], metadata: dict[str, Any], out: str | os.PathLike[str]) -> Counter[str]:
    """Write ``messages`` to the MCAP file ``out`` (JSON encoding, a JSON schema per topic), ``metadata`` as the
    MCAP metadata record ``rolltouch`` (each value JSON-encoded); returns the messages written per topic."""
    from mcap.writer import Writer

    counts: Counter[str] = Counter()
    try:
        with open(out, "wb") as f:
            writer = Writer(f)
            writer.start(profile="", library="rolltouch")
            channels: dict[str, int] = {}
            for topic, schema in SCHEMAS.items():
                sid = writer.register_schema(schema["title"], "jsonschema", json.dumps(schema).encode())
                channels[topic] = writer.register_channel(topic, "json", sid)
            for seq, m in enumerate(messages):
                ns = max(int(round(m.time * 1e9)), 0)
                data = json.dumps(_clean(m.data), allow_nan=False).encode()
                writer.add_message(channels[m.topic], log_time=ns, data=data, publish_time=ns, sequence=seq)
                counts[m.topic] += 1
            writer.add_metadata("rolltouch", {str(k): json.dumps(_clean(v)) for k, v in metadata.items()})
            writer.finish()  # type: ignore[no-untyped-call]  # mcap 1.6 leaves it unannotated
    except OSError as exc:
        raise RigError(f"cannot write {out}: {exc.strerror or exc}") from None
    return counts


def export_mcap(path: str | os.PathLike[str], out: str | os.PathLike[str]) -> Counter[str]:
    """A run's record (:func:`run_messages`) written to the MCAP file ``out``; the messages per topic."""
    messages, meta = run_messages(path)
    return write_mcap(messages, meta, out)
