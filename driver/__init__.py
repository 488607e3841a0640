"""Rig protocol, procedures, pipeline, serial rig and the command line (depends on localizer)."""

__all__: list[str] = []
