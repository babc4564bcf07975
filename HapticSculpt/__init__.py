"""HapticSculpt: sculpt dynamic B-spline surfaces in FreeCAD (Dachille, Qin, Kaufman, El-Sana).

The dynamics core is :mod:`HapticSculpt.core`; the scripting API below imports FreeCAD only when a
function that needs it is called, so importing this package never imports FreeCAD or a GUI.
"""
__version__ = "0.1.0"

from .api import (RunReport, add_constraint, export_step, keep_shape, make_sculpt, material_of, paint,
                  remove_constraint, run, set_curvature_target, set_material, set_tool, set_uniform, thicken,
                  to_cadquery)
from .replay_device import CursorSample, ReplayDevice
from .session import Session, stop_all

__all__ = ["make_sculpt", "run", "add_constraint", "remove_constraint", "set_material", "material_of", "keep_shape",
           "set_tool", "set_uniform", "set_curvature_target", "paint",
           "export_step", "thicken",
           "to_cadquery", "ReplayDevice", "CursorSample", "RunReport", "Session", "stop_all", "__version__"]
