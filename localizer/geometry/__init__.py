"""A part's boundary and how it is read: the spline through a point file, the outline of exact
pieces drawn in CAD (lines, arcs, Béziers, corners), the file readers, the limits every input
and table is held to, and the numerics the whole package shares.
"""

from ._boundary import Boundary
from ._cache import per_part
from ._cad import CAD_SUFFIXES, load_outline
from ._facets import FACETS, FacetRule, read_facets
from ._files import load_part
from ._fingerprint import QUANTUM_MM, fingerprint
from ._limits import (
    MAX_ARRAY_BYTES,
    MAX_GRID_POINTS,
    MAX_PAIRWISE_POINTS,
    MAX_PART_BYTES,
    MAX_PIECES,
    bytes_text,
    check_grid,
    check_size,
    count_text,
    read_toml,
)
from ._numerics import TWO_PI, curvature, gauss_legendre, mod_period, wrap_angle
from ._outline import Corner, Outline, nearest_corner, outline_from_pieces
from ._part import UNITS_TO_MM, Part, part_from_points, polygon_crossing
from ._pieces import CircularArc, CubicBezier, Line, elliptical_arc
from ._poly import bernstein_bounds, horner

__all__ = [
    "Boundary",
    "per_part",
    "CAD_SUFFIXES",
    "load_outline",
    "FACETS",
    "FacetRule",
    "read_facets",
    "load_part",
    "QUANTUM_MM",
    "fingerprint",
    "MAX_ARRAY_BYTES",
    "MAX_GRID_POINTS",
    "MAX_PAIRWISE_POINTS",
    "MAX_PART_BYTES",
    "MAX_PIECES",
    "bytes_text",
    "check_grid",
    "check_size",
    "count_text",
    "read_toml",
    "TWO_PI",
    "curvature",
    "gauss_legendre",
    "mod_period",
    "wrap_angle",
    "Corner",
    "Outline",
    "nearest_corner",
    "outline_from_pieces",
    "UNITS_TO_MM",
    "Part",
    "part_from_points",
    "polygon_crossing",
    "CircularArc",
    "CubicBezier",
    "Line",
    "elliptical_arc",
    "bernstein_bounds",
    "horner",
]
