"""Machining error: the real part differs from its model by a smooth random normal deviation."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from localizer import Outline, Part, part_from_points

from .noise import NoiseModel

__all__ = ["machined_part", "machined_outline", "MachinedOutline", "machining_slope"]

#: Arc between the points of a machined outline, mm: the kinematic world takes the deepest of them as
#: the contact, so this bounds the contact's place error (a quarter of a µm of depth on a 10 mm radius).
OUTLINE_SPACING = 0.005


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
    knots = np.arange(part.n_knots, dtype=float)
    dev = _deviation(part.arc_at_param(knots), part.perimeter, noise, rng)
    pts = part.points + dev[:, None] * part.normal(knots)
    return part_from_points(pts, name=f"{part.name} (machined)")


def _deviation(sigma: np.ndarray, perimeter: float, noise: NoiseModel, rng: np.random.Generator) -> np.ndarray:
    """The random normal deviation, mm, at arc positions ``sigma``: harmonics of the perimeter with 1/k
    amplitudes down to ``noise.machining_wavelength``, scaled to an RMS of ``noise.machining_error``."""
    kmax = max(1, int(perimeter / noise.machining_wavelength))
    dev = np.zeros(sigma.size)
    for k in range(1, kmax + 1):
        dev += rng.normal() / k * np.cos(2 * np.pi * k * sigma / perimeter + rng.uniform(0, 2 * np.pi))
    scaled: np.ndarray = dev * noise.machining_error / max(np.sqrt(np.mean(dev**2)), 1e-300)
    return scaled


@dataclass(frozen=True, eq=False)
class MachinedOutline:
    """An outline as machined: dense points of the real boundary, each the model's point at arc ``arcs``
    moved along the model's outward normal (after the jump at a corner).

    Attributes
    ----------
    model : Outline
    arcs : ndarray, shape (n,), mm
        The model's arc position of each point (every corner's included).
    xy : ndarray, shape (n, 2), mm
    """

    model: Outline
    arcs: np.ndarray
    xy: np.ndarray

    @property
    def name(self) -> str:
        return f"{self.model.name} (machined)"

    @property
    def perimeter(self) -> float:
        return self.model.perimeter


def machined_outline(
    outline: Outline, noise: NoiseModel, rng: np.random.Generator, spacing: float = OUTLINE_SPACING
) -> MachinedOutline:
    """The ``outline`` as machined under the ``noise`` model (the same deviation as :func:`machined_part`:
    harmonics of the arc position, drawn from ``rng``), sampled every ``spacing`` mm with its corners."""
    P = outline.perimeter
    arcs = np.unique(np.concatenate([np.arange(0.0, P, spacing), [c.arc for c in outline.corners]]))
    xy = np.asarray(outline.point_at_arc(arcs), dtype=float)
    if noise.machining_error > 0:
        theta = np.asarray(outline.tangent_angle_at_arc(arcs))
        normal = np.stack([np.sin(theta), -np.cos(theta)], axis=-1)
        xy = xy + _deviation(arcs, P, noise, rng)[:, None] * normal
    return MachinedOutline(outline, arcs, xy)


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
