"""Monte Carlo study files (TOML): their schema, read and checked (the trial they describe: :mod:`bench.trial`).

A study file::

    name = "paper"                       # optional, for plots
    parts = ["../../parts/trefoil.json"] # relative to the study file (or absolute)
    rolls_deg = [20.0, 15.0]             # one localization = these rolls, all one way
    step_deg = 0.2                       # rolling step
    method = "paper"                     # "paper" or "likelihood" (the localizer's rule)
    engine = "kinematic"                 # or "pymunk"
    trials = 200                         # per level
    seed = 2005
    success_radius = 0.3                 # mm (default localizer.SUCCESS_RADIUS)
    noise = "paper"                      # preset or a TOML file (relative to the study file)

    [sweep]                              # optional: one noise-model field over levels
    parameter = "v2_noise"
    values = [0.0, 0.0003, 0.0006, 0.0012]
    # or whole noise models over levels (files relative to the study file, or presets):
    # parameter = "noise"
    # values = ["noise/paper-x0.5.toml", "paper", "noise/paper-x2.toml"]

    jaw = "straight:100"                 # optional: the finger (or "wheel:5", docs/wheel.md)
    [sweep]                              # or the finger over levels: the same trials' seeds, each
    parameter = "jaw"                    #   finger from a start drawn uniformly over the whole
    values = ["straight:100", "wheel:5"] #   boundary and redrawn where it cannot start ("redraws")

    [likelihood]                         # optional: the standard deviations told to the
    sd_length = 0.3                      # likelihood rule (mm, degrees)
    sd_turn_deg = 0.03

Several methods on the same trials (instead of ``method``)::

    methods = ["paper", "particle", "reactive"]   # first one fills success/error_mm

    [reactive]                           # the sequential filter (driver.jaw.reactive)
    confidence = 0.95
    max_rotation_deg = 240.0             # default driver.jaw.MAX_ROTATION
    sd_position = 0.04                   # mm, one contact-location reading   } each optional: the
    sd_scale = 0.003                     # calibration scale                  } filter's own default,
    sd_slope = 0.003                     # rad, the part's slope error        } with its noise scale
                                         #   ("auto": from the study's noise model)  weighed out
    noise_scales = [1.0]                 # optional: the factors on those it weighs (default
                                         #   localizer.NOISE_SCALES; [1.0] trusts them)
    slope_envelope = [0.25]              # optional: other factors on sd_slope under which the
                                         #   stated mass must hold too (default
                                         #   localizer.SLOPE_ENVELOPE; [] the slope prior alone)
    defect_window = 12.0                 # optional: mm of rolled arc no belief may rest on alone,
                                         #   and the stretch the fit test judges (0: neither)
    lookalike_slope = 8.0                # optional: the factor on sd_slope under which a look-alike
                                         #   must be ruled out too (default localizer.LOOKALIKE_SLOPE;
                                         #   0: no such check)
    corner_ends = true                   # optional: the stated mass must hold too under a prior that
                                         #   lays the jaw on a corner only at its jump's ends (drawings)
    stretch_weight = 0.06                # optional: the weight of the stretch check in the stated
                                         #   mass (default localizer.STRETCH_WEIGHT; 1: the least)
    seek = false                         # optional: false for the baseline direction rule (the two
                                         #   leading modes' spread); default true, seeking information
    off_scale = 0.05                     # optional, the wheel: the prior probability that the part is
                                         #   off its model's size (default localizer.OFF_SCALE; 0: the
                                         #   part is its model's size)

    [world]                              # optional: how each trial's world differs from the model
    defects = 1                          #   (sim2d.world_part): defects near the start, or anywhere,
    defect_height_mm = [0.1, 0.5]        #   a bump > 0, a dent < 0, or a range of magnitudes with a
    defect_length_mm = 4.0               #   random sign; scale; spikes of the wrist (rate per reading,
    defect_place = "start"               #   size in raw samples' sd); world_parts: a part file per
    defect_near_mm = 5.0                 #   model part (a scan against its drawing)
    scale = 1.0
    spike_rate = 0.0
    spike_size = 20.0
    world_parts = []

    [particle]                           # the peer baseline, over the fixed rolls' readings
    particles = 2000
    sd_position = 0.04                   # mm, one reading
    process = 0.005                      # mm per step

The paper and likelihood methods, the particle filter and ``grid`` (the reactive
method's filter, :class:`localizer.ContactFilter` with the ``[reactive]`` settings,
without the reactive rolling) use the readings of the fixed rolls
(``rolls_deg``); the reactive method rolls on its own, from the same start on a
rig with the same seed.

Every trial is reproducible from (seed, level, trial): its generator is
``numpy.random.SeedSequence([seed, level, trial])``. The start is drawn uniformly over the
boundary points from which the jaw, laid with the contact 40 mm from its centre, can roll the
fixed rolls without bridging (:class:`localizer.Reach`); the rig's own refusal, rare then, is
redrawn (``restarts``). Calibration taps the most curved point the whole jaw reaches
(:func:`localizer.calibration_arc`). Each method is scored on its own: an error in one is that
method's failure (``<method>_stopped = "error"``, ``<method>_failure``), never the others'.
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar, cast

from driver.jaw import STEP_RANGE_DEG
from localizer import (
    MAX_GRID_POINTS,
    ROLL_STEP,
    SUCCESS_RADIUS,
    RolltouchError,
    load_part,
    read_toml,
)
from sim2d import WorldSpec

from .columns import FINGER_COLUMNS, METHOD_COLUMNS, METHODS, TRIAL_COLUMNS, WORLD_COLUMNS
from .method_options import ParticleOptions, ReactiveOptions

if TYPE_CHECKING:
    from sim2d import NoiseModel

#: The rolling step, degrees, from its one home.
STEP_DEG = round(math.degrees(ROLL_STEP), 9)
#: The largest study file read, bytes (a study is a page of TOML).
MAX_STUDY_BYTES = 2**20
#: The most trials one study may run (split a larger one: its table is read whole).
MAX_TRIALS = 100_000
#: The standard deviations a study tells the two-roll rules unless its [likelihood] table says
#: otherwise, mm and degrees: the simulated rig's own at the `paper` preset, which a study knows (a
#: user's first run does not: the rules' defaults, :data:`localizer.SD_LENGTH`, are wider).
STUDY_SD_LENGTH = 0.3
STUDY_SD_TURN_DEG = 0.03

__all__ = ["Study", "StudyError", "load_study", "STUDY_SD_LENGTH", "STUDY_SD_TURN_DEG"]


_KEYS = {
    "name",
    "parts",
    "rolls_deg",
    "step_deg",
    "method",
    "methods",
    "engine",
    "trials",
    "seed",
    "success_radius",
    "noise",
    "sweep",
    "likelihood",
    "reactive",
    "particle",
    "jaw",
    "world",
}


class StudyError(RolltouchError, ValueError):
    """A study file that cannot be run; the message names the key and what is wrong."""


@dataclass(frozen=True)
class Study:
    """A parsed study: each field is the study file's key of the same name (module notes), paths resolved.

    Attributes
    ----------
    name, parts, rolls_deg, step_deg, method, engine, trials, seed, success_radius, noise
        The file's keys (``parts``: absolute paths; ``rolls_deg`` and ``step_deg`` in degrees;
        ``success_radius`` in mm; ``noise``: a preset or a resolved file).
    parameter, values
        The ``[sweep]``: the swept noise-model field (or ``"noise"``, or ``"jaw"``: fingers) and its values.
    sd_length, sd_turn_deg
        The ``[likelihood]`` table (mm, degrees).
    source : str
        The study file's path.
    methods : tuple of str
        The methods scored on the same trials.
    reactive, particle : ReactiveOptions, ParticleOptions
        The ``[reactive]`` and ``[particle]`` tables.
    jaw : str
        The finger (``"straight:100"`` or ``"wheel:R"``) when no sweep names it.
    world : WorldSpec or None
        The ``[world]`` table: how each trial's world differs from the model (None: no table).
    """

    name: str
    parts: tuple[str, ...]
    rolls_deg: tuple[float, ...]
    step_deg: float = STEP_DEG
    method: str = "paper"
    engine: str = "kinematic"
    trials: int = 100
    seed: int = 0
    success_radius: float = SUCCESS_RADIUS
    noise: str = "paper"
    parameter: str | None = None
    values: tuple[str | float, ...] = ()
    sd_length: float = STUDY_SD_LENGTH
    sd_turn_deg: float = STUDY_SD_TURN_DEG
    source: str = ""
    methods: tuple[str, ...] = ()
    reactive: ReactiveOptions = ReactiveOptions()
    particle: ParticleOptions = ParticleOptions()
    jaw: str = "straight:100"
    world: WorldSpec | None = None

    @property
    def fingers(self) -> bool:
        """Whether the study names its finger (a wheel, or a sweep over fingers): its table has
        :data:`FINGER_COLUMNS` too."""
        return self.parameter == "jaw" or self.jaw != "straight:100"

    @property
    def columns(self) -> tuple[str, ...]:
        """The columns of this study's trials.csv."""
        extra = tuple(f"{m}_{c}" for m in self.methods for c in METHOD_COLUMNS) if self.methods else ()
        world = WORLD_COLUMNS if self.world is not None else ()
        return TRIAL_COLUMNS + extra + (FINGER_COLUMNS if self.fingers else ()) + world

    def level_jaw(self, level: int) -> str:
        """The finger of ``level`` (a spec, :func:`localizer.parse_jaw`)."""
        return str(self.values[level]) if self.parameter == "jaw" else self.jaw

    @property
    def levels(self) -> int:
        return max(1, len(self.values))

    def level_value(self, level: int) -> str | float | None:
        """The swept parameter's value at ``level`` (None without a sweep)."""
        return self.values[level] if self.values else None

    def level_label(self, level: int) -> str | float | None:
        """The value of ``level`` as trials.csv and summary.json write it (a noise file by its name)."""
        v = self.level_value(level)
        return Path(cast(str, v)).stem if self.parameter == "noise" and v is not None else v

    def level_noise(self, level: int) -> NoiseModel:
        """The noise model of ``level``."""
        from sim2d import load_noise

        if self.parameter == "noise":
            return load_noise(self.values[level])
        noise = load_noise(self.noise)
        if self.parameter not in (None, "jaw"):
            noise = replace(noise, **{self.parameter: cast(float, self.values[level])})
        return noise

    def with_overrides(self, *, trials: int | None = None, engine: str | None = None) -> Study:
        """The study with ``trials`` per level and the ``engine`` replaced where given (the command line's flags)."""
        s = self
        if trials is not None:
            if isinstance(trials, bool) or int(trials) < 1:
                raise StudyError(f"--trials {trials} must be at least 1")
            if int(trials) > MAX_TRIALS:
                raise StudyError(f"--trials {trials} is more than {MAX_TRIALS} per level: split the study")
            s = replace(s, trials=int(trials))
        if engine is not None:
            if engine not in ("kinematic", "pymunk"):
                raise StudyError(f"--engine {engine!r}: use kinematic or pymunk")
            s = replace(s, engine=engine)
        return s

    def as_dict(self) -> dict[str, Any]:
        """Plain-JSON form (study.json)."""
        return asdict(self)


