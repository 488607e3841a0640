"""The straight jaw's wrist calibrated without weights (paper §III-B): 11 taps from -50 to 50 mm on the
jaw, Δv1 held constant by feedback, a cubic spline of the ratio Δv2/Δv1 against the contact's place,
read back by intersecting it; kept in a JSON file."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from ..rig import (
    Rig,
    RigError,
)
from .hand import (
    PRESS,
    Hand,
    PressSettings,
    delta_voltages,
    press,
    zero,
)

__all__ = ["Calibration", "calibrate"]


@dataclass(frozen=True)
class Calibration:
    """Contact location on the jaw from the ratio Δv2/Δv1 (paper §III-B, Fig. 6a).

    Attributes
    ----------
    positions : tuple of float, mm
        Jaw positions of the taps.
    ratios : tuple of float
        Measured Δv2/Δv1 at each tap.
    target : float, V
        Δv1 held during the taps.
    jaw : str
        The finger calibrated (the paper's 100 mm jaw): refused for another.

    Examples
    --------
    A sensor whose ratio grows linearly along the jaw:

    >>> cal = Calibration(positions=(-50.0, -25.0, 0.0, 25.0, 50.0), ratios=(0.5, 0.75, 1.0, 1.25, 1.5))
    >>> round(cal.position(1.1), 6)
    10.0
    """

    positions: tuple[float, ...]
    ratios: tuple[float, ...]
    target: float = 0.4
    jaw: str = "straight:100"
    _r: NDArray[np.float64] = field(init=False, repr=False, compare=False)  # the ratios, ascending
    _d: NDArray[np.float64] = field(init=False, repr=False, compare=False)  # the positions in that order, mm

    def __post_init__(self) -> None:
        d = np.asarray(self.positions, float)
        r = np.asarray(self.ratios, float)
        if d.size < 4 or d.size != r.size or not np.all(np.isfinite(r)):
            raise RigError(f"calibration needs >= 4 finite (position, ratio) pairs, got {d.size} and {r.size}")
        if np.any(np.diff(d) <= 0):
            raise RigError("calibration positions must increase")
        grid = np.linspace(d[0], d[-1], 2001)
        rg = CubicSpline(d, r)(grid)
        steps = np.diff(rg)
        if not (np.all(steps < 0) or np.all(steps > 0)):
            k = int(np.argmax(np.sign(steps) != np.sign(steps[0])))
            raise RigError(
                f"calibration is not monotone near {grid[k]:.1f} mm on the jaw: a ratio there "
                "matches two contact locations; recalibrate with more averaging"
            )
        order = np.argsort(rg)
        object.__setattr__(self, "_r", rg[order])
        object.__setattr__(self, "_d", grid[order])

    def position(self, ratio: float) -> float:
        """Contact location (mm) for a ratio Δv2/Δv1, by intersecting the spline."""
        r = float(ratio)
        lo, hi = self._r[0], self._r[-1]
        margin = 0.02 * (hi - lo)
        if not (lo - margin <= r <= hi + margin):
            raise RigError(
                f"ratio Δv2/Δv1 = {r:.5f} is outside the calibrated range [{lo:.5f}, {hi:.5f}]: "
                f"the contact is beyond the calibrated span {self.positions[0]:.0f}..{self.positions[-1]:.0f} mm"
            )
        if r < lo or r > hi:  # a little beyond the ends: extrapolate the end slope
            j = (0, 1) if r < lo else (-2, -1)
            return float(
                self._d[j[0]] + (r - self._r[j[0]]) * (self._d[j[1]] - self._d[j[0]]) / (self._r[j[1]] - self._r[j[0]])
            )
        return float(np.interp(r, self._r, self._d))

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write as JSON."""
        doc = {"jaw": self.jaw, "positions": list(self.positions), "ratios": list(self.ratios), "target": self.target}
        Path(path).write_text(json.dumps(doc, indent=2) + "\n")

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Calibration:
        """Read a calibration written by :meth:`save`."""
        try:
            data = json.loads(Path(path).read_text())
            if not isinstance(data, dict):
                raise ValueError(f"it holds a JSON {type(data).__name__}, not a calibration's object")
            jaw = str(data.get("jaw", "straight:100"))  # files from before fingers were named: the paper's jaw
            if not jaw.startswith("straight"):
                raise ValueError(f"it is a calibration of a {jaw} finger, not of a straight jaw")
            return cls(tuple(data["positions"]), tuple(data["ratios"]), float(data.get("target", 0.4)), jaw)
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise RigError(f"calibration file {path}: {exc}") from None


def calibrate(
    rig: Rig,
    approach_pose: Iterable[float],
    *,
    taps: int = 11,
    span: float = 50.0,
    target: float = 0.4,
    n: int = 256,
    backoff: float = 2.0,
    pressing: PressSettings = PRESS,
) -> Calibration:
    """Tap an immobilized object at ``taps`` jaw positions from -span to +span mm (paper §III-B).

    ``approach_pose`` faces the object's contact point with jaw position 0, clear of it.
    Before each tap the jaw slides along itself so that the same object point meets the
    jaw ``span/5`` mm further on; Δv1 is held at ``target`` by feedback while Δv2 is read.
    """
    x0, y0, phi = (float(v) for v in approach_pose)
    Hand(rig, (x0, y0, phi))
    baseline = zero(rig)  # clear of the object
    positions = np.linspace(-span, span, taps)
    ratios: list[float] = []
    for d in positions:
        hand = Hand(rig, (x0 - d * math.cos(phi), y0 - d * math.sin(phi), phi))
        press(rig, hand, baseline, target=target, pressing=pressing)
        dv1, dv2 = delta_voltages(rig, baseline, n)
        ratios.append(dv2 / dv1)
        hand.press_by(-backoff - 1.0)
    return Calibration(tuple(float(v) for v in positions), tuple(float(v) for v in ratios), target)
