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


def echo_recorded_state(obj: Any, before: Any, title: str, strokes: int) -> None:
    """Echoes a stroke, spray or session end that a threaded session committed as the
    ``HapticSculpt.record_state`` call that gives the state it left: run here it changes nothing
    (the object holds that state), and in a recorded macro it replays the stroke exactly."""
    from ..app.recorded_state import pack
    from ..app.sculpt_properties import read_state
    packed = pack(before, read_state(obj))
    run_echoed(f"HapticSculpt.record_state({ref(obj)}, {packed!r}, {title!r}, strokes={strokes})")
