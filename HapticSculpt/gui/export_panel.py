"""Export STEP's task panel (GUI only): what is exported and a STEP file name in FreeCAD's own file
chooser (Gui::FileChooser in save mode, filtered to STEP), from a .ui file as FreeCAD's workbenches
load theirs; OK writes the file through the echoed ``HapticSculpt.export_step`` call."""
from __future__ import annotations

import os
import re
from typing import Any

import FreeCAD
import FreeCADGui as Gui

UI = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources", "ui", "ExportStep.ui")
_OK, _CANCEL = 0x00000400, 0x00400000  # QDialogButtonBox's Ok and Cancel (no Qt import here)


def exportable(selection: list[Any], doc: Any) -> list[Any]:
    """What to export: the selected objects that have a shape (a sculpt, a sculpted solid, a
    thickened solid, any part); else what the user sees of their sculpting, when that is one
    object: the visible end result built on a sculpt (the Thickness made from it, the Cut or
    Body made from a sculpted solid, else the sculpt or the sculpted solid itself); else the
    document's only sculpt or sculpted solid (a SculptedSolid's own hidden sculpt does not count);
    empty if there is no such choice."""
    from ..app.sculpt_feature import is_sculpt
    from ..app.sculpted_solid import is_sculpted_solid, solid_of

    picked = [o for o in selection if hasattr(o, "Shape") and not o.Shape.isNull()]
    if picked or doc is None:
        return picked

    def sculpted(o: Any) -> bool:
        return is_sculpt(o) or is_sculpted_solid(o)

    results = [o for o in doc.Objects
               if getattr(o, "Visibility", False) and hasattr(o, "Shape") and not o.Shape.isNull()
               and not any(hasattr(user, "Shape") for user in o.InList)  # (cheap first: IsActive runs often)
               and (sculpted(o) or any(sculpted(x) for x in o.OutListRecursive))]
    if len(results) == 1:
        return results
    found = [o for o in doc.Objects if is_sculpted_solid(o) or (is_sculpt(o) and solid_of(o) is None)]
    return found if len(found) == 1 else []


#: Where FreeCAD's own file dialogs keep the folder they last used (Gui::FileDialog's working directory).
LAST_FOLDER = ("User parameter:BaseApp/Preferences/General", "FileOpenSavePath")


def last_folder() -> str:
    """The folder FreeCAD's file dialogs last used, if it still exists; else the home folder."""
    folder = FreeCAD.ParamGet(LAST_FOLDER[0]).GetString(LAST_FOLDER[1], "")
    return folder if folder and os.path.isdir(folder) else os.path.expanduser("~")


def default_path(objs: list[Any]) -> str:
    """<the document's folder, else the folder FreeCAD's file dialogs last used, else the home
    folder>/<the object's label, or the document's>.step."""
    doc = objs[0].Document
    folder = os.path.dirname(doc.FileName) if doc.FileName else last_folder()
    label = objs[0].Label if len(objs) == 1 else doc.Label
    return os.path.join(folder, (re.sub(r'[\\/:*?"<>|]+', "_", label).strip() or "sculpt") + ".step")


def with_suffix(path: str) -> str:
    """``path`` with .step added unless it ends in .step or .stp (as FreeCAD's save dialog does)."""
    path = os.path.expanduser(path.strip())
    return path if path.lower().endswith((".step", ".stp")) else path + ".step"


class ExportStepPanel:
    """The task panel: the objects named, the file chosen (prefilled), OK exports, Cancel closes."""

    def __init__(self, objs: list[Any]) -> None:
        self.objs = objs
        self.form = Gui.PySideUic.loadUi(UI)
        self.form.objects.setText("Export " + ", ".join(o.Label for o in objs))
        self.form.file.setProperty("fileName", default_path(objs))
        self._replace: str | None = None  # a file that exists and OK was pressed for once: the next OK replaces it

    def path(self) -> str:
        """The file name the chooser holds, with .step added if it has no STEP suffix."""
        return with_suffix(str(self.form.file.property("fileName") or ""))

    def getStandardButtons(self) -> int:
        return _OK | _CANCEL

    def accept(self) -> bool:
        """Exports, unless the file exists and was not offered for replacing yet: the panel then
        says so and stays open, and OK again replaces it (no file is overwritten unasked)."""
        from .echo import ref, run_echoed
        path = self.path()
        if os.path.exists(path) and self._replace != path:
            self._replace = path
            self.form.message.setText(f"{os.path.basename(path)} exists: OK again replaces it")
            return False
        try:
            run_echoed(f"HapticSculpt.export_step([{', '.join(ref(o) for o in self.objs)}], {path!r})")
        except Exception as exc:  # noqa: BLE001 - said in the report view; the panel stays open to fix the name
            FreeCAD.Console.PrintError(f"HapticSculpt: Export STEP: {exc}\n")
            self.form.message.setText(str(exc))
            return False
        FreeCAD.Console.PrintMessage(f"HapticSculpt: exported {', '.join(o.Label for o in self.objs)} to {path}\n")
        # (remembered as FreeCAD's own dialogs remember it: the next export or save starts there)
        FreeCAD.ParamGet(LAST_FOLDER[0]).SetString(LAST_FOLDER[1], os.path.dirname(path))
        Gui.Control.closeDialog()
        return True

    def reject(self) -> bool:
        Gui.Control.closeDialog()
        return True
