"""Monte Carlo study files (TOML) and the trial they describe.

A study file::

    name = "paper"                       # optional, for plots
    parts = ["../../parts/trefoil.json"] # relative to the study file (or absolute)
    rolls_deg = [20.0, 15.0]             # one localization = these rolls, all one way
    step_deg = 0.2                       # rolling step
    method = "paper"                     # "paper" or "likelihood" (the localizer's rule)
    engine = "kinematic"                 # or "pymunk"
    trials = 200                         # per level
    seed = 2005
    success_radius = 0.3                 # mm
    noise = "paper"                      # preset or a TOML file (relative to the study file)

    [sweep]                              # optional: one noise-model field over levels
    parameter = "v2_noise"
    values = [0.0, 0.0003, 0.0006, 0.0012]

    [likelihood]                         # optional: the standard deviations told to the
    sd_length = 0.3                      # likelihood rule (mm, degrees)
    sd_turn_deg = 0.03

Several methods on the same trials (instead of ``method``)::

    methods = ["paper", "particle", "reactive"]   # first one fills success/error_mm

    [reactive]                           # the sequential filter (driver.reactive)
    confidence = 0.95
    max_rotation_deg = 180.0
    sd_position = 0.04                   # mm, one contact-location reading
    sd_scale = 0.003                     # calibration scale
    sd_slope = 0.003                     # rad, the part's slope error ("auto": from the noise model)

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
``numpy.random.SeedSequence([seed, level, trial])``.
"""

from __future__ import annotations

import math
import time
import tomllib
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

__all__ = ["Study", "StudyError", "load_study", "run_trial", "TRIAL_COLUMNS"]

#: Columns of trials.csv, in order.
TRIAL_COLUMNS = ("level", "trial", "parameter", "value", "part", "start_arc", "true_arc", "estimate_arc",
                 "error_mm", "success", "candidates", "probability", "ambiguous", "lengths", "turns",
                 "restarts", "time_s", "failure")

_KEYS = {"name", "parts", "rolls_deg", "step_deg", "method", "methods", "engine", "trials", "seed",
         "success_radius", "noise", "sweep", "likelihood", "reactive", "particle"}
METHODS = ("paper", "likelihood", "particle", "grid", "reactive")
#: Per-method columns of trials.csv for a study with ``methods``, after TRIAL_COLUMNS.
METHOD_COLUMNS = ("success", "error_mm", "estimate_arc", "rotation_deg", "curve")


@dataclass(frozen=True)
class ReactiveOptions:
    """[reactive] of a study file (see :func:`driver.reactive.localize_reactively`)."""

    confidence: float = 0.95
    max_rotation_deg: float = 180.0
    check_every: int = 5
    sd_position: float = 0.04
    sd_scale: float = 0.003
    sd_slope: float | None = None   # None: "auto"
    min_spread: float = 0.05


@dataclass(frozen=True)
class ParticleOptions:
    """[particle] of a study file (see :class:`localizer.ParticleFilter`)."""

    particles: int = 2000
    sd_position: float = 0.04
    process: float = 0.005


class StudyError(ValueError):
    """A study file that cannot be run; the message names the key and what is wrong."""


@dataclass(frozen=True)
class Study:
    """A parsed study (see the module notes for the file format)."""

    name: str
    parts: tuple
    rolls_deg: tuple
    step_deg: float = 0.2
    method: str = "paper"
    engine: str = "kinematic"
    trials: int = 100
    seed: int = 0
    success_radius: float = 0.3
    noise: str = "paper"
    parameter: str | None = None
    values: tuple = ()
    sd_length: float = 0.3
    sd_turn_deg: float = 0.03
    source: str = ""
    methods: tuple = ()
    reactive: ReactiveOptions = ReactiveOptions()
    particle: ParticleOptions = ParticleOptions()

    @property
    def columns(self) -> tuple:
        """The columns of this study's trials.csv."""
        extra = tuple(f"{m}_{c}" for m in self.methods for c in METHOD_COLUMNS) if self.methods else ()
        return TRIAL_COLUMNS + extra

    @property
    def levels(self) -> int:
        return max(1, len(self.values))

    def level_value(self, level: int):
        return self.values[level] if self.values else None

    def with_overrides(self, *, trials=None, engine=None) -> "Study":
        s = self
        if trials is not None:
            if int(trials) < 1:
                raise StudyError(f"--trials {trials} must be at least 1")
            s = replace(s, trials=int(trials))
        if engine is not None:
            if engine not in ("kinematic", "pymunk"):
                raise StudyError(f"--engine {engine!r}: use kinematic or pymunk")
            s = replace(s, engine=engine)
        return s

    def as_dict(self) -> dict:
        return asdict(self)


