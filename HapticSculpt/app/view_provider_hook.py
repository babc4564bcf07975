"""How a document object made in this layer gets its view provider while FreeCAD's GUI runs: the
GUI layer installs a factory when it loads (see HapticSculpt.gui), so this layer never imports a
GUI module."""
from __future__ import annotations

from typing import Any, Callable


class ViewProviderHook:
    """One per object type: ``install(factory)`` from the GUI, ``attach(obj)`` on each new object."""

    def __init__(self) -> None:
        self._factory: Callable[[Any], Any] | None = None

    def install(self, factory: Callable[[Any], Any]) -> None:
        """Installs ``factory(view_object)``, called for each new object while the GUI is up."""
        self._factory = factory

    def attach(self, obj: Any) -> None:
        """Gives ``obj`` its view provider if FreeCAD's GUI runs (a no-op in console mode)."""
        import FreeCAD
        if FreeCAD.GuiUp and self._factory is not None:
            self._factory(obj.ViewObject)
