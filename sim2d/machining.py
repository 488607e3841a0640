"""Machining error: the real part differs from its model by a smooth random normal deviation."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from localizer import Outline, Part, check_grid, part_from_points

from .noise import NoiseModel
from .offset import offset_boundary
from .sampled import SAMPLE_SPACING, SampledPart, model_sample

__all__ = ["machined_part", "machined_outline", "machining_deviation", "machining_slope"]


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
    # one harmonic a wavelength of the perimeter, each summed over the knots in turn
    wavelength = noise.machining_wavelength
    check_grid(
        part,
        "simulated machining",
        wavelength,
        part.perimeter / wavelength,
        unit="harmonics",
        advice=f"is the part in the right units (mm), and machining_wavelength={wavelength:g} mm meant?",
    )
    knots = np.arange(part.n_knots, dtype=float)
    dev = machining_deviation(part.arc_at_param(knots), part.perimeter, noise, rng)
    pts = part.points + dev[:, None] * part.normal(knots)
    return part_from_points(pts, name=f"{part.name} (machined)")


def machining_deviation(sigma: np.ndarray, perimeter: float, noise: NoiseModel, rng: np.random.Generator) -> np.ndarray:
    """The random normal deviation, mm, at arc positions ``sigma``: harmonics of the perimeter with 1/k
    amplitudes down to ``noise.machining_wavelength``, scaled to an RMS of ``noise.machining_error``."""
    kmax = max(1, int(perimeter / noise.machining_wavelength))
    dev = np.zeros(sigma.size)
    for k in range(1, kmax + 1):
        dev += rng.normal() / k * np.cos(2 * np.pi * k * sigma / perimeter + rng.uniform(0, 2 * np.pi))
    scaled: np.ndarray = dev * noise.machining_error / max(np.sqrt(np.mean(dev**2)), 1e-300)
    return scaled


def machined_outline(
    outline: Outline,
    noise: NoiseModel,
    rng: np.random.Generator,
    spacing: float = SAMPLE_SPACING,
    change: Callable[[np.ndarray], np.ndarray] | None = None,
) -> SampledPart:
    """The ``outline`` as machined under the ``noise`` model (the same deviation as :func:`machined_part`:
    harmonics of the arc position, drawn from ``rng``), sampled every ``spacing`` mm with its corners, the
    pieces joined at each corner as a real part's are (:func:`sim2d.offset.offset_boundary`).

    ``change`` (arc positions, mm → mm outward) adds a deviation of its own along the same normals (a
    burr, a dent: :func:`sim2d.world_part.world_part`); the result then says it is ``altered``."""
    arcs, _, normal = model_sample(outline, spacing)
    offset = np.zeros(arcs.size)
    if noise.machining_error > 0:
        offset += machining_deviation(arcs, outline.perimeter, noise, rng)
    if change is not None:
        offset += change(arcs)
    arcs, xy = offset_boundary(outline, arcs, normal, offset)
    return SampledPart(outline, arcs, xy, altered=change is not None)


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
