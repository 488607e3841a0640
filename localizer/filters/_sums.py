"""The grid filter's records of its readings: the running sums of stretches of readings, the readings
as the sums took them, and the cubic B-spline basis they are written in."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from .._types import FloatArray, IntArray


def _quad(s: dict[str, Any], t2: float) -> FloatArray:
    """Each hypothesis' quadratic form of a solve of the marginalisation
    (:meth:`localizer.filters._contact_marginal.ContactMarginal._solve`: the readings' misfit in units of
    the told reading variance, every nuisance and the calibration's scale, of prior variance ``t2``,
    weighed out)."""
    qpp, qpz = s["qpp"], s["qpz"]
    qpr = qpz - qpp
    out: FloatArray = s["qzz"] - 2 * qpz + qpp - t2 * qpr**2 / (1 + t2 * qpp)
    return out


class _Sums(NamedTuple):
    """Sums of some stretches of readings, one per leading index: UᵀU, Uᵀz, zᵀz, and Uᵀp, pᵀp, zᵀp over some
    hypotheses; how many readings. The basis terms over the columns ``cols`` only (those any reading has
    touched)."""

    cols: IntArray
    uu: FloatArray
    uz: FloatArray
    szz: FloatArray
    up: FloatArray
    spp: FloatArray
    szp: FloatArray
    readings: FloatArray


class _Stack(NamedTuple):
    """Some readings, weighted: their basis rows over the columns ``cols`` (k, c), values (k,) and predictions
    at some hypotheses (k, n)."""

    cols: IntArray
    a: FloatArray
    z: FloatArray
    p: FloatArray


def _sums(stack: _Stack, stretches: Sequence[IntArray]) -> _Sums:
    """The sums of each stretch of readings (their positions in ``stack``), along a leading axis."""
    mask = np.zeros((len(stretches), stack.z.size))
    for n, at in enumerate(stretches):
        mask[n, at] = 1.0
    masked = np.swapaxes(mask[:, :, None] * stack.a, 1, 2)  # (stretches, c, k)
    return _Sums(
        cols=stack.cols,
        uu=masked @ stack.a,
        uz=masked @ stack.z,
        szz=mask @ stack.z**2,
        up=masked @ stack.p,
        spp=mask @ stack.p**2,
        szp=mask @ (stack.z[:, None] * stack.p),
        readings=mask.sum(axis=1),
    )


class _Reading(NamedTuple):
    """One reading as the sums took it: basis columns and weighted values, the weighted z, the hypotheses
    live then and their weighted predictions, the reading's own arc (mm) and turn (rad), its segment."""

    cols: IntArray
    vals: FloatArray
    z: float
    live: IntArray
    p: FloatArray
    arc: float
    turn: float
    segment: int
    weight: float
    radius: float  # the reference's radius of curvature then (mm; 0 on a face or a concave stretch)


def _bspline(x: float) -> tuple[IntArray, FloatArray]:
    """(indices, values) of the four uniform cubic B-splines that are nonzero at ``x`` (in knot steps)."""
    i = math.floor(x)
    u = x - i
    vals = np.array([(1 - u) ** 3, 3 * u**3 - 6 * u**2 + 4, -3 * u**3 + 3 * u**2 + 3 * u + 1, u**3]) / 6
    return i + np.arange(4), vals
