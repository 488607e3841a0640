"""The simulated rig: instruments, noise model, worlds and ``SimRig`` (depends on localizer)."""

from ._errors import SimError
from .machining import machined_part, machining_slope
from .noise import PRESETS, NoiseModel, load_noise
from .rig import SimRig
from .sampled import SampledPart
from .wheel_rig import WheelRig
from .wheel_world import WheelContact, WheelWorld
from .world import Contact, World
from .world_part import Defect, WorldChange, WorldSpec, load_world, world_part
from .wrist import Wrist, encoder_angle

__all__ = [
    "SimError",
    "NoiseModel",
    "PRESETS",
    "load_noise",
    "SimRig",
    "WheelRig",
    "WheelWorld",
    "WheelContact",
    "Wrist",
    "encoder_angle",
    "machined_part",
    "machining_slope",
    "World",
    "Contact",
    "SampledPart",
    "Defect",
    "WorldChange",
    "WorldSpec",
    "load_world",
    "world_part",
]
