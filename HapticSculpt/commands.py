"""Workbench commands (GUI only; registered from InitGui through FreeCADGui.addCommand)."""
from __future__ import annotations

import os
from typing import Any

import FreeCAD
import FreeCADGui as Gui

from .undo import transaction
from .view_provider import icon

TOOLBAR = ["HapticSculpt_NewPatch", "HapticSculpt_SculptFace", "HapticSculpt_Thicken", "HapticSculpt_ExportStep"]


def _selected_sculpts() -> list[Any]:
    from .sculpt_feature import is_sculpt
    return [o for o in Gui.Selection.getSelection() if is_sculpt(o)]


class NewPatch:
    """A flat 8x8 sculpt patch (100 x 100 mm) in the active document."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("HapticSculpt"), "MenuText": "New sculpt patch",
                "ToolTip": "Create a flat 100 x 100 mm B-spline patch (8 x 8 poles, degree 3) to sculpt"}

    def IsActive(self) -> bool:
        return FreeCAD.ActiveDocument is not None

    def Activated(self) -> None:
        from .api import make_sculpt
        make_sculpt(FreeCAD.ActiveDocument)
        FreeCAD.ActiveDocument.recompute()
        Gui.SendMsgToActiveView("ViewFit")


class SculptFace:
    """Turn the selected face (of any solid) into a sculpt surface."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("HapticSculpt"), "MenuText": "Sculpt selected face",
                "ToolTip": "Convert the selected face to a sculptable B-spline surface (exact where possible)"}

    def IsActive(self) -> bool:
        sel = Gui.Selection.getSelectionEx()
        return len(sel) == 1 and any(n.startswith("Face") for n in sel[0].SubElementNames)

    def Activated(self) -> None:
        from .api import make_sculpt
        sel = Gui.Selection.getSelectionEx()[0]
        face = next(n for n in sel.SubElementNames if n.startswith("Face"))
        obj = make_sculpt(sel.Object.Document, source=(sel.Object, face))
        FreeCAD.Console.PrintMessage(f"HapticSculpt: {obj.Label} from {obj.SourceDescription}, "
                                     f"{obj.ConversionMethod}, error {obj.ConversionError:.3g} mm\n")


class Thicken:
    """Thicken the selected sculpt into a solid (2 mm)."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("HapticSculpt"), "MenuText": "Thicken",
                "ToolTip": "Offset the selected sculpt surface by 2 mm into a new solid"}

    def IsActive(self) -> bool:
        return bool(_selected_sculpts())

    def Activated(self) -> None:
        import Part
        from .api import thicken
        for obj in _selected_sculpts():
            with transaction(obj.Document, "Thicken"):
                Part.show(thicken(obj, 2.0), obj.Name + "_Solid")


class ExportStep:
    """Export the selected sculpts to a STEP file beside the document."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("HapticSculpt"), "MenuText": "Export STEP",
                "ToolTip": "Write the selected sculpt surfaces to <document>.step beside the document file"}

    def IsActive(self) -> bool:
        return bool(_selected_sculpts())

    def Activated(self) -> None:
        from .api import export_step
        objs = _selected_sculpts()
        doc = objs[0].Document
        base = os.path.splitext(doc.FileName)[0] if doc.FileName else os.path.join(os.path.expanduser("~"), doc.Name)
        path = export_step(objs, base + ".step")
        FreeCAD.Console.PrintMessage(f"HapticSculpt: wrote {path}\n")


def register() -> None:
    """Adds every command to FreeCAD (called once from the workbench's Initialize)."""
    for name, cls in (("HapticSculpt_NewPatch", NewPatch), ("HapticSculpt_SculptFace", SculptFace),
                      ("HapticSculpt_Thicken", Thicken), ("HapticSculpt_ExportStep", ExportStep)):
        Gui.addCommand(name, cls())
