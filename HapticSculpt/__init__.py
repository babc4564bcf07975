"""HapticSculpt: sculpt dynamic B-spline surfaces in FreeCAD (Dachille, Qin, Kaufman, El-Sana).

Layers, each importing only those before it: :mod:`HapticSculpt.core` (the C++ dynamics core),
:mod:`HapticSculpt.app` (the document layer and the scripting API), :mod:`HapticSculpt.runtime`
(threaded sessions and devices) and :mod:`HapticSculpt.gui` (the workbench, imported only while
FreeCAD's GUI runs). The scripting API below imports FreeCAD only when a function that needs it is
called, so importing this package never imports FreeCAD or a GUI.
"""
from . import legacy_paths
from .app.api import (
                      CursorSource,
                      RunReport,
                      add_constraint,
                      export_step,
                      held_boundary,
                      hold_boundary,
                      fair,
                      keep_shape,
                      make_sculpt,
                      make_thickness,
                      material_of,
                      paint,
                      record_state,
                      remove_constraint,
                      replay_stroke,
                      run,
                      set_curvature_target,
                      set_material, set_regional,
                      set_tool,
                      set_uniform, scale_map,
                      thicken,
                      to_cadquery,
)
from .app.curve_api import curve_constraints_of
from .app.curve_follow import add_curve_constraint
from .app.curve_network import make_sculpt_from_curves
from .app.scan_api import clear_target, deviation_of, fit_to_target, pull_of, set_pull, set_target, target_object
from .app.sculpted_solid import boundary_of, seam_report_of
from .app.solid_api import sculpt_solid, set_boundary
from .runtime.replay_device import CursorSample, ReplayDevice
from .runtime.session import Session, stop_all
from .version import __version__

legacy_paths.install()

__all__ = ["make_sculpt", "fair", "sculpt_solid", "set_boundary", "boundary_of", "seam_report_of", "run", "add_constraint", "add_curve_constraint",
           "make_sculpt_from_curves",
           "curve_constraints_of", "remove_constraint", "hold_boundary", "held_boundary",
           "set_material", "material_of", "keep_shape", "set_regional",
           "set_tool", "set_uniform", "scale_map", "set_curvature_target", "paint", "record_state", "replay_stroke",
           "set_target", "clear_target", "set_pull", "pull_of", "fit_to_target", "target_object", "deviation_of", "export_step", "thicken", "make_thickness",
           "to_cadquery", "ReplayDevice", "CursorSample", "CursorSource", "RunReport", "Session", "stop_all",
           "__version__"]