def load_study(path) -> Study:
    """Read and check a study file.

    Raises
    ------
    StudyError
        Unreadable or invalid TOML, unknown keys, missing parts, bad values.
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except OSError as exc:
        raise StudyError(f"study {path}: cannot read ({exc.strerror or exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise StudyError(f"study {path}: not valid TOML ({exc})") from None
    unknown = sorted(set(data) - _KEYS)
    if unknown:
        raise StudyError(f"study {path}: unknown key(s) {unknown}; valid keys: {sorted(_KEYS)}")
    here = path.resolve().parent

    def resolve(p):
        q = Path(p)
        return str(q if q.is_absolute() else (here / q).resolve())

    parts = data.get("parts")
    if not isinstance(parts, list) or not parts or not all(isinstance(p, str) for p in parts):
        raise StudyError(f"study {path}: 'parts' must be a non-empty list of part files")
    parts = [resolve(p) for p in parts]
    for p in parts:
        if not Path(p).is_file():
            raise StudyError(f"study {path}: part file {p} does not exist")
    rolls = data.get("rolls_deg")
    if (not isinstance(rolls, list) or not rolls or not all(isinstance(r, (int, float)) and r != 0 for r in rolls)
            or len({r > 0 for r in rolls}) != 1):
        raise StudyError(f"study {path}: 'rolls_deg' must be a non-empty list of nonzero angles of one sign, "
                         f"got {rolls!r}")
    method = data.get("method", "paper")
    if method not in ("paper", "likelihood"):
        raise StudyError(f"study {path}: method {method!r}; use 'paper' or 'likelihood'")
    methods = data.get("methods", [])
    if (not isinstance(methods, list) or not all(m in METHODS for m in methods)
            or len(set(methods)) != len(methods)):
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
        if not isinstance(v, int) or v < lo:
            raise StudyError(f"study {path}: {key}={v!r} must be an integer >= {lo}")
    for key, default in (("step_deg", 0.2), ("success_radius", 0.3)):
        v = data.get(key, default)
        if not isinstance(v, (int, float)) or not v > 0:
            raise StudyError(f"study {path}: {key}={v!r} must be a positive number")
    noise = data.get("noise", "paper")
    from sim2d import PRESETS, NoiseModel, SimError, load_noise

    if noise not in PRESETS:
        noise = resolve(noise)
    try:
        base = load_noise(noise)
    except SimError as exc:
        raise StudyError(f"study {path}: noise: {exc}") from None
    parameter, values = None, ()
    sweep = data.get("sweep")
    if sweep is not None:
        if not isinstance(sweep, dict) or set(sweep) - {"parameter", "values"}:
            raise StudyError(f"study {path}: [sweep] takes 'parameter' and 'values'")
        parameter = sweep.get("parameter")
        if parameter not in NoiseModel.__dataclass_fields__:
            raise StudyError(f"study {path}: sweep parameter {parameter!r} is not a noise-model field; "
                             f"fields: {sorted(NoiseModel.__dataclass_fields__)}")
        values = sweep.get("values")
        if not isinstance(values, list) or not values:
            raise StudyError(f"study {path}: sweep values must be a non-empty list")
        for v in values:
            try:
                replace(base, **{parameter: v})
            except (SimError, TypeError) as exc:
                raise StudyError(f"study {path}: sweep value {v!r} of {parameter}: {exc}") from None
        values = tuple(float(v) for v in values)
    lk = data.get("likelihood", {})
    if not isinstance(lk, dict) or set(lk) - {"sd_length", "sd_turn_deg"}:
        raise StudyError(f"study {path}: [likelihood] takes 'sd_length' and 'sd_turn_deg'")
    return Study(name=str(data.get("name", path.stem)), parts=tuple(parts), rolls_deg=tuple(float(r) for r in rolls),
                 step_deg=float(data.get("step_deg", 0.2)), method=method, engine=engine,
                 trials=int(data.get("trials", 100)), seed=int(data.get("seed", 0)),
                 success_radius=float(data.get("success_radius", 0.3)), noise=str(noise), parameter=parameter,
                 values=values, sd_length=float(lk.get("sd_length", 0.3)),
                 sd_turn_deg=float(lk.get("sd_turn_deg", 0.03)), source=str(path), methods=tuple(methods),
                 reactive=reactive, particle=particle)


def _options(path, table, cls, name):
    """A [reactive] or [particle] table as its options dataclass, checked."""
    if not isinstance(table, dict):
        raise StudyError(f"study {path}: [{name}] must be a table")
    known = set(cls.__dataclass_fields__)
    unknown = sorted(set(table) - known)
    if unknown:
        raise StudyError(f"study {path}: [{name}] unknown key(s) {unknown}; valid: {sorted(known)}")
    values = {}
    for key, value in table.items():
        if key == "sd_slope" and value == "auto":
            values[key] = None
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0 or not math.isfinite(value):
            raise StudyError(f"study {path}: [{name}] {key}={value!r} must be a positive number")
        values[key] = int(value) if key in ("particles", "check_every") else float(value)
    if values.get("confidence", 0.5) >= 1:
        raise StudyError(f"study {path}: [{name}] confidence={values['confidence']!r} must be below 1")
    if values.get("particles", 2) < 2:
        raise StudyError(f"study {path}: [{name}] particles={values['particles']!r} must be at least 2")
    return cls(**values)


# ------------------------------------------------------------------ trial
@dataclass(frozen=True)
class TrialSpec:
    """Everything one trial needs (picklable, sent to worker processes)."""

    study: Study
    level: int
    trial: int
    extra: dict = field(default_factory=dict)


_PART_CACHE: dict = {}


def _part(path):
    from localizer import load_part

    if path not in _PART_CACHE:
        _PART_CACHE[path] = load_part(path)
    return _PART_CACHE[path]


def run_trial(spec: TrialSpec) -> dict:
    """One simulated localization: calibrate, pick a start, roll, localize, score. Never raises.

    The start is drawn uniformly over the perimeter; a start where the pipeline
    refuses to roll (not on the convex hull, or a roll would bridge a
    concavity) is redrawn, up to 20 times (``restarts``). With ``methods``, every
    method is scored on that same trial (module notes).
    """
    import math as _m

    from driver.procedures import calibrate, localize_by_rolling
    from driver.rig import RigError
    from sim2d import SimRig, load_noise

    s = spec.study
    t0 = time.perf_counter()
    rng = np.random.default_rng(np.random.SeedSequence([s.seed, spec.level, spec.trial]))
    part_file = s.parts[int(rng.integers(len(s.parts)))]
    part = _part(part_file)
    noise = load_noise(s.noise)
    value = s.level_value(spec.level)
    if s.parameter is not None:
        noise = replace(noise, **{s.parameter: value})
    row = {"level": spec.level, "trial": spec.trial, "parameter": s.parameter or "", "value": value,
           "part": Path(part_file).name}
    rolls = [_m.radians(r) for r in s.rolls_deg]
    rule = s.method if s.method in ("paper", "likelihood") else "paper"
    try:
        t = np.linspace(0, part.n_knots, 20 * part.n_knots, endpoint=False)
        cal_arc = float(part.arc_at_param(t[np.argmax(part.curvature(t))]))
        cal_rig = SimRig(part, noise=noise, seed=int(rng.integers(1 << 31)), engine=s.engine)
        cal = calibrate(cal_rig, cal_rig.approach_pose(cal_arc, jaw_position=0.0, standoff=1.0))
        run = None
        for restarts in range(20):
            start = float(rng.uniform(0, part.perimeter))
            rig_seed = int(rng.integers(1 << 31))
            rig = SimRig(part, noise=noise, seed=rig_seed, engine=s.engine)
            try:
                run = localize_by_rolling(
                    rig, part, rolls, calibration=cal, step=_m.radians(s.step_deg), rule=rule,
                    sd_length=s.sd_length, sd_turn=_m.radians(s.sd_turn_deg),
                    approach_pose=rig.approach_pose(start, jaw_position=-40.0 if rolls[0] > 0 else 40.0,
                                                    standoff=1.0))
            except RigError:
                continue
            first = run.rolls[0].truth[0][0]
            if abs(float(part.arc_offset(first, start))) > 1.0:  # laid off the hull
                run = None
                continue
            break
        if run is None:
            raise RigError("no start out of 20 let the rolls run (a part with little convex hull?)")
        true_arc = rig.truth()["contact_arc"]
        best = run.localization.best
        est = best.end_arc if best is not None else math.nan
        err = abs(float(part.arc_offset(est, true_arc))) if best is not None else math.inf
        row.update({"start_arc": start, "true_arc": true_arc, "estimate_arc": est, "error_mm": err,
                    "success": int(err < s.success_radius), "candidates": len(run.localization.candidates),
                    "probability": best.probability if best is not None else 0.0,
                    "ambiguous": int(run.localization.ambiguous),
                    "lengths": " ".join(f"{L:.6f}" for L, _ in run.estimates),
                    "turns": " ".join(f"{w:.8f}" for _, w in run.estimates),
                    "restarts": restarts, "failure": ""})
        if s.methods:
            from .methods import score_methods

            row.update(score_methods(s, part, noise, cal, run, start, rig_seed, true_arc))
            first_method = s.methods[0]
            for key in ("success", "error_mm", "estimate_arc"):
                row[key] = row[f"{first_method}_{key}"]
    except Exception as exc:  # a trial that breaks is a recorded failure, not a lost study
        row.update({"start_arc": math.nan, "true_arc": math.nan, "estimate_arc": math.nan, "error_mm": math.inf,
                    "success": 0, "candidates": 0, "probability": 0.0, "ambiguous": 0, "lengths": "",
                    "turns": "", "restarts": 0, "failure": f"{type(exc).__name__}: {exc}"[:200]})
        for m in s.methods:
            row.update({f"{m}_success": 0, f"{m}_error_mm": math.inf, f"{m}_estimate_arc": math.nan,
                        f"{m}_rotation_deg": math.nan, f"{m}_curve": ""})
    row["time_s"] = time.perf_counter() - t0
    return row
