"""Rig protocol, procedures, pipeline, serial rig and the command line (depends on localizer)."""

from .rig import ProtocolError, Rig, RigError

__all__ = ["Rig", "RigError", "ProtocolError"]
