"""The Sculpt document object: a ``Part::FeaturePython`` whose Shape is one face on a
``Part.BSplineSurface`` built from exactly the core's poles, knots, degrees and weights.

The document properties are the truth (numbers and one JSON string, see :mod:`sculpt_state`); the
live core surface is owned by ``obj.Proxy.live`` (:mod:`live_surface`): a cache rebuilt from them
whenever they change under it (Undo, Redo, opening a file), so Undo restores the sculpt state
exactly, and the one way to read or edit the surface while a session runs.
"""
from __future__ import annotations

from typing import Any

from .. import core
from . import scan_deviation, sculpt_state
from .live_surface import LiveSurface
from .sculpt_properties import STATE_PROPERTIES, ensure_properties, face_of, read_state, set_error, write_state
from .undo_up_to_date import ensure_observer
from .view_provider_hook import ViewProviderHook

TYPE = "HapticSculpt::Sculpt"

#: What gives a new Sculpt its view provider while the GUI runs (installed by HapticSculpt.gui).
_VIEW_PROVIDER = ViewProviderHook()
set_view_provider = _VIEW_PROVIDER.install
attach_view_provider = _VIEW_PROVIDER.attach


class SculptFeature:
    """Proxy of a Sculpt object. State lives in properties; nothing of it is pickled. The core
    surface is owned by :attr:`live` (see :mod:`live_surface`)."""

    def __init__(self, obj: Any, state: sculpt_state.SculptState, method: str = "plane",
                 error: float = 0.0, description: str = "") -> None:
        self.Type = TYPE
        self._obj = obj
        self.live = LiveSurface(obj)
        ensure_observer()
        ensure_properties(obj)
        obj.Proxy = self
        self.live.writing = True
        try:
            write_state(obj, state)
            obj.ConversionMethod = method
            obj.ConversionError = float(error)
            obj.SourceDescription = description
        finally:
            self.live.writing = False

    @property
    def surface(self) -> core.DynamicSurface:
        """The core surface for stepping it synchronously (``obj.Proxy.live.surface``; raises while a
        session runs)."""
        return self.live.surface

    # --- FreeCAD callbacks ----------------------------------------------------------------------
    def execute(self, obj: Any) -> None:
        """Recompute: the Shape from the stored state (raises, marking the object, if it is corrupt)."""
        self._attach(obj)
        try:
            obj.Shape = face_of(read_state(obj))
        except (ValueError, KeyError, TypeError) as exc:
            message = f"{obj.Label}: stored sculpt state is invalid: {exc}"
            set_error(obj, message, self.live)
            raise ValueError(message) from exc
        scan_deviation.refresh_property(obj)

    def onChanged(self, obj: Any, prop: str) -> None:
        """A state property changed from outside (Undo, Redo, a script): the live surface follows;
        so does its pull when the ``Target`` link changed, and the deviation report when the
        tolerance was edited (in the property editor, or by a script)."""
        live = getattr(self, "live", None)
        if live is not None and prop in STATE_PROPERTIES:
            live.property_written()
            if not live.writing:
                live.document_changed()
        elif live is not None and prop == "Target":
            live.target_changed()
        elif prop == "TargetTolerance" and not getattr(self, "setting_target", False) and not obj.Document.Restoring \
                and not getattr(obj.Document, "Transacting", False):  # (Undo and Redo restore the report themselves)
            from .scan_deviation import refresh_property
            refresh_property(obj)

    def onDocumentRestored(self, obj: Any) -> None:
        """Opening a file: add properties older files lack, then load the state (errors are reported
        on this object only; the rest of the document is unaffected)."""
        self._attach(obj)
        ensure_observer()
        migrated = ensure_properties(obj)
        try:
            self.live.surface  # noqa: B018 - loads and validates
        except ValueError as exc:
            import FreeCAD
            FreeCAD.Console.PrintError(f"HapticSculpt: {exc}\n")
            return
        if not migrated:
            obj.purgeTouched()  # opening a file of this version changes nothing in it

    # --- serialisation: no state in the proxy itself ----------------------------------------------
    def dumps(self) -> dict[str, Any]:
        """Proxy state for the file: only the type tag; the sculpt state is in the properties."""
        return {"Type": TYPE}

    def loads(self, state: Any) -> None:
        """Restores the proxy after the file's properties are read (see ``onDocumentRestored``)."""
        self.Type = TYPE
        self._obj = None
        self.live = None

    def __getstate__(self) -> dict[str, Any]:
        return self.dumps()

    def __setstate__(self, state: Any) -> None:
        self.loads(state)

    def _attach(self, obj: Any) -> None:
        if getattr(self, "live", None) is None or self._obj is not obj:
            self._obj = obj
            self.live = LiveSurface(obj)


def is_sculpt(obj: Any) -> bool:
    """True for a Sculpt document object."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TYPE
