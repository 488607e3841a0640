"""A feasible boundary stretch: the record every solver returns."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["Segment", "DIRECTIONS", "KINDS"]

#: Rolling directions: the contact moves counter-clockwise or clockwise on the part.
DIRECTIONS = ("ccw", "cw")
#: What a segment is: a transversal root, a near-double root, or a circular stretch.
KINDS = ("simple", "double", "continuum", "corner")


@dataclass(frozen=True)
class Segment:
    """A boundary stretch with the requested arc length and total curvature.

    Attributes
    ----------
    start_arc : float, mm
        Where the contact started, counter-clockwise from the first point, in [0, perimeter).
    end_arc : float, mm
        Where the contact ended, in [0, perimeter). For ``direction="ccw"`` the
        contact moved counter-clockwise from ``start_arc`` to ``end_arc``; for
        ``"cw"`` clockwise.
    start_param, end_param : float
        Spline parameters of the two ends, in [0, N).
    length : float, mm
        Arc length L of the stretch (the query's).
    turn : float, rad
        Signed jaw rotation Ω (counter-clockwise positive), the query's.
    direction : {"ccw", "cw"}
        Direction the contact moved on the part.
    kind : {"simple", "double", "continuum", "corner"}
        ``"simple"``: a transversal root, refined to the solver's tolerance.
        ``"double"``: g touches zero here (two roots closer than the solver's
        resolution, or a tangency); the segment is feasible to within
        ``residual``. ``"continuum"``: every start from ``start_arc`` over ``span`` mm
        in the rolling direction is feasible (a circular stretch, or on an outline two lines or
        equal arcs). ``"corner"`` (outlines): the start or the end is at a corner, where the jaw
        touches at every angle within the corner's jump (:func:`localizer.outline_segments`).
    span : float, mm
        Extent of a continuum, 0 otherwise.
    residual : float, rad
        |Φ(segment) - Ω| at the reported start (exact Φ).
    iterates : tuple of float, mm
        ``method="march"`` only: start arc positions s0, s1, s2, ... of the
        iterations that converged to this segment.
    iterations : int
        ``method="march"`` only: the iteration count.
    """

    start_arc: float
    end_arc: float
    start_param: float
    end_param: float
    length: float
    turn: float
    direction: str = "ccw"
    kind: str = "simple"
    span: float = 0.0
    residual: float = 0.0
    iterates: tuple[float, ...] = ()
    iterations: int = 0

    def as_dict(self) -> dict[str, Any]:
        """Plain-JSON form."""
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        d["iterates"] = list(self.iterates)
        return d
