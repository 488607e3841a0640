"""What a sequential filter believes about the present contact: the records it reports."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.special import ndtr

from .._types import FloatArray, IntArray
from ..geometry import check_grid

__all__ = [
    "Belief",
    "Mode",
    "find_modes",
    "belief_flags",
    "flat_top",
    "most_probable",
    "mass_within",
    "within",
    "FLAT_TOP",
]


@dataclass(frozen=True)
class Mode:
    """One separate mode of the belief over the present contact.

    Attributes
    ----------
    arc : float, mm
        Most probable present contact in the mode.
    mass : float
        Probability of the mode.
    start_arc : float, mm
        The corresponding start of the rolling.
    """

    arc: float
    mass: float
    start_arc: float


@dataclass(frozen=True)
class Belief:
    """What the filter believes about the present contact.

    Attributes
    ----------
    map_arc : float, mm
        The estimate of the present contact: the most probable one (the wheel's filter: the middle of a
        flat top, :func:`flat_top`).
    mass : float
        Probability that the contact is within ``radius`` of ``map_arc``.
    radius : float, mm
    modes : tuple of Mode
        Separate modes, most probable first.
    ambiguous : bool
        More than one mode holds at least ``mode_floor`` of the probability and the
        first does not reach the confidence: the data cannot tell them apart (yet).
    informative : bool
        False when the posterior is as flat as the prior (e.g. on a circle).
    steps : int
        Updates so far.
    consistent : bool
        False when no hypothesis fits the readings even under a generous error model (the wheel's
        filter: a contact that jammed, a model that is not the part); ``mass`` is then 0.
    mismatch : (float, float) or None
        Where on the model (arc positions, mm, counter-clockwise from the first to the second) the
        readings stopped fitting the part under the most probable start: a burr, a dent, debris, a
        part that is not its model. None while they fit; NaN ends where a mismatch was found but not
        where. A belief with a mismatch is never sure.
    mismatch_mm : float, mm
        How much the part seems to differ there: the readings' RMS distance from what the model
        predicts over that stretch, or the jump the jaw made where the model has none (NaN: unknown).
    """

    map_arc: float
    mass: float
    radius: float
    modes: tuple[Mode, ...]
    ambiguous: bool
    informative: bool
    steps: int
    consistent: bool = True
    mismatch: tuple[float, float] | None = None
    mismatch_mm: float = math.nan

    def sure(self, confidence: float) -> bool:
        """Whether the belief may be acted on at ``confidence``: its mass reaches it, something fits, and
        no stretch of the readings contradicts the model."""
        return self.mass >= confidence and self.consistent and self.mismatch is None


def find_modes(part: Any, w: FloatArray, present: FloatArray, starts: FloatArray, radius: float) -> list[Mode]:
    """Connected groups of probable present contacts, binned at ``radius`` mm, most probable first.

    Parameters
    ----------
    part : Part or Outline
    w : ndarray
        Each hypothesis' probability.
    present, starts : ndarray, mm
        Each hypothesis' present contact and start.
    radius : float, mm
    """
    nb = max(8, int(part.perimeter / radius))
    check_grid(part, "belief", radius, nb, unit="bins", advice=f"is radius={radius!r} mm meant?")
    b = np.minimum((present / part.perimeter * nb).astype(int), nb - 1)
    mass = np.bincount(b, weights=w, minlength=nb)
    live = mass > 1e-4 * mass.max()
    if live.all():
        labels = np.zeros(nb, dtype=int)
    else:
        # label runs of live bins around the circle, counted from a dead bin so that none wraps
        start = int(np.flatnonzero(~live)[0])
        order = (np.arange(nb) + start) % nb
        run = live[order]
        first = run & ~np.r_[False, run[:-1]]
        labels = np.full(nb, -1)
        labels[order] = np.where(run, np.cumsum(first) - 1, -1)
    held = labels[b]  # each hypothesis' mode
    out: list[Mode] = []
    for lab in range(int(labels.max()) + 1):
        sel = held == lab
        if not sel.any():
            continue
        top = int(np.argmax(np.where(sel, w, -1.0)))
        out.append(Mode(arc=float(present[top]), mass=float(mass[labels == lab].sum()), start_arc=float(starts[top])))
    out.sort(key=lambda m: -m.mass)
    return out


def most_probable(w: FloatArray, k: int) -> IntArray:
    """The indices of the ``k`` largest of the non-negative weights ``w`` (all of them if fewer), largest
    first, equal weights by index: the same on every machine (numpy's argsort orders equal values as the
    CPU's sort does). A partition of the positive weights finds the k-th: numpy's partition of a grid
    mostly of zeros (the pruned starts) takes as long as a sort."""
    n = int(w.size)
    k = min(int(k), n)
    if k <= 0:
        return np.zeros(0, dtype=np.int64)
    positive = w[w > 0]
    kth = np.partition(positive, positive.size - k)[positive.size - k] if positive.size >= k else 0.0
    above = np.flatnonzero(w > kth)
    chosen = np.concatenate([above, np.flatnonzero(w == kth)[: k - above.size]])
    out: IntArray = chosen[np.lexsort((chosen, -w[chosen]))]
    return out


def mass_within(part: Any, arcs: FloatArray, weights: FloatArray, at: float, radius: float) -> float:
    """The weight of the points ``arcs`` (mm along ``part``, each with its weight ``weights``) that lie within
    ``radius`` mm of arc ``at``, either way round the part.

    Examples
    --------
    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    >>> circle = part_from_points(np.c_[30 * np.cos(a), 30 * np.sin(a)])
    >>> arcs = np.array([1.0, 2.0, circle.perimeter - 0.5, 50.0])
    >>> round(mass_within(circle, arcs, np.array([0.1, 0.2, 0.3, 0.4]), 0.5, 1.5), 6)
    0.6
    """
    near = np.abs(np.asarray(part.arc_offset(arcs, at))) <= radius
    return float(np.asarray(weights)[near].sum())


def within(part: Any, arcs: FloatArray, sd: FloatArray, at: float, radius: float) -> FloatArray:
    """Probability that a contact N(``arcs``, ``sd``²) along the ``part`` (mm) is within ``radius`` mm of arc
    ``at``, each point's (1 or 0 where its ``sd`` is 0)."""
    off = np.asarray(part.arc_offset(arcs, at))
    spread = np.where(sd > 0, sd, 1.0)
    inside: FloatArray = np.where(
        sd > 0, ndtr((radius - off) / spread) - ndtr((-radius - off) / spread), np.abs(off) <= radius
    )
    return inside


#: Weights within this fraction of the most probable one are as probable: a flat top, whose middle is
#: the estimate (:func:`flat_top`).
FLAT_TOP = 1e-3


def flat_top(w: FloatArray) -> int:
    """The index of the most probable point of a circular grid of non-negative weights ``w`` or, where
    the weights around it are as high within :data:`FLAT_TOP` (the readings place the contact anywhere
    along a stretch, as between two jumps of a wheel), the middle of that flat top: not its first point,
    which would be as far from the truth as the top is long. Where the largest weight is not positive
    and finite, its index (no top to speak of)."""
    n = w.size
    i = int(np.argmax(w))
    if not (math.isfinite(float(w[i])) and w[i] > 0):
        return i
    floor = float(w[i]) * (1.0 - FLAT_TOP)
    left = right = 0
    while left < n - 1 and w[(i - left - 1) % n] >= floor:
        left += 1
    while right < n - 1 - left and w[(i + right + 1) % n] >= floor:
        right += 1
    return (i + (right - left) // 2) % n


def belief_flags(
    w: FloatArray, prior: FloatArray, modes: list[Mode], mode_floor: float, confidence: float
) -> tuple[bool, bool]:
    """(informative, ambiguous) of a posterior ``w`` over hypotheses with ``prior`` (each sums to 1):
    informative when it gained more than 0.05 nats on the prior (KL(posterior ‖ prior); a flat
    posterior gains about 0), ambiguous when informative and two or more of its ``modes`` hold
    ``mode_floor`` each while the first does not reach ``confidence``."""
    nz = w > 0
    informative = float(np.sum(w[nz] * np.log(w[nz] / prior[nz]))) > 0.05
    strong = [m for m in modes if m.mass >= mode_floor]
    return informative, informative and len(strong) > 1 and modes[0].mass < confidence
