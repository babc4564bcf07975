"""Undo and Redo leave sculpts up to date. FreeCAD marks each object whose properties a transaction
restored as touched, for a recompute, but a sculpt's Shape is restored with its state, so the tree
showed every sculpt, solid and thickness of the step as needing a recompute that would change
nothing. One document observer clears that mark on ours whose inputs are up to date themselves."""
from __future__ import annotations

from typing import Any

#: The proxy types whose Shape an undo step restores with the rest of their state.
TYPES = ("HapticSculpt::Sculpt", "HapticSculpt::SculptedSolid", "HapticSculpt::Thickness")


class _Observer:
    def slotUndoDocument(self, doc: Any) -> None:
        purge_restored(doc)

    def slotRedoDocument(self, doc: Any) -> None:
        purge_restored(doc)


_INSTALLED: list[_Observer] = []


def ensure_observer() -> None:
    """Installs the observer once (from a sculpt's creation or loading)."""
    if not _INSTALLED:
        import FreeCAD
        _INSTALLED.append(_Observer())
        FreeCAD.addDocumentObserver(_INSTALLED[0])


def purge_restored(doc: Any) -> None:
    """Clears the touched mark of each of ``doc``'s sculpts, solids and thicknesses that nothing it
    is made from (a base solid, a face sculpt) still waits for a recompute; one in error is marked
    touched instead, so that Recompute mends it (its Source deleted, then brought back by Undo)."""
    ours = [o for o in doc.Objects if getattr(getattr(o, "Proxy", None), "Type", None) in TYPES]
    for obj in ours:  # (one in error, its Source deleted and brought back: left to recompute)
        if "Invalid" in obj.State or "Error" in obj.State:
            obj.touch()
    cleared = True
    while cleared:  # (again after each clearing: a solid waits on its face sculpt's mark)
        cleared = False
        for obj in ours:
            if "Touched" in obj.State and "Invalid" not in obj.State and not any("Touched" in dep.State for dep in obj.OutListRecursive):
                obj.purgeTouched()
                cleared = True
