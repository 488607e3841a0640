"""How large a file the package reads, and how large a table it builds for one part: checked before
reading or building, so that a huge or crafted file, or a part drawn in metres and read as millimetres,
is a clear error and not the machine's memory.

The tables built per part (the filters' grids of starts, the roll chain's states, the jaw's reach,
the solvers' tables, the belief's bins) have a point every so many millimetres of the perimeter, so
their size follows the part's physical size, which no file size bounds: a four-vertex DXF rectangle
of 1 km by 500 m is 15 kB, and its roll chain every 0.01 mm grew past 20 GB. :func:`check_grid` is
asked before each is built, with the size it would have.
"""

from __future__ import annotations

import math
import os
import tomllib
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._errors import PartError

if TYPE_CHECKING:
    from ._boundary import Boundary

__all__ = [
    "MAX_PART_BYTES",
    "MAX_GRID_POINTS",
    "MAX_PAIRWISE_POINTS",
    "MAX_ARRAY_BYTES",
    "check_size",
    "check_grid",
    "read_toml",
    "count_text",
    "bytes_text",
]

#: The largest part file read, bytes: a 90-point part is 3 kB, a detailed DXF drawing a few MB.
MAX_PART_BYTES = 64 * 2**20
#: The most points one per-part grid may have (the filters' starts every 0.02 mm, the roll chain's
#: states every 0.01 mm, the wheel's reach every 0.05 mm, the outline solver's cells every 0.01 mm and
#: its Bézier table every 0.005 mm, the arc table's cells, the belief's bins, the simulated worlds'
#: samples and machining harmonics). The largest generated part (bench/parts/heldout-e/glyph-18,
#: 1151 mm) has 57 552 filter starts and 230 205 points in the simulator's 0.005 mm sample, the
#: largest arc table 34 816 cells. The roll chain is the costliest per point: measured, 12 s a roll and
#: 240 MB at 262 000 states (a 750 × 500 mm rectangle; 930 MB and past 90 s at 3 000 000), so 2¹⁸
#: takes a drawing of up to 2.6 m, a filter grid of 5.2 m (its array, :data:`MAX_ARRAY_BYTES`, takes
#: less).
MAX_GRID_POINTS = 2**18
#: The most pieces (segments, arcs, Béziers) a drawing may have, counted as it is read: an outline keeps
#: an object per piece (and a smooth vertex of a faceted drawing becomes two), measured 580 MB to read
#: 200 000 loose LINEs, 2.6 GB at 1 300 000 vertices (a 60 MB LWPOLYLINE). A curve exported at a chord
#: tolerance of 0.001 mm takes 3 500 segments per 100 mm of a 10 mm radius.
MAX_PIECES = 2**18
#: The most points of a table whose every point is compared with every other (the straight jaw's
#: reach every 0.2 mm, :class:`localizer.Reach`): its time grows as the square, measured 1.3 s at 5 153
#: points (the 1030 mm star, bench/parts/heldout-g/star-12), 15 s and 325 MB at 16 334 (the star
#: scaled to 3.3 m); 27 s at 20 611. 2¹⁴ takes a part of up to 3.3 m.
MAX_PAIRWISE_POINTS = 2**14
#: The most memory of one per-part table's arrays, bytes. The straight jaw's filter keeps an (m × n)
#: array of sums, m = 2·perimeter / 5 mm + 85 basis columns, n = perimeter / 0.02 mm starts: 196 MiB on
#: the 1030 mm star (499 × 51 527), 240 MiB on the 1151 mm glyph; a belief copies the columns the
#: readings touched twice more, so at 512 MiB a filter stays within about 2 GB, on a part of up to
#: 1.7 m. The paper's march at its step of 1e-5 keeps three numbers a cell: measured, 422 MB for 176
#: knots and 1.1 GB at its peak, so up to 223 knots.
MAX_ARRAY_BYTES = 2**29


def check_size(path: str | os.PathLike[str], limit: int, what: str, error: type[Exception] = PartError) -> None:
    """Raise ``error`` naming ``path`` when the file is larger than ``limit`` bytes (or cannot be
    examined).

    Parameters
    ----------
    path : str or Path
    limit : int, bytes
    what : str
        What the file is, for the message ("part file", "trace", ...).
    error : type
        The exception raised (a :class:`RolltouchError` subclass; default :class:`PartError`).
    """
    try:
        size = Path(path).stat().st_size
    except FileNotFoundError:
        raise error(f"{path}: cannot read {what} (no such file)") from None
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    if size > limit:
        raise error(f"{path}: {_size(size)} is more than the {_size(limit)} a {what} may have; is it the right file?")


