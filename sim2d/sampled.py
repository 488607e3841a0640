"""The real part as a dense sample: each point of its boundary tagged with the model's arc position it
stands for.

A machined spline keeps the model's knots (:func:`sim2d.machining.machined_part`), so a contact's spline
parameter names the model's arc. A drawing as machined, a part with a burr or a dent, a part scaled
against its model or a scanned part of its own are not splines of the model's knots: the worlds take
them as this dense sample, and a contact on it reports the tagged model arc
(:func:`sim2d.quasistatic.outline_touch`, :class:`sim2d.wheel_world.WheelWorld`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from localizer import Outline, Part, check_grid
from localizer.geometry import per_part

__all__ = ["SampledPart", "SAMPLE_SPACING", "BLOCK", "model_sample", "model_params", "polygon_vertices"]

#: Points in a run of :attr:`SampledPart.blocks`.
BLOCK = 64
#: Arc between the points of a sampled part, mm: the kinematic world takes the deepest of them as the
#: contact, so this bounds the contact's place error (a quarter of a µm of depth on a 10 mm radius).
SAMPLE_SPACING = 0.005


@dataclass(frozen=True, eq=False)
class SampledPart:
    """The real boundary as dense points, each with the model's arc position it stands for.

    Attributes
    ----------
    model : Part or Outline
        The part's model: what the localizer is given, and whose arc positions the truth reports.
    arcs : ndarray, shape (n,), mm
        The model's arc position of each point, increasing, in [0, perimeter) (every corner's included).
    xy : ndarray, shape (n, 2), mm
        The real boundary's points, counter-clockwise.
    label : str
        How it differs from the model, for its name ("machined", "a 0.3 mm bump ...").
    altered : bool
        Whether it differs from the model by more than its machining (a defect, a scale, a part of its
        own): a polygon of it must then follow the sample, not the model's pieces.
    """

    model: Part | Outline
    arcs: np.ndarray
    xy: np.ndarray
    label: str = "machined"
    altered: bool = False

    @property
    def name(self) -> str:
        return f"{self.model.name} ({self.label})"

    @property
    def perimeter(self) -> float:
        """The model's perimeter, mm: the arcs' period."""
        return float(self.model.perimeter)

    @cached_property
    def blocks(self) -> tuple[np.ndarray, np.ndarray]:
        """The points in runs of :data:`BLOCK` in order: each run's middle point's index, and the farthest any
        point of the run lies from it (mm). What lies under a jaw is sought run by run
        (:func:`sim2d.quasistatic.outline_touch`)."""
        n = self.xy.shape[0]
        starts = np.arange(0, n, BLOCK)
        middle = np.minimum(starts + BLOCK // 2, n - 1)
        run = np.repeat(np.arange(starts.size), np.diff(np.append(starts, n)))
        far = np.hypot(*(self.xy - self.xy[middle[run]]).T)
        radius = np.maximum.reduceat(far, starts)
        return middle, radius


def _read_only(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """The arrays, made read-only: they are kept with the model and shared by every world made of it."""
    for a in arrays:
        a.setflags(write=False)
    return arrays


def model_sample(model: Part | Outline, spacing: float = SAMPLE_SPACING) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(arcs mm, points mm, outward unit normals) of the ``model`` every ``spacing`` mm of arc, with every
    corner's arc among them (the normal there is the one after the corner). Read-only, kept with the model
    (:func:`localizer.geometry.per_part`): every world made of it (each of a trial's rigs, each trial of a
    study) samples it alike."""
    P = float(model.perimeter)
    check_grid(model, "simulated part", spacing, P / spacing + len(model.corners))

    def make() -> tuple[np.ndarray, ...]:
        arcs = np.unique(np.concatenate([np.arange(0.0, P, spacing), [c.arc for c in model.corners]]))
        xy = np.asarray(model.point_at_arc(arcs), dtype=float)
        theta = np.asarray(model.tangent_angle_at_arc(arcs), dtype=float)
        return _read_only(arcs, xy, np.stack([np.sin(theta), -np.cos(theta)], axis=-1))

    arcs, xy, normal = per_part("world sample", model, float(spacing), make)
    return arcs, xy, normal


def model_params(model: Part, spacing: float = SAMPLE_SPACING) -> np.ndarray:
    """The spline parameters of a spline ``model`` at the arcs of :func:`model_sample` (read-only, kept with
    the model)."""
    arcs = model_sample(model, spacing)[0]
    (params,) = per_part(
        "world sample params",
        model,
        float(spacing),
        lambda: _read_only(np.asarray(model.param_at_arc(arcs), dtype=float)),
    )
    return params


def polygon_vertices(xy: np.ndarray, tolerance: float, keep: np.ndarray | None = None) -> np.ndarray:
    """Indices of a closed sample's points whose polygon stays within about ``tolerance`` mm of it.

    The chord h allowed where the sample turns at curvature κ is √(8·tolerance/κ) (its sagitta κh²/8);
    κ is taken as the largest turning per length within a millimetre, so that a short sharp turn (a
    burr's crest) is not skipped by a long chord. ``keep``
    (indices) are vertices in any case (an outline's corners).

    Parameters
    ----------
    xy : ndarray, shape (n, 2), mm
        The points, in order, the last joined to the first.
    tolerance : float, mm
    keep : ndarray of int, optional
    """
    from scipy.ndimage import maximum_filter1d

    n = xy.shape[0]
    step = np.diff(np.vstack([xy, xy[:1]]), axis=0)
    length = np.hypot(step[:, 0], step[:, 1])
    heading = np.arctan2(step[:, 1], step[:, 0])
    turn = np.abs((heading - np.roll(heading, 1) + math.pi) % (2 * math.pi) - math.pi)  # at each point
    local = 0.5 * (length + np.roll(length, 1))
    kappa = turn / np.maximum(local, 1e-12)
    # over ±1 mm: longer than the chord of any curved stretch at this tolerance (0.9 mm at a radius of a
    # metre), so that a chord about to span a sharp spot is shortened before it
    window = int(min(2 * math.ceil(1.0 / float(np.mean(length))) + 1, n // 4 * 2 + 1))
    kappa = maximum_filter1d(kappa, size=max(window, 1), mode="wrap")
    density = np.sqrt(kappa / (8.0 * tolerance))  # chords per mm
    count = np.cumsum(density * length)
    picks = np.flatnonzero(np.diff(np.floor(count), prepend=-1.0) > 0)
    extra = [np.array([0])] if keep is None else [np.array([0]), np.asarray(keep, dtype=np.int64)]
    out: np.ndarray = np.unique(np.concatenate([picks, *extra]))
    return out
