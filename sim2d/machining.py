"""Machining error: the real part differs from its model by a smooth random normal deviation."""

from __future__ import annotations

import math

import numpy as np

from localizer import Part, part_from_points

from .noise import NoiseModel

__all__ = ["machined_part", "machining_slope"]


def machined_part(part: Part, noise: NoiseModel, rng: np.random.Generator) -> Part:
    """The ``part`` as machined under the ``noise`` model, its random harmonics drawn from ``rng``: each knot
    moved along the model's outward normal.

    The deviation is a random sum of harmonics of the arc position with
    wavelengths down to ``noise.machining_wavelength`` mm, scaled to an RMS of
    ``noise.machining_error`` mm. Knot i of the result corresponds to knot i
    of the model, so spline parameters map one to one.
    """
    if noise.machining_error <= 0:
        return part
    P = part.perimeter
    kmax = max(1, int(P / noise.machining_wavelength))
    knots = np.arange(part.n_knots, dtype=float)
    sigma = part.arc_at_param(knots)
    dev = np.zeros(part.n_knots)
    for k in range(1, kmax + 1):
        dev += rng.normal() / k * np.cos(2 * np.pi * k * sigma / P + rng.uniform(0, 2 * np.pi))
    dev *= noise.machining_error / max(np.sqrt(np.mean(dev**2)), 1e-300)
    pts = part.points + dev[:, None] * part.normal(knots)
    return part_from_points(pts, name=f"{part.name} (machined)")


def machining_slope(rms: float, wavelength: float, perimeter: float) -> float:
    """RMS slope error (rad) of a boundary deviation of ``rms`` mm made of harmonics of the
    ``perimeter`` (mm) with 1/k amplitudes down to ``wavelength`` mm (the simulator's machining model).

    Examples
    --------
    The ``paper`` preset's 0.009 mm at 20 mm on a 400 mm outline:

    >>> round(machining_slope(0.009, 20.0, 400.0) * 1e3, 3)  # mrad
    0.5
    """
    if rms <= 0:
        return 0.0
    k = np.arange(1, max(1, int(perimeter / wavelength)) + 1)
    return float(rms * 2 * np.pi / perimeter * math.sqrt(len(k) / np.sum(1.0 / k**2)))
