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