def _size(n: int) -> str:
    """A file size for a message: MB from 1 MB on, kB below."""
    if n >= 2**20:
        return f"{n // 2**20} MB" if n % 2**20 == 0 else f"{n / 2**20:.1f} MB"
    return f"{n / 2**10:.1f} kB"


def check_grid(
    part: Boundary,
    structure: str,
    spacing: float,
    points: float | None = None,
    *,
    limit: float | None = MAX_GRID_POINTS,
    point_bytes: float = 0.0,
    unit: str = "points",
    per: str = "mm",
    advice: str = "is the part in the right units (mm)?",
) -> None:
    """Raise :class:`PartError` naming ``part`` when the grid that ``structure`` would build for it is
    larger than the limits: asked before building, so that nothing of it is allocated.

    Parameters
    ----------
    part : Part or Outline
        The part the grid is built on (its name and perimeter go in the message).
    structure : str
        What builds the grid, for the message ("filter", "roll chain", ...).
    spacing : float, mm (or ``per``)
        The grid's step.
    points : float, optional
        How many points the grid would have (default: the perimeter over ``spacing``).
    limit : float or None
        The most points it may have (default :data:`MAX_GRID_POINTS`; :data:`MAX_PAIRWISE_POINTS` for a
        table that compares every point with every other; None: only the memory is checked).
    point_bytes : float, bytes
        The memory of the table's arrays per point (the filter's: 8 bytes times its basis columns);
        with it, ``points`` × ``point_bytes`` may be at most :data:`MAX_ARRAY_BYTES`.
    unit : str
        What a point is, for the message ("points", "states", "cells", ...).
    per : str
        The unit of ``spacing``, for the message ("mm"; "of a knot" for a grid in the spline's parameter).
    advice : str
        What to do, ending the message.

    Examples
    --------
    >>> from localizer import outline_from_pieces, Line
    >>> square = outline_from_pieces([Line((0, 0), (1e6, 0)), Line((1e6, 0), (1e6, 1e6)),
    ...                               Line((1e6, 1e6), (0, 1e6)), Line((0, 1e6), (0, 0))], name="sq")
    >>> check_grid(square, "filter", 0.02)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    localizer._errors.PartError: part 'sq' is 4 000 000 mm around: the filter's grid every 0.02 mm would need 2e8 ...
    """
    perimeter = float(part.perimeter)
    count = perimeter / spacing if points is None else float(points)
    need = count * point_bytes
    if limit is not None and not count <= limit:
        too_many = f"{count_text(count)} {unit}, more than the {count_text(limit)} it may have"
    elif not need <= MAX_ARRAY_BYTES:
        too_many = (
            f"{count_text(count)} {unit}, {bytes_text(need)}, more than the {bytes_text(MAX_ARRAY_BYTES)} it may have"
        )
    else:
        return
    whose = f"{structure}'" if structure.endswith("s") else f"{structure}'s"
    raise PartError(
        f"part {part.name!r} is {count_text(perimeter)} mm around: the {whose} grid every {spacing:.3g} {per} "
        f"would need {too_many}; {advice}"
    )


def count_text(x: float) -> str:
    """A count or a length for a message: whole and grouped by thousands below ten million ("262 144"),
    two figures above ("1.5e8"), as given below 10."""
    if not math.isfinite(x):
        return str(x)
    if x < 10:
        return f"{x:.3g}"
    if x < 1e7:
        return f"{round(x):,}".replace(",", " ")
    mantissa, exponent = f"{x:.2g}".split("e")
    return f"{mantissa}e{int(exponent)}"


def bytes_text(n: float) -> str:
    """A memory size for a message: GB from 1 GB on, as :func:`_size` below."""
    return f"{n / 2**30:.1f} GB" if n >= 2**30 else _size(int(n))


def read_toml(path: str | os.PathLike[str], limit: int, what: str, error: type[Exception]) -> dict[str, Any]:
    """A settings file's TOML tables, its size checked first (:func:`check_size`).

    Parameters
    ----------
    path : str or Path
    limit : int, bytes
    what : str
        What the file is, for the messages ("study", "world file", "noise file").
    error : type
        The exception raised on a file too large, unreadable, not text or not TOML, naming the file.
    """
    check_size(path, limit, what, error)
    try:
        with open(path, "rb") as f:
            raw = f.read(limit + 1)  # a pipe or a device says size 0: read no more than the limit
        if len(raw) > limit:
            raise error(f"{what} {path}: more than the {_size(limit)} a {what} may have; is it the right file?")
        return tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise error(f"{what} {path}: not a text file (TOML expected)") from None
    except OSError as exc:
        raise error(f"{what} {path}: cannot read ({exc.strerror or exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{what} {path}: not valid TOML ({exc})") from None
