"""View provider of Sculpt objects (imported only when FreeCAD.GuiUp)."""
from __future__ import annotations

import os
from typing import Any

ICONS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources", "icons")


def icon(name: str) -> str:
    """Path of an icon in resources/icons."""
    return os.path.join(ICONS, name + ".svg")


class SculptViewProvider:
    """Shows the sculpt face with Part's own shape display; adds the icon."""

    def __init__(self, vobj: Any) -> None:
        vobj.Proxy = self

    def attach(self, vobj: Any) -> None:
        self.Object = vobj.Object

    def getIcon(self) -> str:
        return icon("HapticSculpt")

    def dumps(self) -> None:
        return None

    def loads(self, state: Any) -> None:
        return None

    def __getstate__(self) -> None:
        return None

    def __setstate__(self, state: Any) -> None:
        return None
