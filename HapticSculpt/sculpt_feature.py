"""The Sculpt document object: a ``Part::FeaturePython`` whose Shape is one face on a
``Part.BSplineSurface`` built from exactly the core's poles, knots, degrees and weights.

The document properties are the truth (numbers and one JSON string, see :mod:`sculpt_state`); the
live core surface (``obj.Proxy.surface``) is a cache rebuilt from them whenever they change under it
(Undo, Redo, opening a file), so Undo restores the sculpt state exactly.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from . import core, sculpt_state
from .part_surface import part_bspline

TYPE = "HapticSculpt::Sculpt"
GROUP = "Sculpt"
#: Properties that hold sculpt state; a change to any of them from outside invalidates the cache.
STATE_PROPERTIES = (*sculpt_state.ARRAY_NAMES, "SculptSettings")


def _add_property(obj: Any, kind: str, name: str, doc: str, mode: int) -> None:
    """Adds a property unless an older file already has it; mode 1 read-only, 2 hidden."""
    if name not in obj.PropertiesList:
        obj.addProperty(kind, name, GROUP, doc)
    obj.setEditorMode(name, mode)


def ensure_properties(obj: Any) -> None:
    """All properties this version uses (files from older versions gain the missing ones)."""
    for name in sculpt_state.ARRAY_NAMES:
        _add_property(obj, "App::PropertyFloatList", name, f"Sculpt state: {name} (flat, binary-exact)", 2)
    _add_property(obj, "App::PropertyString", "SculptSettings", "Sculpt state: sampling, maps, constraints, "
                  "tool and integrator settings (JSON)", 2)
    _add_property(obj, "App::PropertyString", "SourceDescription", "What the surface was made from", 1)
    _add_property(obj, "App::PropertyString", "ConversionMethod", "plane, exact or approximated", 1)
    _add_property(obj, "App::PropertyFloat", "ConversionError",
                  "Largest distance (mm) between the source and the surface it was converted to", 1)
    _add_property(obj, "App::PropertyInteger", "Strokes", "Strokes applied so far", 1)
    _add_property(obj, "App::PropertyString", "SculptError", "Why the stored sculpt state could not be "
                  "loaded (empty when it loads)", 1)


def read_state(obj: Any) -> sculpt_state.SculptState:
    """The sculpt state held in an object's properties."""
    arrays = {name: np.asarray(getattr(obj, name), dtype=float) for name in sculpt_state.ARRAY_NAMES}
    return sculpt_state.SculptState(arrays, sculpt_state.parse_settings(obj.SculptSettings))


def write_state(obj: Any, state: sculpt_state.SculptState) -> None:
    """Writes a state into an object's properties (only those that changed, so undo stays small)."""
    for name in sculpt_state.ARRAY_NAMES:
        values = state.arrays[name]
        current = getattr(obj, name)
        if len(current) != values.size or not np.array_equal(np.asarray(current, dtype=float), values):
            setattr(obj, name, values.tolist())
    text = state.settings_json()
    if obj.SculptSettings != text:
        obj.SculptSettings = text


def face_of(state: sculpt_state.SculptState) -> Any:
    """The Part face for a state: exactly its poles, knots, degrees and weights."""
    s, a = state.settings, state.arrays
    nu, nv = s["controls"]
    weights = a["Weights"].reshape(nu, nv) if a["Weights"].size else None
    bs = part_bspline(a["Poles"].reshape(nu, nv, 3), a["KnotsU"], a["KnotsV"], tuple(s["degree"]), weights)
    return bs.toShape()


