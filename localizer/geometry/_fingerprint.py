"""A part's fingerprint: a short name for its geometry, so that a trace, a run log or a study made on one
part is never scored on another.

The geometry is what the localizer sees, in millimetres after the file's units are applied: the
perimeter and the boundary's points at :data:`SAMPLES` equal steps of arc from the first point, each
rounded to :data:`QUANTUM_MM` mm, hashed (SHA-256). A spline and a drawing are fingerprinted alike, a file
renamed or copied keeps its fingerprint, and a knot moved by a micrometre or a part given in other units
changes it. The rounding keeps the last bits of floating-point arithmetic (another numpy, another
machine) out of the name: a coordinate lands within 1e-12 mm of a rounding boundary about once in 1e8.
"""

from __future__ import annotations

import hashlib

import numpy as np

from ._boundary import Boundary

__all__ = ["fingerprint", "SAMPLES", "QUANTUM_MM"]

#: Points of the boundary the fingerprint hashes, at equal steps of arc.
SAMPLES = 256
#: The rounding of each hashed number, mm: a tenth of a micrometre.
QUANTUM_MM = 1e-4


def fingerprint(part: Boundary) -> str:
    """A 16-hex-digit name of ``part``'s geometry (see the module notes).

    Parameters
    ----------
    part : Part or Outline

    Returns
    -------
    str
        Equal for two loads of one file, for a copy of it under another name, and for a drawing and its
        re-export that trace the same boundary from the same first point; different for any change of
        shape, size or first point larger than about :data:`QUANTUM_MM` mm.

    Examples
    --------
    >>> import numpy as np
    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 32, endpoint=False)
    >>> circle = part_from_points(np.c_[20 * np.cos(a), 20 * np.sin(a)])
    >>> fingerprint(circle) == fingerprint(part_from_points(np.c_[20 * np.cos(a), 20 * np.sin(a)], name="other"))
    True
    >>> fingerprint(circle) == fingerprint(part_from_points(np.c_[20.01 * np.cos(a), 20 * np.sin(a)]))
    False
    """
    perimeter = float(part.perimeter)
    arcs = perimeter * np.arange(SAMPLES) / SAMPLES
    points = np.asarray(part.point_at_arc(arcs), dtype=float)
    numbers = np.concatenate([[perimeter], points.ravel()])
    quanta = np.round(numbers / QUANTUM_MM).astype(np.int64)
    return hashlib.sha256(quanta.tobytes()).hexdigest()[:16]
