"""Which part a trace or a run log was made on, and the refusal to score it on another.

A trace's metadata and a run log's first line hold a *part record*: the part's name, its file, its
perimeter (mm) and its fingerprint (:func:`localizer.fingerprint`, a hash of its geometry in mm).
Scoring the readings on another part gives an answer that looks like any other (a kidney's trace on
the trefoil: "95.7% within 0.3 mm", 118 mm from the truth), so :func:`check_same_part` refuses it,
by name, unless the user says the part is the same one (a drawing re-exported with another first
point, a part file cleaned up).
"""

from __future__ import annotations

import math
from typing import Any

from localizer import Boundary, RolltouchError, fingerprint

__all__ = ["PartMismatch", "part_record", "check_same_part", "SAME_PART_FLAG"]

#: The command-line flag that scores readings on a part other than the one they were made on.
SAME_PART_FLAG = "--same-part"
#: Relative difference of perimeters under which a record without a fingerprint (written before
#: fingerprints were) is taken to be of the same part.
PERIMETER_RTOL = 1e-6


class PartMismatch(RolltouchError, ValueError):
    """Readings made on one part were given another to be scored on."""


def part_record(part: Boundary, file: object) -> dict[str, Any]:
    """The part record of ``part``, read from ``file``: name, file, perimeter (mm), fingerprint."""
    return {"name": part.name, "file": str(file), "perimeter": float(part.perimeter), "fingerprint": fingerprint(part)}


def check_same_part(recorded: object, part: Boundary, file: object, source: object, *, same: bool = False) -> None:
    """Refuse to score the readings of ``source`` (a trace or a log) on ``part`` (read from ``file``) when
    its part record ``recorded`` names another part.

    Parameters
    ----------
    recorded : dict or str or None
        The record (:func:`part_record`); a bare name or nothing (older files) is checked as far as it
        goes: a perimeter that differs is refused, a record with neither is let through.
    part : Part or Outline
    file, source : path-like
        For the message.
    same : bool
        The user says ``part`` is the one the readings were made on (:data:`SAME_PART_FLAG`).

    Raises
    ------
    PartMismatch
        The recorded fingerprint, or without one the perimeter, differs from ``part``'s.
    """
    if same or not isinstance(recorded, dict):
        return
    was = f"{recorded.get('name', '?')!r} ({recorded.get('file', '?')})"
    hint = (
        f"give the part it was made on, or {SAME_PART_FLAG} if {file} is that part (e.g. the same drawing "
        "exported again)"
    )
    mark = recorded.get("fingerprint")
    if isinstance(mark, str):
        now = fingerprint(part)
        if now != mark:
            raise PartMismatch(
                f"{source} was made on part {was}, fingerprint {mark}; {file} is another part "
                f"({part.name!r}, fingerprint {now}): {hint}"
            )
        return
    given = recorded.get("perimeter")
    perimeter = float(given) if isinstance(given, (int, float)) else math.nan
    if perimeter > 0 and abs(part.perimeter - perimeter) > PERIMETER_RTOL * perimeter:
        raise PartMismatch(
            f"{source} was made on part {was} of perimeter {perimeter:.6f} mm; {file} is "
            f"{part.perimeter:.6f} mm around: {hint}"
        )
