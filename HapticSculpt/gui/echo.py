"""Workbench actions as scripting calls (GUI only): each command and key runs the HapticSculpt
call that does what it does through FreeCADGui.doCommand, as FreeCAD's own tools do, so it shows in
the Python console and a recorded macro replays the session in console mode."""
from __future__ import annotations

from typing import Any


def run_echoed(code: str, modules: tuple[str, ...] = ("HapticSculpt",)) -> None:
    """Runs a scripting call through FreeCADGui.doCommand, as FreeCAD's own tools do: it shows in
    the Python console and goes into a macro being recorded, which then replays in console mode."""
    import FreeCADGui as Gui
    # The import each time (not Gui.addModule, which writes it once per FreeCAD run): a macro whose
    # recording starts later must import the module too.
    for module in modules:
        Gui.doCommand(f"import {module}")
    Gui.doCommand(code)


def ref(obj: Any) -> str:
    """How a script names a document object."""
    return f"App.getDocument({obj.Document.Name!r}).getObject({obj.Name!r})"


def echo_stroke(obj: Any, before: Any, title: str, strokes: int, echo: bool = True) -> None:
    """Keeps a stroke, spray or edit that a threaded session committed in the sculpt's StrokeLog
    and echoes the one short ``HapticSculpt.replay_stroke`` line that names it: run here it changes
    nothing (the object holds that state), and in a recorded macro it replays the commit exactly
    (``before`` is the state the macro holds there). ``echo=False``: kept only (a commit made again
    at the session's stop, with what moved after it, under the name its line gave already). Called
    inside the commit's transaction (see runtime.session.set_commit_listener)."""
    from ..app import stroke_log
    name = stroke_log.record(obj, before, title, strokes)
    if echo:
        # (not a stroke: an edit a session took, after its own call, with what moved meanwhile, or a
        # long paint stroke: named, where a bare line read as a stroke nobody made)
        said = "" if strokes else f"  # {title}"
        run_echoed(f"HapticSculpt.replay_stroke({ref(obj)}, {name!r}){said}")
