"""View providers of Sculpt and SculptedSolid objects (imported only when FreeCAD.GuiUp)."""
from __future__ import annotations

import os
from typing import Any

ICONS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources", "icons")


def icon(name: str) -> str:
    """Path of an icon in resources/icons."""
    return os.path.join(ICONS, name + ".svg")


class _Stateless:
    """A view provider keeps nothing in the file (the object's properties hold everything)."""

    def dumps(self) -> None:
        return None

    def loads(self, state: Any) -> None:
        return None

    def __getstate__(self) -> None:
        return None

    def __setstate__(self, state: Any) -> None:
        return None


class SculptViewProvider(_Stateless):
    """Shows the sculpt face with Part's own shape display; adds the icon."""

    def __init__(self, vobj: Any) -> None:
        vobj.Proxy = self

    def attach(self, vobj: Any) -> None:
        self.Object = vobj.Object

    def onChanged(self, vobj: Any, prop: str) -> None:
        if prop == "Visibility" and not vobj.Object.Document.Restoring:  # the jacks show and hide with the sculpt
            from .workbench import controller
            ctl = controller()
            for ov in ctl.overlays_of(vobj.Object) if ctl.inputs else []:
                ov.refresh()

    def updateData(self, obj: Any, prop: str) -> None:
        # the curves it follows show at once; not while a document is read or undone / redone: its
        # views draw it once it is (mid-Undo the net of a refining Follow curve was half restored)
        if prop == "CurveConstraints" and not obj.Document.Restoring and not getattr(obj.Document, "Transacting", False):
            from .workbench import controller
            ctl = controller()
            if ctl.inputs:
                ctl.refresh(obj)

    def getIcon(self) -> str:
        return icon("HapticSculpt")


class SolidViewProvider(_Stateless):
    """A SculptedSolid shows as Part shows a solid; its base and its sculpts are its children in the
    tree, hidden, as FreeCAD's own features show theirs (shown again when it is deleted)."""

    def __init__(self, vobj: Any) -> None:
        vobj.Proxy = self
        obj = vobj.Object
        for child in [obj.Base, *obj.Sculpts]:
            if child is not None and child.ViewObject is not None:
                child.ViewObject.Visibility = False

    def attach(self, vobj: Any) -> None:
        self.Object = vobj.Object

    def getIcon(self) -> str:
        return icon("HapticSculpt")

    def onChanged(self, vobj: Any, prop: str) -> None:
        if prop == "Visibility" and not vobj.Object.Document.Restoring:  # its sculpt's displays lie on its face
            from .workbench import controller
            ctl = controller()
            for sculpt in getattr(vobj.Object, "Sculpts", []) if ctl.inputs else []:
                for ov in ctl.overlays_of(sculpt):
                    ov.refresh()

    def claimChildren(self) -> list[Any]:
        obj = self.Object
        return [o for o in [getattr(obj, "Base", None), *getattr(obj, "Sculpts", [])] if o is not None]

    def onDelete(self, vobj: Any, subelements: Any) -> bool:
        """Deleting it shows its base again and deletes its sculpts with it (in the same undo step):
        a face of a solid that is gone is nothing to sculpt, and a session on it went on, hidden."""
        obj = vobj.Object
        base = getattr(obj, "Base", None)
        if base is not None and base.ViewObject is not None:
            base.ViewObject.Visibility = True
        for sculpt in list(getattr(obj, "Sculpts", [])):
            if sculpt is not None and obj.Document.getObject(sculpt.Name) is sculpt and \
                    not [o for o in sculpt.InList if o is not obj]:
                obj.Document.removeObject(sculpt.Name)
        return True


class ThicknessViewProvider(_Stateless):
    """A Thickness shows as Part shows a solid, its sculpt as its child in the tree (hidden);
    double-click opens the panel that edits its thickness."""

    def __init__(self, vobj: Any) -> None:
        vobj.Proxy = self
        source = vobj.Object.Source
        if source is not None and source.ViewObject is not None:
            source.ViewObject.Visibility = False  # (as Part's Offset hides what it offsets)

    def attach(self, vobj: Any) -> None:
        self.Object = vobj.Object

    def getIcon(self) -> str:
        return icon("HapticSculpt")

    def claimChildren(self) -> list[Any]:
        source = getattr(self.Object, "Source", None)
        return [source] if source is not None else []

    def doubleClicked(self, vobj: Any) -> bool:
        import FreeCADGui as Gui
        Gui.ActiveDocument.setEdit(vobj.Object, 0)
        return True

    def setEdit(self, vobj: Any, mode: int) -> bool:
        if mode != 0:
            return False
        import FreeCADGui as Gui
        from .thickness_panel import ThicknessPanel
        Gui.Control.showDialog(ThicknessPanel(feature=vobj.Object))
        return True

    def unsetEdit(self, vobj: Any, mode: int) -> bool:
        import FreeCADGui as Gui
        Gui.Control.closeDialog()
        return True

    def onDelete(self, vobj: Any, subelements: Any) -> bool:
        source = getattr(vobj.Object, "Source", None)
        if source is not None and source.ViewObject is not None:
            source.ViewObject.Visibility = True
        return True
