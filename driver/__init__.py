"""Rig protocol, procedures, pipeline, serial rig and the command line (depends on localizer)."""

from .records import PartMismatch, check_same_part, part_record
from .rig import (
    Clocked,
    ForceServo,
    GroundTruth,
    ImplausibleReading,
    Pose,
    ProtocolError,
    Reading,
    Rig,
    RigError,
    SampleLog,
    TransportError,
    Truth,
)

__all__ = [
    "Rig",
    "ForceServo",
    "Clocked",
    "GroundTruth",
    "SampleLog",
    "Pose",
    "Reading",
    "Truth",
    "RigError",
    "ProtocolError",
    "TransportError",
    "ImplausibleReading",
    "PartMismatch",
    "part_record",
    "check_same_part",
]
