"""Reading a part from a file: a point file becomes a spline :class:`Part`, a CAD drawing an
:class:`Outline`."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path

from .._errors import PartError
from ._cad import CAD_SUFFIXES, load_outline
from ._limits import MAX_PART_BYTES, check_size
from ._outline import Outline
from ._part import Part, part_from_points

__all__ = ["load_part"]


def load_part(path: str | os.PathLike[str], *, layer: str | None = None, element: str | None = None) -> Part | Outline:
    """Read and validate a part file.

    Parameters
    ----------
    path : str or Path
        A JSON file ``{"name": str, "units": "mm", "points": [[x, y], ...]}``
        or a CSV file of ``x,y`` rows in mm (a header row and ``#`` comments
        are allowed): the closed C2 spline through the points. Or a CAD drawing,
        ``.dxf`` or ``.svg``: its outline of exact pieces and corners
        (:func:`localizer.load_outline`).
    layer, element : str, optional
        The DXF layer or SVG element id to read the outline from (CAD files only).

    Returns
    -------
    Part or Outline

    Raises
    ------
    PartError
        The file is missing or unreadable, or the part is invalid (see
        :func:`part_from_points`).
    """
    path = Path(path)
    src = str(path)
    check_size(path, MAX_PART_BYTES, "part file")
    if path.suffix.lower() in CAD_SUFFIXES:
        return load_outline(path, layer=layer, element=element)
    for name, value in (("layer", layer), ("element", element)):
        if value is not None:
            raise PartError(f"{src}: {name}={value!r} names a part of a CAD drawing; this is a point file")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise PartError(f"{src}: not a text file (a part file is JSON or CSV text, or .dxf/.svg)") from None
    except OSError as exc:
        raise PartError(f"{src}: cannot read part file ({exc.strerror or exc})") from None
    if path.suffix.lower() == ".csv":
        rows = []
        lines = (line for line in text.splitlines() if not line.lstrip().startswith("#"))
        try:
            for k, row in enumerate(csv.reader(lines)):
                if not row or all(not c.strip() for c in row):
                    continue
                try:
                    rows.append([float(row[0]), float(row[1])])
                except (ValueError, IndexError):
                    if rows or k > 0:
                        shown = repr(row)[:80]
                        raise PartError(f"{src}: row {k + 1} {shown} is not two numbers x,y") from None
        except csv.Error as exc:
            raise PartError(f"{src}: not a CSV of x,y rows ({exc})") from None
        return part_from_points(rows, name=path.stem, source=src)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise PartError(f"{src}: not valid JSON ({exc.msg} at line {exc.lineno})") from None
    except RecursionError:
        raise PartError(f"{src}: JSON nested too deeply to be a part file") from None
    if not isinstance(data, dict) or "points" not in data:
        raise PartError(f'{src}: a part file is a JSON object with "name", "units" and "points"')
    units = data.get("units", "mm")
    return part_from_points(data["points"], name=str(data.get("name", path.stem)), units=units, source=src)
