"""The package's type aliases, defined once (as pymunk keeps its aliases in one ``_types``).

Arrays are typed by their element type only; shapes are in the docstrings.
"""

from typing import TypeAlias

import numpy as np
import numpy.typing as npt

__all__ = ["FloatArray", "IntArray", "BoolArray", "ArrayLike"]

#: An array of float64 (positions in mm, angles in rad, ...).
FloatArray: TypeAlias = npt.NDArray[np.float64]
#: An array of platform integers (indices, counts).
IntArray: TypeAlias = npt.NDArray[np.intp]
#: An array of booleans (masks).
BoolArray: TypeAlias = npt.NDArray[np.bool_]
#: An input that may be a scalar, a sequence or an array (converted with ``np.asarray``).
ArrayLike: TypeAlias = npt.ArrayLike
