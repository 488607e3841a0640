"""Time-domain passivity observer and controller (Hannaford–Ryu), with the low-velocity fixes of
Ryu et al. (2005). Control, not estimation: used by the simulated haptic model (sim2d) and the
guarded force servo (sim2d's rig, driver), so it sits beside ``localizer``, below both.

It is named ``passivity``, not ``control``: python-control, which a control researcher may well
have installed, owns the top-level name ``control``.
"""

from ._controller import ControlError, PassivityController, PassivityStep

__all__ = ["PassivityController", "PassivityStep", "ControlError"]