def load_study(path: str | os.PathLike[str]) -> Study:
    """Read and check the study file at ``path`` (TOML, see the module notes).

    Raises
    ------
    StudyError
        Unreadable or invalid TOML, unknown keys, missing parts, bad values.
    """
    path = Path(path)
    data = read_toml(path, MAX_STUDY_BYTES, "study", StudyError)
    unknown = sorted(set(data) - _KEYS)
    if unknown:
        raise StudyError(f"study {path}: unknown key(s) {unknown}; valid keys: {sorted(_KEYS)}")
    here = path.resolve().parent

    def resolve(p: str) -> str:
        q = Path(p)
        return str(q if q.is_absolute() else (here / q).resolve())

    parts = data.get("parts")
    if not isinstance(parts, list) or not parts or not all(isinstance(p, str) for p in parts):
        raise StudyError(f"study {path}: 'parts' must be a non-empty list of part files")
    parts = [resolve(p) for p in parts]
    for p in parts:
        if not Path(p).is_file():
            what = "is a folder, not a part file" if Path(p).is_dir() else "does not exist"
            raise StudyError(f"study {path}: part file {p} {what}")
        try:  # read now, so that a bad part is named before any trial runs
            load_part(p)
        except RolltouchError as exc:
            raise StudyError(f"study {path}: {exc}") from None
    rolls = data.get("rolls_deg")
    if (
        not isinstance(rolls, list)
        or not rolls
        or not all(isinstance(r, (int, float)) and not isinstance(r, bool) and r != 0 for r in rolls)
        or len({r > 0 for r in rolls}) != 1
    ):
        raise StudyError(
            f"study {path}: 'rolls_deg' must be a non-empty list of nonzero angles of one sign, got {rolls!r}"
        )
    method = data.get("method", "paper")
    if method not in ("paper", "likelihood"):
        raise StudyError(f"study {path}: method {method!r}; use 'paper' or 'likelihood'")
    methods = data.get("methods", [])
    if not isinstance(methods, list) or not all(m in METHODS for m in methods) or len(set(methods)) != len(methods):
        raise StudyError(f"study {path}: methods {methods!r} must be a list of distinct names from {list(METHODS)}")
    if methods and "method" in data:
        raise StudyError(f"study {path}: give 'method' or 'methods', not both")
    if methods:
        method = methods[0]
    reactive = _options(path, data.get("reactive", {}), ReactiveOptions, "reactive")
    particle = _options(path, data.get("particle", {}), ParticleOptions, "particle")
    engine = data.get("engine", "kinematic")
    if engine not in ("kinematic", "pymunk"):
        raise StudyError(f"study {path}: engine {engine!r}; use 'kinematic' or 'pymunk'")
    for key, default, lo in (("trials", 100, 1), ("seed", 0, 0)):
        v = data.get(key, default)
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise StudyError(f"study {path}: {key}={v!r} must be an integer >= {lo}")
    for key, fallback in (("step_deg", STEP_DEG), ("success_radius", SUCCESS_RADIUS)):
        v = data.get(key, fallback)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
            raise StudyError(f"study {path}: {key}={v!r} must be a positive number")
    step, (step_lo, step_hi) = data.get("step_deg", STEP_DEG), STEP_RANGE_DEG
    if not step_lo <= step <= step_hi:
        raise StudyError(
            f"study {path}: step_deg={step!r} must be between {step_lo:g}° and {step_hi:g}° "
            "(a smaller step would roll for days)"
        )
    if data.get("trials", 100) > MAX_TRIALS:
        raise StudyError(f"study {path}: trials={data['trials']!r} is more than {MAX_TRIALS}: split the study")
    noise = data.get("noise", "paper")
    from sim2d import PRESETS, NoiseModel, SimError, load_noise

    if noise not in PRESETS:
        noise = resolve(noise)
    try:
        base = load_noise(noise)
    except SimError as exc:
        raise StudyError(f"study {path}: noise: {exc}") from None
    parameter: str | None = None
    values: tuple[str | float, ...] = ()
    sweep = data.get("sweep")
    if sweep is not None:
        if not isinstance(sweep, dict) or set(sweep) - {"parameter", "values"}:
            raise StudyError(f"study {path}: [sweep] takes 'parameter' and 'values'")
        parameter = sweep.get("parameter")
        given = sweep.get("values")
        if parameter == "jaw":
            if not isinstance(given, list) or not given or not all(isinstance(v, str) for v in given):
                raise StudyError(f"study {path}: a jaw sweep's values must be a non-empty list of fingers")
            values = tuple(_finger(path, v) for v in given)
        elif parameter == "noise":
            if not isinstance(given, list) or not given or not all(isinstance(v, str) for v in given):
                raise StudyError(f"study {path}: a noise sweep's values must be a non-empty list of presets or files")
            for v in given:
                try:
                    load_noise(v if v in PRESETS else resolve(v))
                except SimError as exc:
                    raise StudyError(f"study {path}: sweep noise {v!r}: {exc}") from None
            values = tuple(v if v in PRESETS else resolve(v) for v in given)
        elif parameter not in NoiseModel.__dataclass_fields__:
            raise StudyError(
                f"study {path}: sweep parameter {parameter!r} is not a noise-model field nor "
                f"'noise'; fields: {sorted(NoiseModel.__dataclass_fields__)}"
            )
        else:
            if not isinstance(given, list) or not given:
                raise StudyError(f"study {path}: sweep values must be a non-empty list")
            for v in given:
                try:
                    replace(base, **{parameter: v})
                except (SimError, TypeError) as exc:
                    raise StudyError(f"study {path}: sweep value {v!r} of {parameter}: {exc}") from None
            values = tuple(float(v) for v in given)
    jaw = _finger(path, data.get("jaw", "straight:100"))
    fingers = cast(tuple[str, ...], values) if parameter == "jaw" else (jaw,)
    if any(f.startswith("wheel") for f in fingers) and methods != ["reactive"]:
        raise StudyError(f'study {path}: a wheel localizes reactively: give methods = ["reactive"]')
    world = None
    if "world" in data:
        try:
            world = WorldSpec.from_table(data["world"], f"study {path}", here, len(parts))
        except SimError as exc:
            raise StudyError(str(exc)) from None
    lk = data.get("likelihood", {})
    if not isinstance(lk, dict) or set(lk) - {"sd_length", "sd_turn_deg"}:
        raise StudyError(f"study {path}: [likelihood] takes 'sd_length' and 'sd_turn_deg'")
    return Study(
        name=str(data.get("name", path.stem)),
        parts=tuple(parts),
        rolls_deg=tuple(float(r) for r in rolls),
        step_deg=float(data.get("step_deg", STEP_DEG)),
        method=method,
        engine=engine,
        trials=int(data.get("trials", 100)),
        seed=int(data.get("seed", 0)),
        success_radius=float(data.get("success_radius", SUCCESS_RADIUS)),
        noise=str(noise),
        parameter=parameter,
        values=values,
        sd_length=float(lk.get("sd_length", STUDY_SD_LENGTH)),
        sd_turn_deg=float(lk.get("sd_turn_deg", STUDY_SD_TURN_DEG)),
        source=str(path),
        methods=tuple(methods),
        reactive=reactive,
        particle=particle,
        jaw=jaw,
        world=world,
    )


