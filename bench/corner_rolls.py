"""Rolls that start or end exactly at a corner of a drawing, against a reference from the pieces.

A jaw laid on a convex corner touches it at every angle within the corner's jump. A roll of length L
that starts at corner c with the jaw at angle α (between the angles before and after c) and ends at
e = c + L has rotation Ω = θ(e) − α; one that ends at c has Ω = α − θ(c − L); the same clockwise.
Where the end lands on a corner is decided by rounding (c + L wraps past the first point, a length
is the difference of two corners): the solver must find the start whatever side of the corner the
sum lands, and return nothing that cannot roll.

The reference here does not use the outline's angles: θ is built from each piece's own tangent
(lines, arcs, Béziers, unwrapped over a dense sample of each) and the jumps between pieces, and a
position within :data:`NEAR` mm of a piece's start is at that corner. For every convex corner of a
drawing, lengths from 8% to 60% of the perimeter, the jaw at a fraction of the corner's range, the
four rolls (start or end at the corner, counter-clockwise or clockwise) are asked of
:func:`localizer.feasible_segments`; a start is **missed** when no segment holds it, and a segment is
**infeasible** when its rotation is outside what the reference allows at its two ends::

    python -m bench.corner_rolls parts/bracket.dxf parts/profile.svg bench/parts/cad-heldout*/*.*
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from localizer import Outline, Segment, feasible_segments, load_outline
from localizer.geometry import wrap_angle

__all__ = ["TurningReference", "CornerRoll", "corner_rolls", "check_rolls", "feasible", "holds", "NEAR"]

#: A position this close to a piece's start (mm) is at its corner, for the reference: far looser than the
#: outline's own rule (localizer.AT_CORNER), and independent of it.
NEAR = 1e-7
#: Slack on the rotation, rad, and on a start's place, mm.
TURN_TOL, ARC_TOL = 1e-6, 1e-6


class TurningReference:
    """The outline's unwrapped tangent angle from its pieces' own closed forms (not the outline's).

    Parameters
    ----------
    outline : Outline
    """

    def __init__(self, outline: Outline) -> None:
        self.pieces = outline.pieces
        lengths = np.array([p.length for p in self.pieces])
        self.starts = np.concatenate([[0.0], np.cumsum(lengths)])
        self.perimeter = float(self.starts[-1])
        first, last = [], []
        for p in self.pieces:
            first.append(float(p.tangent_angle(0.0)))
            last.append(float(p.tangent_angle(p.length)))
        self.theta0 = np.empty(len(self.pieces))
        self.jump = np.empty(len(self.pieces))  # at each piece's start
        theta = first[0]
        for i, p in enumerate(self.pieces):
            if i:
                self.jump[i] = wrap_angle(first[i] - last[i - 1])
                theta += self.jump[i]
            self.theta0[i] = theta
            theta += self._within(i, p.length)
        self.jump[0] = wrap_angle(first[0] - last[-1])
        self.total = theta + self.jump[0] - self.theta0[0]

    def _within(self, i: int, u: float) -> float:
        """How far the tangent turns from piece ``i``'s start to ``u`` mm along it, rad."""
        tu = np.unwrap(np.asarray(self.pieces[i].tangent_angle(np.linspace(0.0, u, 129)), dtype=float))
        return float(tu[-1] - tu[0])

    def range(self, sigma: float) -> tuple[float, float]:
        """(θ before, θ after) at the unrolled arc ``sigma`` (mm), rad: equal except at a corner."""
        P = self.perimeter
        lap = math.floor(sigma / P)
        s = sigma - lap * P
        base = 2.0 * math.pi * lap
        for shift, extra in ((0.0, 0.0), (P, 2.0 * math.pi), (-P, -2.0 * math.pi)):
            i = int(np.argmin(np.abs(self.starts[:-1] + shift - s)))
            if abs(self.starts[i] + shift - s) <= NEAR and abs(self.jump[i]) > 1e-9:
                after = self.theta0[i] + base + extra
                return after - self.jump[i], after
        i = min(int(np.searchsorted(self.starts, s, side="right")) - 1, len(self.pieces) - 1)
        t = self.theta0[i] + self._within(i, s - self.starts[i]) + base
        return t, t


@dataclass(frozen=True)
class CornerRoll:
    """One roll at a corner: its ``direction``, true ``start`` (arc, mm), ``length`` (mm), ``turn`` (rad)
    and whether the corner is its ``end`` rather than its start."""

    direction: str
    start: float
    length: float
    turn: float
    end: bool


def corner_rolls(
    outline: Outline, ref: TurningReference, lengths: Iterable[float], fraction: float = 0.3
) -> list[CornerRoll]:
    """The four rolls (start or end at the corner, ccw or cw) at every convex corner of ``outline`` for
    each of ``lengths`` (mm), the jaw at ``fraction`` of the corner's range of angles."""
    rolls = []
    for c in outline.corners:
        if c.angle <= 0:
            continue
        before, after = ref.range(c.arc)
        alpha = before + fraction * (after - before)
        for L in lengths:
            L = float(L)
            rolls += [
                CornerRoll("ccw", c.arc, L, ref.range(c.arc + L)[1] - alpha, False),
                CornerRoll("ccw", c.arc - L, L, alpha - ref.range(c.arc - L)[0], True),
                CornerRoll("cw", c.arc, L, ref.range(c.arc - L)[0] - alpha, False),
                CornerRoll("cw", c.arc + L, L, alpha - ref.range(c.arc + L)[1], True),
            ]
    return rolls


def feasible(ref: TurningReference, seg: Segment) -> bool:
    """Whether the reference lets ``seg`` roll: its rotation within what the jaw's angles at its two ends
    allow (a range at a corner), at both ends of a continuum."""
    L = seg.length
    if seg.direction == "ccw":
        first = seg.start_arc
        starts = [first, first + seg.span] if seg.span else [first]
        turn = seg.turn
    else:  # the same stretch travelled the other way
        first = seg.end_arc
        starts = [first, first - seg.span] if seg.span else [first]
        turn = -seg.turn
    for s in starts:
        s_before, s_after = ref.range(s)
        e_before, e_after = ref.range(s + L)
        lo, hi = sorted((e_before - s_after, e_after - s_before))
        slack = TURN_TOL + seg.residual
        if not lo - slack <= turn <= hi + slack:
            return False
    return True


def holds(segs: Iterable[Segment], start: float, perimeter: float) -> bool:
    """Whether one of ``segs`` starts at ``start`` (mm), or is a continuum of starts over it."""
    for g in segs:
        if abs((g.start_arc - start + perimeter / 2) % perimeter - perimeter / 2) <= ARC_TOL:
            return True
        if g.span:
            x = (start - g.start_arc) % perimeter if g.direction == "ccw" else (g.start_arc - start) % perimeter
            if x <= g.span + ARC_TOL:
                return True
    return False


def check_rolls(outline: Outline, rolls: Iterable[CornerRoll], ref: TurningReference | None = None) -> dict[str, Any]:
    """Ask every roll of ``rolls`` of the solver: counts of rolls, starts ``missed`` and segments
    ``infeasible``, with the first few of each in ``examples``."""
    ref = TurningReference(outline) if ref is None else ref
    P = ref.perimeter
    out: dict[str, Any] = {"rolls": 0, "missed": 0, "segments": 0, "infeasible": 0, "examples": []}
    for r in rolls:
        segs = feasible_segments(outline, r.length, r.turn, direction=r.direction)
        out["rolls"] += 1
        out["segments"] += len(segs)
        if not holds(segs, r.start % P, P):
            out["missed"] += 1
            out["examples"].append({"missed": r.__dict__})
        for g in segs:
            if not feasible(ref, g):
                out["infeasible"] += 1
                out["examples"].append({"infeasible": {"start_arc": g.start_arc, "kind": g.kind, **r.__dict__}})
    out["examples"] = out["examples"][:6]
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.corner_rolls", description=__doc__.split("\n\n")[0])
    ap.add_argument("drawings", nargs="+", help="DXF or SVG files")
    ap.add_argument("--lengths", type=int, default=12, help="lengths per corner, 8%%–60%% of the perimeter")
    ap.add_argument("--json", help="write the counts per drawing here")
    args = ap.parse_args(argv)
    rows = {}
    totals = {"rolls": 0, "missed": 0, "segments": 0, "infeasible": 0}
    for path in args.drawings:
        t = time.perf_counter()
        outline = load_outline(path)
        ref = TurningReference(outline)
        rolls = corner_rolls(outline, ref, np.linspace(0.08, 0.60, args.lengths) * ref.perimeter)
        row = check_rolls(outline, rolls, ref)
        row["seconds"] = round(time.perf_counter() - t, 2)
        rows[path] = row
        for k in totals:
            totals[k] += row[k]
        print(
            f"{path}: {row['rolls']} rolls, missed {row['missed']}, infeasible {row['infeasible']} "
            f"of {row['segments']} segments ({row['seconds']} s)",
            flush=True,
        )
    print(f"all: {totals['rolls']} rolls, missed {totals['missed']}, infeasible {totals['infeasible']}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"totals": totals, "drawings": rows}, fh, indent=1)
    return 1 if totals["missed"] or totals["infeasible"] else 0


if __name__ == "__main__":
    sys.exit(main())
