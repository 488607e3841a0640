"""A world whose part is not its model: local defects, a scale, a part of its own, and a wrist that spikes.

A real part is never exactly its drawing: a burr, a chip, a dent from handling, a weld bead, a speck of
debris, a part made a little large, a part made to an older revision; and a DAQ spikes now and then. A
:class:`WorldChange` says how one simulated world differs from the model the localizer is given:

- **defects**: each a smooth bump (height > 0, outward) or dent (< 0) of ``length`` mm along the
  model's arc, added along the model's outward normal (a spline's or a drawing's) on top of the
  machining error. Its profile is h·cos⁴(π·u/ℓ) for |u| < ℓ/2 (u the arc from its centre): smooth
  to the third derivative, zero with its slope and curvature at both ends, so the defect adds no
  kink of its own; its flanks are concave, its crest a tight convex bend (a 0.3 mm × 4 mm bump turns
  the tangent by ±0.31 rad, its crest's radius 1.4 mm);
- **scale**: the whole part scaled about the model's centroid (a part made large or small);
- **part**: the world's own boundary (a scan of the part against its drawing, registered to it), its
  points tagged with the model's arc of their nearest model point;
- **spikes**: each reading of the wrist's channels, with probability ``spike_rate``, off by
  ``spike_size`` times one raw sample's standard deviation (either sign, on the twist channel, which
  carries the contact's place: at the ``paper`` preset 20 times is about 4 mm of jaw).

A :class:`WorldSpec` (a study's ``[world]`` table, or ``rolltouch simulate --world FILE.toml``) says how
to draw such a change for a trial: how many defects, how high and long, where (near the trial's
start so that the rolling crosses it, or anywhere). :func:`world_part` builds the real part a world's
contact runs on (:class:`sim2d.sampled.SampledPart`); a defect that would make it cross itself is
refused by name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from localizer import Outline, Part, RolltouchError, load_part, polygon_crossing, read_toml

from ._errors import SimError
from .machining import machined_outline, machined_part
from .noise import NoiseModel
from .sampled import SAMPLE_SPACING, SampledPart, model_params, model_sample

__all__ = [
    "Defect",
    "WorldChange",
    "WorldSpec",
    "WORLD_KEYS",
    "PLACES",
    "load_world",
    "world_part",
    "Spikes",
    "outstanding",
    "MAX_WORLD_BYTES",
]

#: Where a defect is put: centred within ``defect_near_mm`` of the trial's start, or anywhere.
PLACES = ("start", "anywhere")
#: The keys of a ``[world]`` table.
WORLD_KEYS = (
    "defects",
    "defect_height_mm",
    "defect_length_mm",
    "defect_place",
    "defect_near_mm",
    "scale",
    "spike_rate",
    "spike_size",
    "world_parts",
)
#: The largest world file read, bytes (a world is a few lines of TOML).
MAX_WORLD_BYTES = 2**16
#: The most defects one world draws.
MAX_DEFECTS = 100
#: The scale factors a world may take (a part 20% off its drawing is another part: give it as a file).
SCALE_RANGE = (0.8, 1.25)


@dataclass(frozen=True)
class Defect:
    """A smooth bump or dent on the real part (module notes).

    Attributes
    ----------
    arc : float, mm
        The model's arc position of its centre.
    height : float, mm
        Along the model's outward normal at its crest: a bump > 0, a dent < 0.
    length : float, mm
        Its extent along the model's arc.
    """

    arc: float
    height: float
    length: float

    def offset(self, sigma: np.ndarray, perimeter: float) -> np.ndarray:
        """The normal offset (mm) it adds at the model's arc positions ``sigma`` (mm) on a part of ``perimeter``
        mm."""
        u = (np.asarray(sigma, dtype=float) - self.arc + perimeter / 2) % perimeter - perimeter / 2
        inside = np.abs(u) < self.length / 2
        out: np.ndarray = np.where(inside, self.height * np.cos(math.pi * u / self.length) ** 4, 0.0)
        return out

    def describe(self) -> str:
        """One line for people: "a 0.3 mm bump 4 mm long at arc 120.00 mm"."""
        kind = "bump" if self.height > 0 else "dent"
        return f"a {abs(self.height):.3g} mm {kind} {self.length:.3g} mm long at arc {self.arc:.2f} mm"


@dataclass(frozen=True)
class WorldChange:
    """How one world's part and wrist differ from the model (module notes).

    Attributes
    ----------
    defects : tuple of Defect
    scale : float
        The real part's size over the model's, about the model's centroid.
    part : Part, Outline or None
        The world's own boundary, registered to the model (a scan against its drawing); with it,
        ``defects`` must be empty and ``scale`` 1 (they belong in its file).
    spike_rate : float
        Probability that a reading of the wrist is a spike.
    spike_size : float
        A spike's size, in standard deviations of one raw sample of the twist channel.
    """

    defects: tuple[Defect, ...] = ()
    scale: float = 1.0
    part: Part | Outline | None = field(default=None, compare=False)
    spike_rate: float = 0.0
    spike_size: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.scale) and SCALE_RANGE[0] <= self.scale <= SCALE_RANGE[1]):
            raise SimError(f"world scale={self.scale!r} must be within {SCALE_RANGE} (a part of its own: world_parts)")
        if not (math.isfinite(self.spike_rate) and 0 <= self.spike_rate <= 1):
            raise SimError(f"world spike_rate={self.spike_rate!r} must be a probability per reading in [0, 1]")
        if not (math.isfinite(self.spike_size) and self.spike_size >= 0):
            raise SimError(f"world spike_size={self.spike_size!r} must be ≥ 0 (raw samples' standard deviations)")
        for d in self.defects:
            if not (math.isfinite(d.arc) and math.isfinite(d.height) and math.isfinite(d.length) and d.length > 0):
                raise SimError(f"defect {d!r}: its arc, height and length must be finite, its length positive")
            if abs(d.height) > d.length:
                raise SimError(
                    f"defect {d.describe()}: higher than it is long is not a burr or a dent; "
                    "give the world's part as a file instead"
                )
        if self.part is not None and (self.defects or self.scale != 1.0):
            raise SimError("a world with a part of its own takes no defects or scale: put them in its file")

    @property
    def shape_differs(self) -> bool:
        """Whether the real part differs from the model beyond its machining."""
        return bool(self.defects) or self.scale != 1.0 or self.part is not None

    @property
    def differs(self) -> bool:
        """Whether anything differs from the model (the part, or the wrist's spikes)."""
        return self.shape_differs or (self.spike_rate > 0 and self.spike_size > 0)

    def describe(self) -> str:
        """One line for people: what differs."""
        bits = [d.describe() for d in self.defects]
        if self.scale != 1.0:
            bits.append(f"scaled {self.scale:g}")
        if self.part is not None:
            bits.append(f"the part {self.part.name}")
        if self.spike_rate > 0 and self.spike_size > 0:
            bits.append(f"spikes of {self.spike_size:g} σ at {self.spike_rate:g} per reading")
        return "; ".join(bits) if bits else "the model"


@dataclass(frozen=True)
class WorldSpec:
    """How to draw a trial's :class:`WorldChange`: a study's ``[world]`` table (module notes).

    Attributes
    ----------
    defects : int
        Defects per world.
    defect_height_mm : float or (float, float)
        Signed height (bump > 0, dent < 0), or the range of a magnitude drawn uniformly with a random sign.
    defect_length_mm : float or (float, float)
        Each defect's extent along the arc, or the range of one drawn uniformly.
    defect_place : {"start", "anywhere"}
        Centred uniformly within ``defect_near_mm`` of the trial's start (so that the rolling crosses
        it), or uniformly over the boundary.
    defect_near_mm : float
    scale : float
    spike_rate, spike_size : float
        See :class:`WorldChange`.
    world_parts : tuple of str
        The world's part for each of the study's parts, in order (files; empty: the model).
    """

    defects: int = 0
    defect_height_mm: float | tuple[float, float] = 0.3
    defect_length_mm: float | tuple[float, float] = 4.0
    defect_place: str = "start"
    defect_near_mm: float = 5.0
    scale: float = 1.0
    spike_rate: float = 0.0
    spike_size: float = 20.0
    world_parts: tuple[str, ...] = ()

    @property
    def differs(self) -> bool:
        """Whether the worlds it draws differ from the model."""
        return self.defects > 0 or self.scale != 1.0 or bool(self.world_parts) or self.spike_rate > 0

    @classmethod
    def from_table(cls, table: object, source: str, here: Path | None = None, parts: int | None = None) -> WorldSpec:
        """A ``[world]`` table, checked: unknown keys and bad values are refused by name.

        Parameters
        ----------
        table : dict
        source : str
            What to call it in messages (the file).
        here : Path, optional
            The folder relative ``world_parts`` are resolved against.
        parts : int, optional
            How many model parts the study has (``world_parts`` must be as long).
        """
        if not isinstance(table, dict):
            raise SimError(f"{source}: [world] must be a table with keys {list(WORLD_KEYS)}")
        unknown = sorted(set(table) - set(WORLD_KEYS))
        if unknown:
            raise SimError(f"{source}: [world] unknown key(s) {unknown}; valid: {list(WORLD_KEYS)}")
        values: dict = {}
        n = table.get("defects", 0)
        if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= MAX_DEFECTS:
            raise SimError(f"{source}: [world] defects={n!r} must be a whole number from 0 to {MAX_DEFECTS}")
        values["defects"] = n
        h = table.get("defect_height_mm", cls.defect_height_mm)
        if isinstance(h, list):
            if len(h) != 2 or not all(_number(v) and v >= 0 for v in h) or h[0] > h[1] or h[1] == 0:
                raise SimError(
                    f"{source}: [world] defect_height_mm={h!r}: a range is [lowest, highest] magnitudes, mm, "
                    "0 ≤ lowest ≤ highest, highest > 0 (the sign is drawn)"
                )
            values["defect_height_mm"] = (float(h[0]), float(h[1]))
        elif not _number(h) or h == 0:
            raise SimError(
                f"{source}: [world] defect_height_mm={h!r} must be a nonzero number of mm (bump > 0, dent < 0) "
                "or a [lowest, highest] range of magnitudes"
            )
        else:
            values["defect_height_mm"] = float(h)
        length = table.get("defect_length_mm", cls.defect_length_mm)
        if isinstance(length, list):
            if len(length) != 2 or not all(_number(v) and v > 0 for v in length) or length[0] > length[1]:
                raise SimError(
                    f"{source}: [world] defect_length_mm={length!r}: a range is [shortest, longest], mm, both positive"
                )
            values["defect_length_mm"] = (float(length[0]), float(length[1]))
        for key in ("defect_length_mm", "defect_near_mm", "scale", "spike_size"):
            if key == "defect_length_mm" and isinstance(length, list):
                continue
            if key in table:
                v = table[key]
                if not _number(v) or v < 0 or (v == 0 and key in ("defect_length_mm", "scale")):
                    raise SimError(f"{source}: [world] {key}={v!r} must be a positive number")
                values[key] = float(v)
        scale = values.get("scale", 1.0)
        if not SCALE_RANGE[0] <= scale <= SCALE_RANGE[1]:
            raise SimError(
                f"{source}: [world] scale={scale!r} must be within {SCALE_RANGE}; a part further off its "
                "model is another part: give it in world_parts"
            )
        if "spike_rate" in table:
            v = table["spike_rate"]
            if not _number(v) or not 0 <= v <= 1:
                raise SimError(f"{source}: [world] spike_rate={v!r} must be a probability per reading in [0, 1]")
            values["spike_rate"] = float(v)
        place = table.get("defect_place", cls.defect_place)
        if place not in PLACES:
            raise SimError(f"{source}: [world] defect_place={place!r}; use one of {list(PLACES)}")
        values["defect_place"] = place
        files = table.get("world_parts", [])
        if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
            raise SimError(f"{source}: [world] world_parts must be a list of part files")
        if files:
            if parts is not None and len(files) != parts:
                raise SimError(
                    f"{source}: [world] world_parts has {len(files)} file(s) for {parts} part(s): give one world "
                    "part per model part, in the same order"
                )
            if n or scale != 1.0:
                raise SimError(f"{source}: [world] world_parts takes no defects or scale: put them in the files")
            resolved = []
            for f in files:
                q = Path(f)
                q = q if q.is_absolute() or here is None else (here / q).resolve()
                try:
                    load_part(q)
                except RolltouchError as exc:
                    raise SimError(f"{source}: [world] world_parts: {exc}") from None
                resolved.append(str(q))
            values["world_parts"] = tuple(resolved)
        return cls(**values)

    def draw(self, model: Part | Outline, start: float, rng: np.random.Generator, part_index: int = 0) -> WorldChange:
        """One world for a trial on ``model`` whose rolling starts at arc ``start`` (mm), its draws from
        ``rng``; ``part_index`` picks the world part of the study's part."""
        P = float(model.perimeter)
        defects = []
        for _ in range(self.defects):
            span = self.defect_length_mm
            length = min(float(rng.uniform(*span)) if isinstance(span, tuple) else float(span), P / 4)
            if self.defect_place == "start":
                centre = start + float(rng.uniform(-self.defect_near_mm, self.defect_near_mm))
            else:
                centre = float(rng.uniform(0.0, P))
            h = self.defect_height_mm
            if isinstance(h, tuple):
                height = float(rng.uniform(h[0], h[1])) * (1.0 if rng.uniform() < 0.5 else -1.0)
                if height == 0.0:
                    height = h[1]
            else:
                height = float(h)
            defects.append(Defect(float(centre % P), height, float(length)))
        part = load_part(self.world_parts[part_index]) if self.world_parts else None
        return WorldChange(
            defects=tuple(defects),
            scale=self.scale,
            part=part,
            spike_rate=self.spike_rate,
            spike_size=self.spike_size if self.spike_rate > 0 else 0.0,
        )


def _number(v: object) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def load_world(path: str | Path, parts: int | None = None) -> WorldSpec:
    """The ``[world]`` table of the TOML file at ``path`` (module notes), for a study of ``parts`` model
    parts (``world_parts`` must be as long; None: not checked).

    Raises
    ------
    SimError
        Unreadable or invalid TOML, no ``[world]`` table, unknown keys, bad values.
    """
    path = Path(path)
    data = read_toml(path, MAX_WORLD_BYTES, "world file", SimError)
    if set(data) != {"world"}:
        raise SimError(f"world file {path}: give one [world] table (found {sorted(data) or 'nothing'})")
    return WorldSpec.from_table(data["world"], f"world file {path}", path.resolve().parent, parts)


def world_part(
    model: Part | Outline,
    change: WorldChange,
    noise: NoiseModel,
    rng: np.random.Generator,
    spacing: float = SAMPLE_SPACING,
) -> Part | SampledPart:
    """The real part of a world: the ``model`` machined under ``noise`` (its harmonics drawn from ``rng``,
    the same draws as without the change), then ``change``'s defects and scale, or ``change``'s own part.

    Returns the machined spline itself (a :class:`Part` of the model's knots) where the shape does not
    differ from a spline model's beyond machining; else a :class:`SampledPart` every ``spacing`` mm.

    Raises
    ------
    SimError
        A defect or scale that makes the part cross itself (the defect named, and where).
    """
    P = float(model.perimeter)

    def defects(arcs: np.ndarray) -> np.ndarray:
        offset = np.zeros(np.shape(arcs))
        for d in change.defects:
            offset += d.offset(arcs, P)
        return offset

    moved = change.shape_differs and change.part is None and bool(change.defects)
    machined: Part | SampledPart = (
        machined_outline(model, noise, rng, spacing, defects if moved else None)
        if isinstance(model, Outline)
        else machined_part(model, noise, rng)
    )
    if not change.shape_differs:
        return machined
    if change.part is not None:
        return _registered(model, change.part, spacing)
    if isinstance(machined, SampledPart):
        arcs, xy = machined.arcs, machined.xy
    else:
        assert isinstance(model, Part)
        arcs, _, normal = model_sample(model, spacing)
        xy = np.asarray(machined.point(model_params(model, spacing)), dtype=float) + defects(arcs)[:, None] * normal
    if change.scale != 1.0:
        centre = _centroid(np.asarray(model_sample(model, max(spacing, P / 4000))[1]))
        xy = centre + change.scale * (xy - centre)
    label = change.describe()
    # does the change make the part cross itself? (its pieces' ends at a drawing's corners are joined as a
    # real part's, so what crosses is the change: a dent deeper than the part is thick, two bumps that meet)
    crossing = polygon_crossing(np.vstack([xy, xy[:1]]))
    if crossing is not None:
        where = xy[crossing[0]]
        raise SimError(
            f"{model.name} with {label} crosses itself near ({where[0]:.3f}, {where[1]:.3f}) mm, "
            f"arc {arcs[crossing[0]]:.2f} mm: make the defect smaller or longer, or move it"
        )
    return SampledPart(model, arcs, xy, label, altered=True)


def _centroid(xy: np.ndarray) -> np.ndarray:
    """The area centroid of the closed polygon ``xy`` (mm)."""
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2
    return np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6 * area)


