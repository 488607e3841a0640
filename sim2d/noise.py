"""The noise model of the simulated instruments: one frozen dataclass, presets, TOML files.

Units: volts (V) for the strain-gauge channels, seconds (s), radians for the
encoder, millimetres for machining error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from pathlib import Path

from localizer import read_toml

from ._errors import SimError

#: The largest noise file read, bytes: a noise model is a few lines of TOML.
MAX_NOISE_BYTES = 2**16

__all__ = ["NoiseModel", "PRESETS", "load_noise"]


@dataclass(frozen=True)
class NoiseModel:
    """Imperfections of the wrist sensor, the arm's encoder and the part.

    Attributes
    ----------
    v1_noise, v2_noise : float, V
        Standard deviation of one raw sample of Δv1 (bending) and Δv2 (twist).
    v1_offset, v2_offset : float, V
        Constant offsets of the two channels (the default readings).
    v1_drift, v2_drift : float, V/s
        Drift in one direction (paper §III-B: "relatively small and in one direction").
    adc_step : float, V
        ADC quantization step (0 = none).
    crosstalk : float
        Fraction of the bending signal seen by the twist channel and vice versa
        (the paper assumes it negligible).
    nonlinearity : float
        Relative cubic term of the twist channel against contact location,
        Δv2 ∝ d·(1 + nonlinearity·(d/50 mm)²): the smooth calibration
        nonlinearity of paper Fig. 6(a).
    gain_error : float
        Relative error of the twist channel's gain against the nominal
        (absorbed by calibration, visible without it).
    encoder_step : float, rad
        Quantization of the arm's joint angle (Adept Cobra 600: 0.03°).
    machining_error : float, mm
        RMS normal deviation of the real part from its model (smooth, random).
    machining_wavelength : float, mm
        Shortest wavelength of the machining deviation.
    axle_encoder_step : float, rad
        Quantization of a wheel finger's axle encoder (docs/wheel.md: 12 bits, 0.088°); unused by the
        straight jaw.
    """

    v1_noise: float = 0.0
    v2_noise: float = 0.0
    v1_offset: float = 0.0
    v2_offset: float = 0.0
    v1_drift: float = 0.0
    v2_drift: float = 0.0
    adc_step: float = 0.0
    crosstalk: float = 0.0
    nonlinearity: float = 0.0
    gain_error: float = 0.0
    encoder_step: float = 0.0
    machining_error: float = 0.0
    machining_wavelength: float = 20.0
    axle_encoder_step: float = 0.0

    def __post_init__(self):
        for f in fields(self):
            v = getattr(self, f.name)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
                raise SimError(f"noise model: {f.name}={v!r} must be a finite number")
        for name in ("v1_noise", "v2_noise", "adc_step", "encoder_step", "machining_error", "axle_encoder_step"):
            if getattr(self, name) < 0:
                raise SimError(f"noise model: {name}={getattr(self, name)!r} must be >= 0")
        if self.machining_wavelength <= 0:
            raise SimError(f"noise model: machining_wavelength={self.machining_wavelength!r} must be > 0")

    def scaled(self, **factors) -> NoiseModel:
        """A copy with some fields multiplied, e.g. ``scaled(v2_noise=2.0)``."""
        for k in factors:
            if k not in self.__dataclass_fields__:
                raise SimError(f"noise model has no field {k!r}; fields: {sorted(self.__dataclass_fields__)}")
        return replace(self, **{k: getattr(self, k) * f for k, f in factors.items()})


#: Named presets. ``paper`` reproduces the paper's rig (Jia 2005 §III–IV): the encoder's
#: ±0.03°, one-way drift, a visibly curved calibration spline (8% cubic term, 5% gain
#: error, cross-talk), an 18-bit ADC over ±10 V, sensor noise and machining error. The paper
#: states no noise amplitudes; these were calibrated so that the paper's method (two
#: rolls, its disambiguation rule) succeeds about 45% of the time on the shipped parts, as
#: the paper's rig did (docs/robustness.md: a common scale of the noise, drift, ADC and
#: machining amplitudes swept from 1 to 0.1; 0.175 of the first guess lands there).
PRESETS = {
    "none": NoiseModel(),
    "paper": NoiseModel(
        v1_noise=0.0007,
        v2_noise=0.0001,
        v1_offset=0.05,
        v2_offset=-0.02,
        v1_drift=3.5e-6,
        v2_drift=3.5e-7,
        adc_step=20.0 / 2**18,
        crosstalk=0.003,
        nonlinearity=0.08,
        gain_error=0.05,
        encoder_step=math.radians(0.03),
        machining_error=0.009,
        machining_wavelength=20.0,
        axle_encoder_step=2 * math.pi / 4096,
    ),
}


def load_noise(spec) -> NoiseModel:
    """A noise model from a preset name, a TOML file, or a NoiseModel.

    Parameters
    ----------
    spec : str, Path or NoiseModel
        ``"none"``, ``"paper"``, or a TOML file whose top-level keys are
        NoiseModel fields; an optional ``preset = "paper"`` key starts from a
        preset and the other keys override it.

    Raises
    ------
    SimError
        Unknown preset, unreadable file, unknown key, bad value.

    Examples
    --------
    >>> load_noise("paper").machining_error       # mm
    0.009
    >>> load_noise("none").machining_error
    0.0
    """
    if isinstance(spec, NoiseModel):
        return spec
    text = str(spec)
    if text in PRESETS:
        return PRESETS[text]
    path = Path(text)
    if path.suffix.lower() != ".toml":
        raise SimError(f"noise {text!r}: use a preset {sorted(PRESETS)} or a .toml file")
    data = read_toml(path, MAX_NOISE_BYTES, "noise file", SimError)
    base = data.pop("preset", "none")
    if base not in PRESETS:
        raise SimError(f"noise file {text}: unknown preset {base!r}; use one of {sorted(PRESETS)}")
    unknown = sorted(set(data) - set(NoiseModel.__dataclass_fields__))
    if unknown:
        raise SimError(
            f"noise file {text}: unknown key(s) {unknown}; valid keys: {sorted(NoiseModel.__dataclass_fields__)}"
        )
    return replace(PRESETS[base], **data)
