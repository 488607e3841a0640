"""The serial link to a real rig: the line protocol, the rig over pyserial, the device emulator that
speaks it, the port's lock and the signals that make the rig safe.
"""

from .emulator import Emulator, Faults
from .lockfile import LockHeld, hold_lock
from .protocol import (
    ARM_COMMANDS,
    DAQ_COMMANDS,
    MAX_LINE,
    Reply,
    checksum,
    encode_reply,
    encode_request,
    parse_reply,
    parse_request,
)
from .serial_rig import LineReader, SerialRig, Workspace
from .signals import handling

__all__ = [
    "Emulator",
    "Faults",
    "LockHeld",
    "hold_lock",
    "ARM_COMMANDS",
    "DAQ_COMMANDS",
    "MAX_LINE",
    "Reply",
    "checksum",
    "encode_reply",
    "encode_request",
    "parse_reply",
    "parse_request",
    "LineReader",
    "SerialRig",
    "Workspace",
    "handling",
]
