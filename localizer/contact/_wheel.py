"""A wheel finger (the paper's §V) and where it reaches; the finger named by a spec string.

A disc of radius r on an axle fixed to the wrist rolls on the part from outside. Laid at a boundary
point P with tangent angle θ, its axle is at c = P + r·n, n = (sin θ, −cos θ) the outward normal of
the counter-clockwise boundary. It touches there when no other point of the part comes nearer to c
than r: the straight jaw's definition (the finger placed tangent at P does not cut into the part
elsewhere, :mod:`localizer.contact._reach`) for a finger that is the same all round, so one yes or no per
point instead of an interval of places. On a concave stretch this needs the part's concave radius of
curvature to be at least r (1 + r·κ ≥ 0, checked on its own: a tighter arc comes nearer to the axle
only to second order, by less than the clearance below), and the pocket to be wide enough for the disc.

As for the straight jaw, ``clearance`` makes the set a little generous (a model point nearer than
r by less than that does not block: the machined part differs from its model), and the *sure* set
is the points where nothing but the contact's own stretch comes within r + clearance.
docs/wheel.md has the physics.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .._errors import QueryError
from .._types import ArrayLike, BoolArray, FloatArray
from ..geometry import Boundary, check_grid, per_part
from ._reach import StraightJaw, grid_neighbours

__all__ = ["WheelJaw", "WheelReach", "wheel_reach_for", "parse_jaw", "Finger"]


@dataclass(frozen=True)
class WheelJaw:
    """A wheel finger: a disc of ``radius`` mm on an axle fixed to the wrist, with an encoder on the axle.

    Attributes
    ----------
    radius : float, mm
    """

    radius: float = 5.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise QueryError(f"wheel radius={self.radius!r} mm must be a positive number")

    def __str__(self) -> str:
        return f"wheel:{self.radius:g}"


#: Either finger.
Finger = StraightJaw | WheelJaw


def parse_jaw(spec: str) -> Finger:
    """The finger named by ``spec``: ``"straight:LENGTH"`` or ``"wheel:RADIUS"`` (mm).

    Examples
    --------
    >>> parse_jaw("wheel:5"), parse_jaw("straight:100")
    (WheelJaw(radius=5.0), StraightJaw(length=100.0))
    >>> str(parse_jaw(" Wheel:2.5 "))
    'wheel:2.5'
    """
    kind, sep, size = str(spec).strip().lower().partition(":")
    if not sep or kind not in ("straight", "wheel"):
        raise QueryError(f"jaw {spec!r}: give straight:LENGTH or wheel:RADIUS in mm, e.g. straight:100 or wheel:5")
    try:
        value = float(size)
    except ValueError:
        raise QueryError(f"jaw {spec!r}: {size!r} is not a number of mm (e.g. {kind}:5)") from None
    return StraightJaw(value) if kind == "straight" else WheelJaw(value)


class WheelReach:
    """Where a wheel touches a part, on a grid of arc positions.

    Parameters
    ----------
    part : Part or Outline
    wheel : WheelJaw
    spacing : float, mm
        Grid step along the boundary (default 0.05 mm); the part is sampled at the same step.
    clearance : float, mm
        A model point must come nearer to the axle than r by more than this to block it.

    Attributes
    ----------
    sigma : ndarray, shape (n,), mm
    reached, sure : ndarray of bool, shape (n,)
        The wheel touches there (generous, with the clearance); it surely does, nothing but the
        contact's own stretch within r + clearance of the axle.
    axle : ndarray, shape (n, 2), mm
        Where the axle is when the wheel touches there.

    Examples
    --------
    A disc of 30 mm: a wheel of 5 mm reaches all of it.

    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    >>> disc = part_from_points(np.c_[30 * np.cos(a), 30 * np.sin(a)])
    >>> bool(WheelReach(disc, WheelJaw(5.0)).sure.all())
    True
    """

    def __init__(self, part: Boundary, wheel: WheelJaw, *, spacing: float = 0.05, clearance: float = 0.1) -> None:
        if not (math.isfinite(spacing) and spacing > 0):
            raise QueryError(f"spacing={spacing!r} mm must be a positive number")
        if not (math.isfinite(clearance) and clearance >= 0):
            raise QueryError(f"clearance={clearance!r} mm must be ≥ 0")
        p = part.perimeter
        # the table resolves a wheel of at least an eighth of its step: the sagitta of a step's chord seen
        # from the axle, h²/8r, is then at most a step, and each point's axle has a few sample points near
        # it. A smaller wheel would need a finer table: with the step's, every axle has the whole part
        # within that slack (wheel:1e-9 listed every point for every point: 0.9 GB on parts/ellipse.json, 207 mm)
        step = min(spacing, 8.0 * wheel.radius)
        check_grid(
            part,
            f"{wheel} reach table",
            step,
            advice=f"is the radius in mm? (a wheel of at least {spacing / 8.0:g} mm needs no more than the "
            f"table's {spacing:g} mm step)"
            if step < spacing
            else "is the part in the right units (mm)?",
        )
        self.part, self.wheel, self.clearance = part, wheel, float(clearance)
        n = max(64, int(math.ceil(p / spacing)))
        self.h = p / n
        self.sigma = np.arange(n) * self.h
        pts = np.asarray(part.point_at_arc(self.sigma), dtype=float)
        theta = np.asarray(part.tangent_angle_at_arc(self.sigma), dtype=float)
        r = wheel.radius
        self.axle = pts + r * np.stack([np.sin(theta), -np.cos(theta)], axis=-1)
        tree = cKDTree(pts)
        # a blocking point between two samples lies nearer than the samples by at most the chord's
        # sagitta seen from the axle, h²/(8r): the sample's own slack
        slack = self.h**2 / (8.0 * r)
        nearest, _ = tree.query(self.axle)
        # the disc fits the curve where it touches (1 + rκ ≥ 0): a concave arc tighter than the disc
        # comes nearer to the axle only to second order, by less than the clearance
        kappa = np.asarray(part.curvature_at_arc(self.sigma), dtype=float)
        self.reached: BoolArray = (nearest >= r - self.clearance - slack) & (1.0 + r * kappa >= 0.0)
        self.sure: BoolArray = self.reached & self._only_own_stretch(tree, n, r + self.clearance + slack)
        for arr in (self.sigma, self.axle, self.reached, self.sure):
            arr.setflags(write=False)

    def _only_own_stretch(self, tree: cKDTree, n: int, within: float) -> BoolArray:
        """Whether the sample points within ``within`` mm of each reached point's axle form one run
        around the contact (False where not reached)."""
        out = np.zeros(n, dtype=bool)
        todo = np.flatnonzero(self.reached)
        near = tree.query_ball_point(self.axle[todo], within)
        sizes = np.fromiter((len(x) for x in near), dtype=np.int64, count=len(near))
        flat = np.fromiter(itertools.chain.from_iterable(near), dtype=np.int64, count=int(sizes.sum()))
        off = (flat - np.repeat(todo, sizes) + n // 2) % n - n // 2
        # one run of consecutive samples that holds the contact (offset 0): the samples are distinct, so
        # they are a run when their span is their count
        held = sizes > 0
        first = (np.cumsum(sizes) - sizes)[held]
        lo, hi = np.minimum.reduceat(off, first), np.maximum.reduceat(off, first)
        out[todo[held]] = (lo <= 0) & (hi >= 0) & (hi - lo + 1 == sizes[held])
        return out

    def touchable(self, arc: ArrayLike) -> BoolArray:
        """Whether the wheel can touch at arc position(s) ``arc`` (mm): either neighbouring grid point."""
        i, j = grid_neighbours(arc, self.h, self.sigma.size)
        out: BoolArray = self.reached[i] | self.reached[j]
        return out

    def clear(self, arc: ArrayLike) -> BoolArray:
        """Whether the wheel surely touches at ``arc`` (mm) and nowhere else: both neighbouring grid points."""
        i, j = grid_neighbours(arc, self.h, self.sigma.size)
        out: BoolArray = self.sure[i] & self.sure[j]
        return out

    @property
    def fraction(self) -> float:
        """The fraction of the boundary the wheel reaches."""
        return float(self.reached.mean())

    def axle_at(self, arc: ArrayLike) -> FloatArray:
        """Where the axle is (mm) when the wheel touches at ``arc`` (mm): the offset curve's point."""
        a = np.asarray(arc, dtype=float)
        theta = np.asarray(self.part.tangent_angle_at_arc(a), dtype=float)
        normal = np.stack([np.sin(theta), -np.cos(theta)], axis=-1)
        out: FloatArray = np.asarray(self.part.point_at_arc(a), dtype=float) + self.wheel.radius * normal
        return out


def wheel_reach_for(part: Boundary, wheel: WheelJaw, spacing: float = 0.05, clearance: float = 0.1) -> WheelReach:
    """The ``part``'s :class:`WheelReach` for ``wheel``, built once per part and settings (shared, read-only).

    ``spacing`` (mm) and ``clearance`` (mm) as for :class:`WheelReach`."""
    return per_part(
        "wheel_reach",
        part,
        (wheel, float(spacing), float(clearance)),
        lambda: WheelReach(part, wheel, spacing=spacing, clearance=clearance),
    )
