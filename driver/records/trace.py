"""Traces: what a rolling run read, saved as ``.npz`` arrays plus JSON metadata (never pickled).

One row per contact-location reading (before each roll and after each of its
steps): roll and step index, time (s), the commanded hand pose (x, y mm,
φ rad), the arm's reading of φ (rad), Δv1 and Δv2 (V, relative to the zero
reading), and on a simulated rig the ground truth: the contact's arc position
on the part (mm) and its location on the jaw (mm).
The metadata holds the calibration, the rolls' step angles and edge offsets,
the estimates (L, Ω) of the run, and how the run was made (part, engine,
noise model, seed, start).
"""

from __future__ import annotations

import json
import math
import os
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from localizer import arc_from_jaw_positions, check_size

from ..jaw import Calibration, RollingRun, step_sequence
from ..rig import RigError

__all__ = ["Trace", "COLUMNS", "FORMAT", "read_archive", "trace_format"]

COLUMNS = ("roll", "step", "time", "x", "y", "phi_command", "phi", "dv1", "dv2", "true_arc", "true_jaw_position")
FORMAT = "rolltouch-trace/1"
#: The largest trace file read, and the most its columns may unpack to, bytes (a long reactive run of
#: 2000 readings is 200 kB; a crafted archive of 2 MB can unpack to gigabytes).
MAX_TRACE_BYTES = 256 * 2**20
MAX_TRACE_UNPACKED = 512 * 2**20


def read_archive(path: str | os.PathLike[str], names: Sequence[str]) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """The metadata (a JSON object) and the named columns (equal-length 1-D numbers) of a trace archive,
    read safely: its size checked before it is opened, never unpickled.

    Raises
    ------
    RigError
        Missing, unreadable, too large, damaged or crafted file; missing or malformed columns.
    """
    check_size(path, MAX_TRACE_BYTES, "trace", RigError)
    try:
        with zipfile.ZipFile(path) as z:
            unpacked = sum(i.file_size for i in z.infolist())
    except (zipfile.BadZipFile, OSError, EOFError, ValueError):
        raise RigError(f"trace {path}: not a rolltouch trace (not an .npz archive, or a damaged one)") from None
    if unpacked > MAX_TRACE_UNPACKED:
        raise RigError(
            f"trace {path}: its columns unpack to {unpacked / 2**20:.0f} MB, more than the "
            f"{MAX_TRACE_UNPACKED / 2**20:.0f} MB a trace may hold; not a rolltouch trace"
        )
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["metadata"])) if "metadata" in data.files else None
            missing = [name for name in ("metadata", *names) if name not in data.files]
            if missing:
                kind = f" ({meta['format']})" if isinstance(meta, dict) and "format" in meta else ""
                raise RigError(f"trace {path}: not a rolltouch trace of this kind{kind} (no {', '.join(missing)})")
            columns = {name: np.array(data[name]) for name in names}
    except RigError:
        raise
    except (OSError, ValueError, KeyError, IndexError, TypeError, EOFError, zipfile.BadZipFile, MemoryError):
        # numpy's own text may suggest allow_pickle=True: a trace never holds Python objects
        raise RigError(f"trace {path}: not a rolltouch trace (a damaged or crafted .npz)") from None
    if not isinstance(meta, dict):
        raise RigError(f"trace {path}: its metadata is a {type(meta).__name__}, not a JSON object")
    sizes = {a.shape for a in columns.values()}
    if names and len(sizes) != 1 or any(a.ndim != 1 or a.dtype.kind not in "fiu" for a in columns.values()):
        raise RigError(f"trace {path}: its columns are not equal-length numbers; not a rolltouch trace")
    return meta, columns


def trace_format(path: str | os.PathLike[str]) -> str:
    """The ``format`` a trace archive's metadata names ("" when it names none)."""
    meta, _ = read_archive(path, ())
    return str(meta.get("format", ""))


