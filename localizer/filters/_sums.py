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
    """The sums of each stretch of readings (their positions in ``stack``, each counted once), along a
    leading axis."""
    m, c, n = len(stretches), stack.cols.size, stack.p.shape[1]
    member = np.zeros((stack.z.size, m), dtype=bool)
    for k, at in enumerate(stretches):
        member[at, k] = True
    rows = np.flatnonzero(member.any(axis=1))
    # the stretches overlap (by three quarters, most of them): each reading is summed once, in the piece
    # of the readings that the same stretches hold, and each stretch adds up its pieces
    pieces, piece_of = np.unique(member[rows], axis=0, return_inverse=True)
    piece_of = piece_of.ravel()
    uu, uz, szz = np.empty((len(pieces), c, c)), np.empty((len(pieces), c)), np.empty(len(pieces))
    up, spp, szp = np.empty((len(pieces), c, n)), np.empty((len(pieces), n)), np.empty((len(pieces), n))
    for k in range(len(pieces)):
        at = rows[piece_of == k]
        a, z, p = stack.a[at], stack.z[at], stack.p[at]
        uu[k], uz[k], szz[k] = a.T @ a, a.T @ z, z @ z
        up[k], spp[k], szp[k] = a.T @ p, np.einsum("ij,ij->j", p, p), z @ p
    held = pieces.T.astype(float)  # (stretches, pieces)
    return _Sums(
        cols=stack.cols,
        uu=np.tensordot(held, uu, axes=1),
        uz=held @ uz,
        szz=held @ szz,
        up=np.tensordot(held, up, axes=1),
        spp=held @ spp,
        szp=held @ szp,
        readings=member.sum(axis=0).astype(float),
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
