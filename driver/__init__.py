"""The rig protocol every rig keeps, and its rooms: the straight jaw (``jaw``), the wheel finger
(``wheel``), the serial rig (``link``), what a run leaves (``records``) and the command line (``cli``)."""

from .blas import one_blas_thread
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
from .warmup import compile_kernels

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
    "one_blas_thread",
    "compile_kernels",
]