@dataclass(frozen=True)
class Trace:
    """A rolling run's readings and metadata.

    Attributes
    ----------
    columns : dict of str -> ndarray
        The per-reading columns of :data:`COLUMNS`.
    metadata : dict
        JSON-able description of the run (see module notes).
    """

    columns: dict[str, np.ndarray]
    metadata: dict[str, Any]

    @classmethod
    def from_run(cls, run: RollingRun, calibration: Calibration, **metadata: Any) -> Trace:
        """Collect the readings of a :class:`RollingRun` with ``metadata`` about how it was made."""
        rows = []
        for k, r in enumerate(run.rolls):
            for j, (rd, t) in enumerate(zip(r.readings, r.truth)):
                rows.append((k, j, rd.time, rd.x, rd.y, rd.phi_commanded, rd.phi, rd.dv1, rd.dv2, *t))
        arr = np.array(rows, dtype=float).reshape(-1, len(COLUMNS))
        columns = {name: arr[:, i] for i, name in enumerate(COLUMNS)}
        columns["roll"] = columns["roll"].astype(np.int64)
        columns["step"] = columns["step"].astype(np.int64)
        meta = dict(metadata)
        meta.update(
            {
                "format": FORMAT,
                "calibration": {
                    "positions": list(calibration.positions),
                    "ratios": list(calibration.ratios),
                    "target": calibration.target,
                },
                "steps": [r.step for r in run.rolls],
                "offsets": [r.offset for r in run.rolls],
                "estimates": [list(e) for e in run.estimates],
            }
        )
        return cls(columns, meta)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write ``path`` (.npz): the columns and a ``metadata`` JSON string."""
        np.savez(path, metadata=np.array(json.dumps(self.metadata)), **cast(dict[str, Any], self.columns))

    @classmethod
    def from_log(cls, path: str | os.PathLike[str], events: list[dict[str, Any]] | None = None) -> Trace:
        """A trace from a run log (JSON Lines, :mod:`driver.records.runlog`), cut short or not.

        Rolls that the log shows begun but without two readings are dropped.
        """
        from .runlog import check_calibration, check_event, read_log

        events = read_log(path) if events is None else events  # ``events``: the log already read
        start = events[0]
        jaw = str(start.get("jaw", "straight:100"))  # logs from before fingers were named: the paper's jaw
        if not jaw.startswith("straight"):
            raise RigError(f"run log {path}: a {jaw} finger's log, not a straight jaw's")
        for k, e in enumerate(events):
            need: dict[str | None, tuple[str, ...]] = {
                "roll": ("roll", "step", "offset"),
                "reading": ("roll", "step", "dv1", "dv2", "phi"),
            }
            missing = [key for key in need.get(e.get("event"), ()) if key not in e]
            if missing:
                raise RigError(f"run log {path}: event {k + 1} ({e.get('event')}) has no {', '.join(missing)}")
            if e.get("event") in need:
                check_event(path, k, e, whole=("roll",), numbers=(*COLUMNS[2:], "offset"))
        rolls = {e["roll"]: e for e in events if e.get("event") == "roll"}
        rows = [e for e in events if e.get("event") == "reading"]
        counts: dict[int, int] = {}
        for e in rows:
            counts[e["roll"]] = counts.get(e["roll"], 0) + 1
        keep = [k for k in sorted(rolls) if counts.get(k, 0) >= 2]
        rows = [e for e in rows if e["roll"] in keep]
        columns = {}
        for name in COLUMNS:
            vals = [e.get(name) for e in rows]
            columns[name] = np.array([math.nan if v is None else v for v in vals], dtype=float)
        columns["roll"] = columns["roll"].astype(np.int64)
        columns["step"] = columns["step"].astype(np.int64)
        meta = {k: v for k, v in start.items() if k not in ("event", "format", "time")}
        cal = [e for e in events if e.get("event") == "calibration"]
        if cal and "calibration" not in meta:
            meta["calibration"] = cal[0]
        if "calibration" in meta:
            found = check_calibration(path, meta["calibration"], ("positions", "ratios", "target"))
            meta["calibration"] = {k: found[k] for k in ("positions", "ratios", "target")}
        meta.update(
            {
                "format": FORMAT,
                "steps": [rolls[k]["step"] for k in keep],
                "offsets": [rolls[k]["offset"] for k in keep],
                "log": str(path),
                "complete": any(e.get("event") == "result" for e in events),
            }
        )
        if "calibration" not in meta:
            raise RigError(f"run log {path}: its start event has no calibration")
        return cls(columns, meta)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Trace:
        """Read a trace written by :meth:`save`, or a run log (``.jsonl``).

        Raises
        ------
        RigError
            Missing or unreadable file, not a rolltouch trace, missing columns.
        """
        if str(path).endswith(".jsonl"):
            return cls.from_log(path)
        meta, columns = read_archive(path, COLUMNS)
        if meta.get("format") != FORMAT:
            jaw = f" (a {meta['jaw']} finger's)" if isinstance(meta.get("jaw"), str) else ""
            raise RigError(f"trace {path}: format {meta.get('format')!r}{jaw}, expected {FORMAT!r}")
        for key in ("steps", "offsets", "calibration"):
            if key not in meta:
                raise RigError(f"trace {path}: its metadata has no {key!r}; not a rolltouch trace")
        return cls(columns, meta)

    # ------------------------------------------------------------ analysis
    @property
    def calibration(self) -> Calibration:
        c = self.metadata["calibration"]
        return Calibration(tuple(c["positions"]), tuple(c["ratios"]), float(c["target"]))

    def estimates(self) -> list[tuple[float, float]]:
        """(L mm, Ω rad) of each roll, recomputed from the readings and the calibration."""
        cal = self.calibration
        out = []
        rolls = self.columns["roll"]
        for k, (step, offset) in enumerate(zip(self.metadata["steps"], self.metadata["offsets"])):
            sel = rolls == k
            if sel.sum() < 2:
                raise RigError(f"roll {k + 1} of the trace has fewer than two readings")
            ratios = self.columns["dv2"][sel] / self.columns["dv1"][sel]
            positions = [cal.position(r) for r in ratios]
            phi = self.columns["phi"][sel]
            out.append((arc_from_jaw_positions(positions, step, offset), float(phi[-1] - phi[0])))
        return out

    @property
    def true_arc(self) -> float:
        """The last reading's true contact arc position (NaN if the trace has no truth)."""
        arc = self.columns["true_arc"]
        return float(arc[-1]) if arc.size else math.nan

    @property
    def true_start_arc(self) -> float:
        arc = self.columns["true_arc"]
        return float(arc[0]) if arc.size else math.nan

    def jaw_positions(self) -> NDArray[np.float64]:
        """Calibrated contact locations on the jaw of every reading, mm."""
        cal = self.calibration
        return np.array([cal.position(a / b) for a, b in zip(self.columns["dv2"], self.columns["dv1"])])

    def step_sequence(self) -> dict[str, NDArray[np.float64]]:
        """The rolls' readings as one step sequence (:func:`driver.jaw.step_sequence`: ``z``, ``turn``,
        ``steps``, ``jaw``), and ``truth``, the true contact at each of its readings (NaN without truth)."""
        rolls, jaw, truth = self.columns["roll"], self.jaw_positions(), self.columns["true_arc"]
        picked = [np.flatnonzero(rolls == k) for k in range(len(self.metadata["steps"]))]
        if not picked or any(sel.size < 2 for sel in picked):
            raise RigError("a roll of the trace has fewer than two readings")
        seq = step_sequence(
            [
                (jaw[sel], self.columns["phi"][sel], float(step), float(offset))
                for sel, step, offset in zip(picked, self.metadata["steps"], self.metadata["offsets"])
            ]
        )
        seq["truth"] = np.concatenate([truth[picked[0][:1]], *(truth[sel[1:]] for sel in picked)]).astype(float)
        return seq
