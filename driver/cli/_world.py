"""The simulated world a run rolls on when it is not the model as machined: ``--world`` and
``--world-part``, and what the run's JSON and trace say of it."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

import numpy as np

from ._options import UsageError

if TYPE_CHECKING:
    from localizer import Outline, Part
    from sim2d import SimRig, WheelRig, WorldChange

__all__ = ["world_change", "world_fields"]


def world_change(args: argparse.Namespace, part: Part | Outline) -> WorldChange | None:
    """The world ``--world`` or ``--world-part`` describes for this run (None: the model as machined)."""
    from localizer import load_part
    from sim2d import WorldChange, load_world

    if getattr(args, "world_part", None):
        return WorldChange(part=load_part(args.world_part))
    if getattr(args, "world", None):
        spec = load_world(args.world)
        if spec.world_parts:
            raise UsageError(f"--world {args.world}: world_parts is a study's; give one part with --world-part")
        return spec.draw(part, float(args.start), np.random.default_rng([int(args.seed) & 0xFFFFFFFF, 2]))
    return None


def world_fields(change: WorldChange | None, rig: SimRig | WheelRig) -> dict[str, Any]:
    """How the simulated world differed from its model, for a trace's metadata and the JSON output."""
    if change is None:
        return {}
    return {
        "world": {
            "describe": change.describe(),
            "defects": [{"arc": d.arc, "height_mm": d.height, "length_mm": d.length} for d in change.defects],
            "scale": change.scale,
            "part": None if change.part is None else change.part.name,
            "spikes": rig.spikes.count,
        }
    }
