"""The task panel that asks a thickness (resources/ui/thickness.ui, a Gui::QuantitySpinBox in mm):
for a new Thickness of a sculpt (the Thicken command) or to edit one (double-click). OK runs the
scripting call through FreeCADGui.doCommand, as one undo step; Cancel changes nothing."""
from __future__ import annotations

import os
from typing import Any

import FreeCAD
import FreeCADGui as Gui

from .echo import ref, run_echoed

UI = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources", "ui", "thickness.ui")
#: The thickness a new Thickness is offered (mm).
DEFAULT = 2.0


class ThicknessPanel:
    """Asks the thickness of ``sculpt``'s new Thickness, or of ``feature`` (an existing one)."""

    def __init__(self, sculpt: Any = None, feature: Any = None) -> None:
        self.sculpt, self.feature = sculpt, feature
        self.form = Gui.PySideUic.loadUi(UI)
        self.form.setWindowTitle(self._title())
        value = DEFAULT if feature is None else float(feature.Thickness.Value)
        self.form.thickness.setProperty("rawValue", value)

    def _title(self) -> str:
        """What is thickened, by name: "Thicken Sculpt", "Edit Thickness of Sculpt"."""
        if self.feature is None:
            return "Thicken" if self.sculpt is None else f"Thicken {self.sculpt.Label}"
        source = getattr(self.feature, "Source", None)
        return f"Edit {self.feature.Label}" + ("" if source is None else f" of {source.Label}")

    def open(self) -> None:
        """Shown: the value is selected, so typing replaces it (as in FreeCAD's own dialogs). Again
        once the event that opened the panel is done: FreeCAD 1.1's model tree takes the keyboard
        back after the double-click that opens the panel to edit a Thickness (ctrl+a then selected
        the tree's items, and the typed value went nowhere)."""
        from pivy import coin
        self._select_value()
        self._again = coin.SoOneShotSensor(lambda *_: self._select_value(), None)
        self._again.schedule()

    def _select_value(self) -> None:
        self.form.thickness.setFocus()
        self.form.thickness.selectAll()

    def thickness(self) -> float:
        """The value in the field (mm)."""
        return float(self.form.thickness.property("rawValue"))

    def accept(self) -> bool:
        t = self.thickness()
        try:
            if self.feature is None:
                run_echoed(f"HapticSculpt.make_thickness({ref(self.sculpt)}, {t!r})")
            else:
                self._edit(t)
        except (ValueError, TypeError) as exc:  # (0 mm, say: the spin box lets it through to be refused)
            FreeCAD.Console.PrintError(f"HapticSculpt: Thicken: {exc}\n")
            self.form.message.setText(str(exc))
            return False  # (the panel stays open for another value)
        self._close()
        return True

    def reject(self) -> bool:
        self._close()
        return True

    def _edit(self, t: float) -> None:
        """The Thickness property set and recomputed, one undo step."""
        doc = f"App.getDocument({self.feature.Document.Name!r})"
        run_echoed(f"{doc}.openTransaction('Edit thickness')", modules=())
        try:
            run_echoed(f"{ref(self.feature)}.Thickness = {t!r}", modules=())
            run_echoed(f"{doc}.recompute()", modules=())
        finally:
            run_echoed(f"{doc}.commitTransaction()", modules=())

    def _close(self) -> None:
        if self.feature is not None and Gui.ActiveDocument is not None and Gui.ActiveDocument.getInEdit():
            Gui.ActiveDocument.resetEdit()
        else:
            Gui.Control.closeDialog()
