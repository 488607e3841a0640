"""The pymunk planar world and its simulated instruments (issue 4; depends on localizer)."""