def _finger(path: Path, spec: str) -> str:
    """A study's finger spec, checked and written as :func:`localizer.parse_jaw` names it."""
    from localizer import DEFAULT_JAW, StraightJaw, parse_jaw

    try:
        finger = parse_jaw(spec)
    except RolltouchError as exc:
        raise StudyError(f"study {path}: {exc}") from None
    if isinstance(finger, StraightJaw) and finger != DEFAULT_JAW:
        raise StudyError(f"study {path}: jaw {spec!r}: the rig models the paper's {DEFAULT_JAW} jaw only")
    return str(finger)


_Options = TypeVar("_Options", ReactiveOptions, ParticleOptions)


def _options(path: Path, table: object, cls: type[_Options], name: str) -> _Options:
    """A [reactive] or [particle] table as its options dataclass, checked."""
    if not isinstance(table, dict):
        raise StudyError(f"study {path}: [{name}] must be a table")
    known = set(cls.__dataclass_fields__)
    unknown = sorted(set(table) - known)
    if unknown:
        raise StudyError(f"study {path}: [{name}] unknown key(s) {unknown}; valid: {sorted(known)}")
    values: dict[str, Any] = {}
    for key, value in table.items():
        if key == "sd_slope" and value == "auto":
            values[key] = "auto"
            continue
        if key in ("corner_ends", "seek"):
            if not isinstance(value, bool):
                raise StudyError(f"study {path}: [{name}] {key}={value!r} must be true or false")
            values[key] = value
            continue
        if key in ("noise_scales", "slope_envelope"):
            if (
                not isinstance(value, list)
                or (not value and key == "noise_scales")
                or not all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0
                    for v in value
                )
            ):
                raise StudyError(f"study {path}: [{name}] {key}={value!r} must be a list of positive factors")
            values[key] = tuple(float(v) for v in value)
            continue
        if key == "stretch_weight":
            if type(value) not in (int, float) or not 0 <= value <= 1:
                raise StudyError(f"study {path}: [{name}] stretch_weight={value!r} must be a probability in [0, 1]")
            values[key] = float(value)
            continue
        if key == "off_scale":
            if type(value) not in (int, float) or not 0 <= value < 1:
                raise StudyError(f"study {path}: [{name}] off_scale={value!r} must be a probability in [0, 1)")
            values[key] = float(value)
            continue
        if key in ("defect_window", "lookalike_slope") and type(value) in (int, float) and value == 0:
            values[key] = 0.0
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0 or not math.isfinite(value):
            raise StudyError(f"study {path}: [{name}] {key}={value!r} must be a positive number")
        if key in ("particles", "check_every", "confirm") and value != int(value):
            raise StudyError(f"study {path}: [{name}] {key}={value!r} must be a whole number")
        values[key] = int(value) if key in ("particles", "check_every", "confirm") else float(value)
    if values.get("temper", 0.5) > 1:
        raise StudyError(f"study {path}: [{name}] temper={values['temper']!r} must be at most 1")
    if values.get("confidence", 0.5) >= 1:
        raise StudyError(f"study {path}: [{name}] confidence={values['confidence']!r} must be below 1")
    if not 2 <= values.get("particles", 2) <= MAX_GRID_POINTS:
        raise StudyError(
            f"study {path}: [{name}] particles={values['particles']!r} must be from 2 to {MAX_GRID_POINTS}"
        )
    return cls(**values)


# ------------------------------------------------------------------ trial
