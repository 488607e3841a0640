"""Where a straight jaw can touch a part: the reachable set of (boundary point, place on the jaw).

A straight jaw of length 2h lies along the tangent of the part at its contact P,
the part on the inner side of its edge. With the contact at jaw position d
(measured along the jaw from its centre, the wrist's axis, in the direction of
the part's counter-clockwise tangent), the edge covers w ∈ [−h − d, h − d] along
the tangent from P. The jaw can touch at P with the contact at d when no other
point Q of the part lies on the jaw's side of that edge, deeper than
``clearance``, within that stretch: with w⁺ the nearest such obstruction ahead
along the tangent and w⁻ the nearest behind,

    h − d < w⁺  and  −h − d > w⁻,   i.e.   d ∈ (h − w⁺, −h − w⁻) = (lo, hi).

Every boundary point thus has one open interval of jaw positions (empty where a
straight jaw cannot touch it at all: on a concave stretch its own neighbours are
in the way). Points on the convex hull have the whole jaw; points below it are
reached only with the contact towards one end, when the concavity is wider than
the rest of the jaw. Rolling moves the contact along the part and along the jaw
together, so a roll stays touchable while (σ, d) stays inside the set.

``clearance`` makes the set a little generous: a model point that cuts into the
jaw by less than that does not block it. The real part differs from its model
by the machining error (9 µm RMS at the ``paper`` preset, up to 0.1 mm in
places at four times that), and a start wrongly ruled out can never be found
again, while one wrongly kept only costs a little sharpness.

This one computation serves the filter's prior and roll transitions, the
reading-by-reading check of the contact's place on the jaw, the evidence of a
bridge, the studies' start sampler and the choice of where to calibrate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

from .._errors import QueryError
from .._types import ArrayLike, BoolArray, FloatArray, IntArray
from ..geometry import MAX_PAIRWISE_POINTS, Boundary, Outline, check_grid, per_part
from ._reach_kernels import reach_intervals

__all__ = ["StraightJaw", "DEFAULT_JAW", "Reach", "reach_for", "calibration_arc", "grid_neighbours"]


def grid_neighbours(arc: ArrayLike, h: float, n: int) -> tuple[IntArray, IntArray]:
    """Indices of the two points of a uniform grid of ``n`` points, ``h`` mm apart round the boundary,
    on either side of arc position(s) ``arc`` (mm)."""
    i = np.floor(np.asarray(arc, dtype=float) / h).astype(np.int64)
    return np.mod(i, n), np.mod(i + 1, n)


@dataclass(frozen=True)
class StraightJaw:
    """A straight jaw (the paper's): an edge of ``length`` mm centred on the wrist's axis.

    Attributes
    ----------
    length : float, mm
        The edge's length (paper: 100 mm, calibrated over ±50 mm).
    """

    length: float = 100.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.length) and self.length > 0):
            raise QueryError(f"jaw length={self.length!r} mm must be a positive number")

    @property
    def half(self) -> float:
        """Half the length, mm: the contact's place on the jaw runs over ±half."""
        return 0.5 * self.length

    def __str__(self) -> str:
        return f"straight:{self.length:g}"


#: The paper's jaw: 100 mm, calibrated over ±50 mm.
DEFAULT_JAW = StraightJaw()


class Reach:
    """The reachable set of a part for a straight jaw, on a grid of arc positions.

    Parameters
    ----------
    part : Part or Outline
    jaw : StraightJaw
    spacing : float, mm
        Grid step along the boundary (default 0.2 mm).
    clearance : float, mm
        A model point must cut into the jaw deeper than this to block it (module notes).

    Attributes
    ----------
    sigma : ndarray, shape (n,), mm
        Arc positions of the grid.
    lo, hi : ndarray, shape (n,), mm
        The open interval of jaw positions at which the jaw can touch there (lo ≥ hi: nowhere;
        ±inf where nothing blocks that way).
    lo_sure, hi_sure : ndarray, shape (n,), mm
        Where it surely touches there and nowhere else (no other point within the clearance
        of the edge; inside ``lo, hi``).
    hull_depth : ndarray, shape (n,), mm
        Distance of each point below the part's convex hull (0 on it).

    Examples
    --------
    >>> import numpy as np
    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    >>> disc = part_from_points(np.c_[30 * np.cos(a), 30 * np.sin(a)])
    >>> r = Reach(disc, StraightJaw(100.0))
    >>> bool(r.touchable(10.0, jaw=45.0)), bool(r.full.all())   # convex: the whole jaw everywhere
    (True, True)
    """

    def __init__(
        self, part: Boundary, jaw: StraightJaw = DEFAULT_JAW, *, spacing: float = 0.2, clearance: float = 0.1
    ) -> None:
        if not (math.isfinite(spacing) and spacing > 0):
            raise QueryError(f"spacing={spacing!r} mm must be a positive number")
        if not (math.isfinite(clearance) and clearance >= 0):
            raise QueryError(f"clearance={clearance!r} mm must be ≥ 0")
        p = part.perimeter
        n = max(64, int(math.ceil(p / spacing)))
        # each point's interval looks at every other point: the time grows as the square of n
        check_grid(
            part, "straight jaw's reach table", spacing, n, limit=MAX_PAIRWISE_POINTS, unit="points (each against all)"
        )
        self.part, self.jaw = part, jaw
        self.clearance = float(clearance)
        self.h = p / n
        self.sigma = np.arange(n) * self.h
        pts = np.asarray(part.point_at_arc(self.sigma))
        theta = np.asarray(part.tangent_angle_at_arc(self.sigma))
        tan = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
        eq = ConvexHull(pts).equations  # n·x + d ≤ 0 inside
        depth = np.full(n, -np.inf)
        for j0 in range(0, len(eq), 256):
            e = eq[j0 : j0 + 256]
            depth = np.maximum(depth, (e[:, :2] @ pts.T + e[:, 2:3]).max(axis=0))
        self.hull_depth: FloatArray = np.maximum(-depth, 0.0)
        tiny = 1e-9 * max(1.0, float(np.ptp(pts)))  # rounding of the depth
        self._pts = np.ascontiguousarray(pts, dtype=float)
        lo, hi, lo_sure, hi_sure = self._intervals(np.arange(n), tan, tiny)
        self.lo, self.hi = lo, hi
        self.lo_sure, self.hi_sure = np.maximum(lo, lo_sure), np.minimum(hi, hi_sure)
        self._tiny = tiny
        for arr in (self.sigma, self.lo, self.hi, self.lo_sure, self.hi_sure, self.hull_depth):
            arr.setflags(write=False)

    def _intervals(
        self, points: IntArray, tangents: FloatArray, tiny: float, origins: FloatArray | None = None
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """(lo, hi, lo_sure, hi_sure) for the jaw along unit ``tangents`` touching the grid points ``points``
        (or the points ``origins``, mm, near them), the sure interval not yet intersected with the
        generous one."""
        here = self._pts[points] if origins is None else origins
        return reach_intervals(
            self._pts,
            np.ascontiguousarray(points, dtype=np.int64),
            np.ascontiguousarray(tangents, dtype=float),
            np.ascontiguousarray(here, dtype=float),
            self.clearance,
            self.jaw.half,
            tiny,
        )

    def at_angle(self, arc: ArrayLike, angle: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """(lo, hi, lo_sure, hi_sure), mm: where on the jaw it touches the boundary at ``arc`` (mm) when the
        jaw lies at ``angle`` (rad) there instead of along the tangent: on a convex corner of an
        outline, any angle within its jump."""
        a = np.atleast_1d(np.asarray(arc, dtype=float))
        i = np.mod(np.rint(a / self.h).astype(np.int64), self.sigma.size)
        th = np.broadcast_to(np.asarray(angle, dtype=float), a.shape)
        tan = np.stack([np.cos(th), np.sin(th)], axis=-1)
        origins = np.asarray(self.part.point_at_arc(a), dtype=float).reshape(-1, 2)
        lo, hi, lo_sure, hi_sure = self._intervals(i, tan, self._tiny, origins)
        return lo, hi, np.maximum(lo, lo_sure), np.minimum(hi, hi_sure)

    def interval(self, arc: ArrayLike, sure: bool = False) -> tuple[FloatArray, FloatArray]:
        """(lo, hi) jaw positions, mm, at which the jaw can touch at arc position(s) ``arc`` (mm).

        The generous interval (default) counts as blocking only points deeper than the
        clearance; the ``sure`` one also those within the clearance of the edge (but the
        contact's own stretch): where the jaw surely touches there and nowhere else. Between two
        grid points the interval can change fast (where the obstruction is a far lobe grazing
        the edge, a tangent turned by κ·Δσ moves a point 50 mm away by 50·κ·Δσ), so the
        generous interval is the union of the two neighbouring grid points', and the sure one
        their intersection.
        """
        i, j = grid_neighbours(arc, self.h, self.sigma.size)
        if sure:
            return np.maximum(self.lo_sure[i], self.lo_sure[j]), np.minimum(self.hi_sure[i], self.hi_sure[j])
        return np.minimum(self.lo[i], self.lo[j]), np.maximum(self.hi[i], self.hi[j])

    def touchable(self, arc: ArrayLike, jaw: ArrayLike | None = None, margin: float = 0.0) -> BoolArray:
        """Whether the jaw can touch at ``arc`` (mm) with the contact at jaw position ``jaw`` (mm).

        ``jaw`` None: at some place on the jaw. ``margin`` (mm) widens the interval (a measured
        jaw position carries an error).
        """
        lo, hi = self.interval(arc)
        half = self.jaw.half
        if jaw is None:
            somewhere: BoolArray = np.maximum(lo, -half) - margin < np.minimum(hi, half) + margin
            return somewhere
        d = np.asarray(jaw, dtype=float)
        there: BoolArray = (lo - margin < d) & (d < hi + margin) & (np.abs(d) <= half + margin)
        return there

    def clear(self, arc: ArrayLike, jaw: ArrayLike, margin: float = 0.0) -> BoolArray:
        """Whether the jaw surely touches at ``arc`` (mm) with the contact at ``jaw`` (mm), with ``margin`` mm
        to spare on both sides (a roll there does not bridge)."""
        lo, hi = self.interval(arc, sure=True)
        d = np.asarray(jaw, dtype=float)
        surely: BoolArray = (lo + margin < d) & (d < hi - margin) & (np.abs(d) <= self.jaw.half - margin)
        return surely

    @property
    def full(self) -> BoolArray:
        """Points the jaw surely touches at every place along it (as the calibration's taps need)."""
        whole_jaw: BoolArray = (self.lo_sure <= -self.jaw.half) & (self.hi_sure >= self.jaw.half)
        return whole_jaw


def reach_for(part: Boundary, jaw: StraightJaw = DEFAULT_JAW, spacing: float = 0.2, clearance: float = 0.1) -> Reach:
    """The ``part``'s :class:`Reach` for ``jaw`` (grid ``spacing`` mm, ``clearance`` mm), built once per part and
    settings (shared, read-only)."""
    return per_part(
        "reach",
        part,
        (jaw, float(spacing), float(clearance)),
        lambda: Reach(part, jaw, spacing=spacing, clearance=clearance),
    )


#: How far along a drawing's outline, each way, the calibration point's clearance is judged, mm.
CALIBRATION_WINDOW = 10.0


def calibration_arc(part: Boundary, jaw: StraightJaw = DEFAULT_JAW) -> float:
    """Where to calibrate on ``part``: the most curved point the ``jaw`` touches at every place along it, mm.

    The calibration taps one object point with the contact at 11 places from one end of
    the jaw to the other (paper §III-B), so the point must be touchable with the whole jaw;
    the most curved such point pins the contact best. A part without one (every point
    blocked somewhere along the jaw) raises :class:`QueryError`.
    """
    r = reach_for(part, jaw)
    ok = np.flatnonzero(r.full)
    if ok.size == 0:
        raise QueryError(
            f"no point of {part.name} can be touched along the whole {jaw} jaw: calibrate on another object"
        )
    sigma = r.sigma[ok]
    kappa = np.asarray(part.curvature_at_arc(sigma))
    if not isinstance(part, Outline):
        return float(sigma[int(np.argmax(kappa))])
    # On a drawing the most curved point is a small fillet between faces that turn little, and a jaw
    # laid along its tangent lies nearly flush on the faces beside it: pressed there with the contact
    # near the jaw's end, it touches the face too, and the calibration comes out non-monotone. So: a
    # point of a curved piece (a line or a corner has no one tangent to lay the jaw along) where the part
    # turns away from the jaw most on its nearer side within CALIBRATION_WINDOW mm, corners' jumps included.
    w = CALIBRATION_WINDOW
    theta = part.tangent_angle_at_arc
    ahead = theta(sigma + w, side="after") - theta(sigma)
    behind = theta(sigma) - theta(sigma - w, side="before")
    score = np.where(kappa > 0, np.minimum(ahead, behind), -np.inf)
    if not np.isfinite(score).any():
        raise QueryError(
            f"no curved point of {part.name} can be touched along the whole {jaw} jaw: calibrate on another object"
        )
    return float(sigma[int(np.argmax(score))])
