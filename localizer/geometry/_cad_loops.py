"""Loose pieces chained into closed loops, and the bound on how many pieces a drawing may have: what
the DXF and SVG readers share."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .._errors import PartError
from ._limits import MAX_PIECES, count_text
from ._outline import JOIN_TOL
from ._pieces import Piece

__all__ = ["check_pieces", "chain_loops"]


def check_pieces(path: Path, count: int) -> None:
    """Refuse a drawing of more than :data:`MAX_PIECES` pieces, before building the one past it."""
    if count > MAX_PIECES:
        raise PartError(
            f"{path}: more than {count_text(MAX_PIECES)} pieces (line segments, arcs, curves) in the drawing, more "
            "than an outline may have: export its curves with a coarser chord tolerance, or as arcs and splines"
        )


def chain_loops(pieces: list[Piece], source: str, ignored: list[str]) -> list[list[Piece]]:
    """Loose pieces chained end to start (reversing pieces where needed) into closed loops; what
    does not close is reported in ``ignored``.

    A loop starts at the first unused piece; at each end the next piece is the first unused one in
    the file's order with an end within :data:`JOIN_TOL` (its start preferred), found among the
    ends' neighbours (scipy's k-d tree) so that 200 000 loose LINEs chain in about a second.
    """
    from scipy.spatial import cKDTree

    n = len(pieces)
    if n == 0:
        return []
    ends = np.array([p.start for p in pieces] + [p.end for p in pieces])  # start of i: i; end of i: n + i
    near = cKDTree(ends).query_ball_point(ends, JOIN_TOL)
    used = np.zeros(n, dtype=bool)
    loops: list[list[Piece]] = []
    first = 0
    while True:
        while first < n and used[first]:
            first += 1
        if first == n:
            return loops
        used[first] = True
        loop, at = [pieces[first]], n + first  # the endpoint the loop has reached
        while math.dist(loop[-1].end, loop[0].start) > JOIN_TOL:
            # the first unused piece with an end here; its start before its end
            options = sorted((e % n, e >= n) for e in near[at] if not used[e % n])
            if not options:
                ignored.append(f"an open chain of {len(loop)} piece(s) from {loop[0].start} to {loop[-1].end}")
                loop = []
                break
            i, reverse = options[0]
            used[i] = True
            loop.append(pieces[i].reversed() if reverse else pieces[i])
            at = i if reverse else n + i
        if loop:
            loops.append(loop)
