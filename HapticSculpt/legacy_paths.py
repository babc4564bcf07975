"""Module paths of HapticSculpt 0.1, before the package was split into layers.

A FreeCAD document stores the module and class of each Python proxy, and reopening it imports
them by name: documents saved by 0.1 name ``HapticSculpt.sculpt_feature`` and
``HapticSculpt.view_provider``. This finder resolves those old names to the modules that hold the
classes now, and only when asked (so the GUI module is still imported only by the GUI)."""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
from types import ModuleType
from typing import Any, Sequence

MOVED = {
    "HapticSculpt.sculpt_feature": "HapticSculpt.app.sculpt_feature",
    "HapticSculpt.view_provider": "HapticSculpt.gui.view_provider",
}


class _Alias(importlib.abc.Loader):
    def __init__(self, target: str) -> None:
        self.target = target

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        module = importlib.import_module(self.target)
        self.spec = module.__spec__  # importlib overwrites it with the old name's spec: put it back
        return module

    def exec_module(self, module: ModuleType) -> None:
        module.__spec__ = self.spec  # nothing to run: the module under the old name is the new one


class LegacyPaths(importlib.abc.MetaPathFinder):
    """Finds the old module names of :data:`MOVED`."""

    def find_spec(self, name: str, path: Sequence[str] | None,
                  target: Any = None) -> importlib.machinery.ModuleSpec | None:
        moved = MOVED.get(name)
        return importlib.machinery.ModuleSpec(name, _Alias(moved)) if moved else None


def install() -> None:
    """Adds the finder once."""
    if not any(isinstance(f, LegacyPaths) for f in sys.meta_path):
        sys.meta_path.append(LegacyPaths())
