"""The GUI layer: the workbench's commands, view input, overlay, HUD, panel and view provider.

Imported only while FreeCAD's GUI runs (InitGui imports it at start-up). Importing it installs
the GUI's parts into the layers below, which never import this one: new Sculpt, SculptedSolid
and Thickness objects get their view providers, running sessions show their shape at graphics rate, and the strokes they commit
are echoed as scripting calls (so macros record them) and written to FreeCAD's recovery file (so a
crash loses none).
"""
from ..app import sculpt_feature, sculpted_solid, thickness
from ..runtime import session
from .echo import echo_stroke
from .frame_clock import coin_frame_clock
from .recovery_file import RecoveryWriter
from .view_provider import SculptViewProvider, SolidViewProvider, ThicknessViewProvider

sculpt_feature.set_view_provider(SculptViewProvider)
sculpted_solid.set_view_provider(SolidViewProvider)
thickness.set_view_provider(ThicknessViewProvider)
session.set_frame_clock(coin_frame_clock)
#: The one writer of recovery files (its numbers are the observer's and the GUI test's).
recovery = RecoveryWriter()
session.set_commit_listener(echo_stroke, recovery.committed)
