"""A model's boundary moved along its normal, its pieces joined at the corners as a real part's are.

Machining error, a burr or a dent moves each point of the model along the model's outward normal. On a
smooth stretch that is the whole story; at a drawing's corner the normal jumps, and moving the two
pieces' ends along their own normals either leaves a gap between them or makes them overlap:

- they **part** where the offset is outward at a convex corner (or inward at a concave one): the real
  boundary goes round the corner on an arc of radius |offset| about it (material grown evenly, as a
  tool's offset path does), drawn here every 5° at the corner's arc position;
- they **overlap** where the offset is inward at a convex corner (or outward at a concave one): each
  piece ends where it meets the other, and what lies beyond is not boundary.

Moving the corner's point along one normal only (the outgoing piece's) left, at every convex corner
where the machining error was inward, a spike as high as the error (9 µm at ``paper`` noise) above the
incoming piece: a straight jaw rolling in on a 48 mm radius met it a whole degree early, 0.8 mm before
the corner, which no real part does and which read as a part that is not its model. A dent across a
concave corner left a loop that made the world cross itself.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from localizer import Outline, Part

__all__ = ["offset_boundary"]

#: The arc round a corner where the pieces part is drawn at this step of its angle (rad).
ROUND_STEP = math.radians(5.0)
#: How far from a corner (in units of the overlap's own reach, |offset|·tan(|angle| / 2) along straight
#: pieces) the pieces are searched for where they meet.
OVERLAP_REACH = 4.0
#: Points this close to the other piece (mm) are where the two meet.
MEET = 1e-9


def offset_boundary(
    model: Part | Outline, arcs: np.ndarray, normal: np.ndarray, offset: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The model's boundary moved by ``offset`` along its outward ``normal`` at each arc, joined at corners.

    Parameters
    ----------
    model : Part or Outline
        The model (an :class:`~localizer.Outline`'s corners are among ``arcs``).
    arcs : ndarray (n,), mm
        Increasing arc positions in [0, perimeter), every corner's included (:func:`sim2d.sampled.model_sample`).
    normal : ndarray (n, 2)
        The outward unit normal at each (at a corner, the one after it).
    offset : ndarray (n,), mm
        How far each point moves (> 0 outward).

    Returns
    -------
    arcs, xy : ndarray (m,), (m, 2)
        The moved boundary's points, each with the model arc it stands for (non-decreasing: the points
        round a corner all stand for the corner).
    """
    arcs = np.asarray(arcs, dtype=float)
    xy = np.asarray(model.point_at_arc(arcs), dtype=float) + np.asarray(offset, dtype=float)[:, None] * normal
    corners = getattr(model, "corners", ())
    if not corners:
        return arcs, xy
    keep = np.ones(arcs.size, dtype=bool)
    spacing = float(np.max(np.diff(arcs)))
    rounds: dict[int, np.ndarray] = {}  # points that stand for a corner's sample, where the pieces part
    at = np.searchsorted(arcs, [c.arc for c in corners])
    P = float(model.perimeter)
    gaps = np.diff(np.append([c.arc for c in corners], corners[0].arc + P))
    for k, (corner, i) in enumerate(zip(corners, at)):
        o = float(offset[i])
        if abs(o) <= MEET:
            continue
        if o * corner.angle > 0:  # the pieces part: round the corner, from the incoming normal to n_out
            n_out = normal[i]
            point = np.asarray(model.point_at_arc(arcs[i]), dtype=float)
            steps = max(2, math.ceil(abs(corner.angle) / ROUND_STEP) + 1)
            turn = np.linspace(-corner.angle, 0.0, steps)
            cs, sn = np.cos(turn), np.sin(turn)
            around = np.stack([cs * n_out[0] - sn * n_out[1], sn * n_out[0] + cs * n_out[1]], axis=-1)
            rounds[int(i)] = point + o * around
            continue
        # the pieces overlap: each ends where it meets the other (searched near the corner only). A point
        # is judged against the other piece's nearest point and normal there, not its tangent line at the
        # corner: a dent's overlap at a sharp corner reaches millimetres along curved pieces
        reach = OVERLAP_REACH * abs(o) * math.tan(0.5 * min(abs(corner.angle), 3.1))
        reach = min(reach + 2.0 * spacing, 0.45 * min(gaps[k], gaps[k - 1]))
        before = np.flatnonzero(((arcs[i] - arcs) % P > 0) & ((arcs[i] - arcs) % P <= reach))
        after = np.flatnonzero((arcs - arcs[i]) % P <= reach)
        sign = math.copysign(1.0, corner.angle)
        # a point on both pieces (where they meet, to rounding) is kept once: the outgoing piece's
        for mine, other, margin in ((before, after, -MEET), (after, before, MEET)):
            _, near = cKDTree(xy[other]).query(xy[mine])
            side = np.einsum("ij,ij->i", xy[mine] - xy[other][near], normal[other][near])
            keep[mine[sign * side > margin]] = False
    if not rounds:
        return arcs[keep], xy[keep]
    out_arcs, out_xy = [], []
    start = 0
    for i in sorted(rounds):
        out_arcs += [arcs[start:i][keep[start:i]], np.full(rounds[i].shape[0], arcs[i])]
        out_xy += [xy[start:i][keep[start:i]], rounds[i]]
        start = i + 1
    out_arcs.append(arcs[start:][keep[start:]])
    out_xy.append(xy[start:][keep[start:]])
    return np.concatenate(out_arcs), np.concatenate(out_xy)