def _registered(model: Part | Outline, world: Part | Outline, spacing: float) -> SampledPart:
    """``world``'s boundary every ``spacing`` mm, each point tagged with the model's arc of its nearest model
    point (the two registered in one frame: a scan against its drawing)."""
    from scipy.spatial import cKDTree

    _, xy, _ = model_sample(world, spacing)
    m_arcs, m_xy, _ = model_sample(model, spacing)
    _, k = cKDTree(m_xy).query(xy)
    n = m_xy.shape[0]
    P = float(model.perimeter)
    best_d = np.full(xy.shape[0], np.inf)
    best_arc = m_arcs[k].copy()
    for j in (k - 1, k):  # the two model chords at the nearest model point
        j = j % n
        a, b = m_xy[j], m_xy[(j + 1) % n]
        ab = b - a
        u = np.clip(np.einsum("ij,ij->i", xy - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
        d = np.hypot(*(xy - (a + u[:, None] * ab)).T)
        a0, a1 = m_arcs[j], m_arcs[(j + 1) % n]
        da = (a1 - a0 + P / 2) % P - P / 2
        better = d < best_d
        best_d = np.where(better, d, best_d)
        best_arc = np.where(better, (a0 + u * da) % P, best_arc)
    # the sample starts at the world's first point: start it where the model's arcs wrap, so they increase
    first = int(np.argmin(best_arc))
    return SampledPart(
        model, np.roll(best_arc, -first), np.roll(xy, -first, axis=0), f"the part {world.name}", altered=True
    )


class Spikes:
    """The spikes of a world's wrist: each reading, with probability ``change.spike_rate``, is off by
    ``change.spike_size`` times ``sd`` (V: one raw sample's standard deviation), either sign.

    Drawn from a stream of their own (seeded by the rig's ``seed``), so that the rest of the rig's noise
    is the same with spikes as without.

    Attributes
    ----------
    count : int
        Readings spiked so far.
    """

    def __init__(self, change: WorldChange, sd: float, seed: int) -> None:
        self.rate, self.size = float(change.spike_rate), float(change.spike_size) * float(sd)
        self._rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, 0x5B1E])
        self.count = 0

    def __call__(self) -> float:
        """This reading's spike, V (0 for most)."""
        if self.rate <= 0 or self.size <= 0 or self._rng.uniform() >= self.rate:
            return 0.0
        self.count += 1
        return self.size if self._rng.uniform() < 0.5 else -self.size


def outstanding(model: Part | Outline, real: Part | SampledPart, arc: float) -> float:
    """How far the real part stands out of its model along the model's outward normal at ``arc`` (mm; 0
    where the real part is the model machined, whose microns a rig's standoffs allow for): an operator
    jogs the jaw clear of what is there (a part made large, a burr under the start)."""
    if not (isinstance(real, SampledPart) and real.altered):
        return 0.0
    k = int(np.argmin(np.abs(np.asarray(model.arc_offset(real.arcs, arc)))))
    theta = float(model.tangent_angle_at_arc(arc))
    normal = np.array([math.sin(theta), -math.cos(theta)])
    return float((real.xy[k] - np.asarray(model.point_at_arc(arc), dtype=float)) @ normal)