class SculptFeature:
    """Proxy of a Sculpt object. State lives in properties; nothing of it is pickled."""

    def __init__(self, obj: Any, state: sculpt_state.SculptState, method: str = "plane",
                 error: float = 0.0, description: str = "") -> None:
        self.Type = TYPE
        self._obj = obj
        self._surface: core.DynamicSurface | None = None
        self._stale = True
        self._writing = False
        self.session = None  # the running Session, if any (it owns the surface meanwhile)
        ensure_properties(obj)
        obj.Proxy = self
        self._writing = True
        try:
            write_state(obj, state)
            obj.ConversionMethod = method
            obj.ConversionError = float(error)
            obj.SourceDescription = description
        finally:
            self._writing = False

    # --- the live core surface ------------------------------------------------------------------
    @property
    def surface(self) -> core.DynamicSurface:
        """The live core surface, rebuilt from the properties if they changed (Undo, Redo, open).

        Raises ``ValueError`` with the reason when the stored state is corrupt, and
        ``RuntimeError`` while a session's threads are stepping it."""
        obj = self._object()
        session = getattr(self, "session", None)
        if session is not None and session.running:
            raise RuntimeError(f"{obj.Label}: a sculpting session is running on this surface; stop it first")
        if self._surface is None or getattr(self, "_stale", True):
            try:
                surface = sculpt_state.restore(read_state(obj))
            except ValueError as exc:
                message = f"{obj.Label}: stored sculpt state is invalid: {exc}"
                self._set_error(obj, message)
                raise ValueError(message) from exc
            self._surface, self._stale = surface, False
            self._set_error(obj, "")
        return self._surface

    def write_back(self, shape: bool = True) -> None:
        """Copies the core's state into the properties and rebuilds the Shape from them."""
        obj = self._object()
        state = sculpt_state.capture(self.surface)
        self._writing = True
        try:
            write_state(obj, state)
            if shape:
                obj.Shape = face_of(state)
        finally:
            self._writing = False

    def write_arrays(self, poles: np.ndarray, velocities: np.ndarray, rest_lengths: Any,
                     painted: tuple[str, tuple[int, int], np.ndarray] | None = None) -> None:
        """Stores a stroke's end state (from a session's snapshot) and rebuilds the Shape;
        ``painted`` = (map name, shape, values) also stores a map an airbrush spray changed."""
        obj = self._object()
        state = read_state(obj)
        state.arrays["Poles"] = np.asarray(poles, dtype=float).ravel()
        state.arrays["Velocities"] = np.asarray(velocities, dtype=float).ravel()
        state.arrays["RestLengths"] = np.asarray(rest_lengths, dtype=float).ravel()
        if painted is not None:
            name, shape, values = painted
            prop = sculpt_state.map_property(name)
            state.arrays[prop] = np.asarray(values, dtype=float).ravel()
            state.settings["maps"][prop] = [int(shape[0]), int(shape[1])]
        self._writing = True
        try:
            write_state(obj, state)
            obj.Shape = face_of(state)
        finally:
            self._writing = False

    def show_poles(self, poles: np.ndarray, base: sculpt_state.SculptState) -> None:
        """Redraws the Shape from intermediate poles on the knots and weights of ``base`` (a GUI
        frame during a session, which reads the properties once; not stored, not an undo step)."""
        obj = self._object()
        frame = sculpt_state.SculptState({**base.arrays, "Poles": np.asarray(poles, dtype=float).ravel()}, base.settings)
        self._writing = True
        try:
            obj.Shape = face_of(frame)
        finally:
            self._writing = False

    # --- FreeCAD callbacks ----------------------------------------------------------------------
    def execute(self, obj: Any) -> None:
        """Recompute: the Shape from the stored state (raises, marking the object, if it is corrupt)."""
        self._obj = obj
        try:
            obj.Shape = face_of(read_state(obj))
        except (ValueError, KeyError, TypeError) as exc:
            message = f"{obj.Label}: stored sculpt state is invalid: {exc}"
            self._set_error(obj, message)
            raise ValueError(message) from exc

    def onChanged(self, obj: Any, prop: str) -> None:
        """A state property changed from outside (Undo, Redo, a script): the cache is stale."""
        if prop in STATE_PROPERTIES and not getattr(self, "_writing", False):
            self._stale = True

    def onDocumentRestored(self, obj: Any) -> None:
        """Opening a file: add properties older files lack, then load the state (errors are reported
        on this object only; the rest of the document is unaffected)."""
        self._obj = obj
        self._surface, self._stale, self._writing, self.session = None, True, False, None
        ensure_properties(obj)
        try:
            self.surface  # noqa: B018 - loads and validates
        except ValueError as exc:
            import FreeCAD
            FreeCAD.Console.PrintError(f"HapticSculpt: {exc}\n")

    # --- serialisation: no state in the proxy itself ----------------------------------------------
    def dumps(self) -> dict[str, Any]:
        """Proxy state for the file: only the type tag; the sculpt state is in the properties."""
        return {"Type": TYPE}

    def loads(self, state: Any) -> None:
        """Restores the proxy after the file's properties are read (see ``onDocumentRestored``)."""
        self.Type = TYPE
        self._obj, self._surface, self._stale, self._writing, self.session = None, None, True, False, None

    def __getstate__(self) -> dict[str, Any]:
        return self.dumps()

    def __setstate__(self, state: Any) -> None:
        self.loads(state)

    # --- helpers --------------------------------------------------------------------------------
    def _object(self) -> Any:
        obj = getattr(self, "_obj", None)
        if obj is None:
            raise RuntimeError("HapticSculpt: this proxy is not attached to a document object yet")
        return obj

    def _set_error(self, obj: Any, message: str) -> None:
        if "SculptError" in obj.PropertiesList and obj.SculptError != message:
            self._writing = True
            try:
                obj.SculptError = message
            finally:
                self._writing = False


def is_sculpt(obj: Any) -> bool:
    """True for a Sculpt document object."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TYPE
