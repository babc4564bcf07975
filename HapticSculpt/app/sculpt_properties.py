"""A Sculpt object's document properties: which there are, and the sculpt state they hold (numbers
and one JSON string, see :mod:`sculpt_state`), read and written; the Part face of a state."""
from __future__ import annotations

from typing import Any

import numpy as np

from . import sculpt_state
from .part_surface import part_bspline

GROUP = "Sculpt"
#: Properties that hold sculpt state; a change to any of them from outside invalidates the cache.
STATE_PROPERTIES = (*sculpt_state.ARRAY_NAMES, "SculptSettings")


def _add_property(obj: Any, kind: str, name: str, doc: str, mode: int) -> bool:
    """Adds a property unless an older file already has it; mode 1 read-only, 2 hidden. True if added."""
    added = name not in obj.PropertiesList
    if added:
        obj.addProperty(kind, name, GROUP, doc)
    obj.setEditorMode(name, mode)
    return added


def ensure_properties(obj: Any) -> bool:
    """All properties this version uses (files from older versions gain the missing ones); True if
    any was missing."""
    added = [_add_property(obj, "App::PropertyFloatList", name, f"Sculpt state: {name} (flat, binary-exact)", 2)
             for name in sculpt_state.ARRAY_NAMES]
    added.append(_add_property(obj, "App::PropertyString", "SculptSettings", "Sculpt state: sampling, maps, "
                               "constraints, tool and integrator settings (JSON)", 2))
    added.append(_add_property(obj, "App::PropertyString", "CurveConstraints", "Curves the surface must follow: "
                               "their conditions (JSON; the links that hold them are in SculptSettings)", 2))
    added.append(_add_property(obj, "App::PropertyString", "SourceDescription", "What the surface was made from", 1))
    added.append(_add_property(obj, "App::PropertyString", "ConversionMethod", "plane, exact or approximated", 1))
    added.append(_add_property(obj, "App::PropertyFloat", "ConversionError",
                               "Largest distance (mm) between the source and the surface it was converted to", 1))
    added.append(_add_property(obj, "App::PropertyInteger", "Strokes", "Strokes applied so far", 1))
    added.append(_add_property(obj, "App::PropertyString", "SculptError", "Why the stored sculpt state could not "
                               "be loaded (empty when it loads)", 1))
    return any(added)


def read_state(obj: Any) -> sculpt_state.SculptState:
    """The sculpt state held in an object's properties."""
    arrays = {name: np.asarray(getattr(obj, name), dtype=float) for name in sculpt_state.ARRAY_NAMES}
    return sculpt_state.SculptState(arrays, sculpt_state.parse_settings(obj.SculptSettings))


def write_state(obj: Any, state: sculpt_state.SculptState, stored: sculpt_state.SculptState | None = None) -> None:
    """Writes a state into an object's properties: only those that changed, so undo stays small.
    ``stored``: what the properties hold, if the caller knows (reading them back costs more than
    the write of one map at 128 x 128)."""
    for name in sculpt_state.ARRAY_NAMES:
        values = state.arrays[name]
        if stored is not None:
            changed = not np.array_equal(stored.arrays[name], values)
        else:
            current = getattr(obj, name)
            changed = len(current) != values.size or not np.array_equal(np.asarray(current, dtype=float), values)
        if changed:
            setattr(obj, name, values.tolist())
    text = state.settings_json()
    if (stored.settings_json() if stored is not None else obj.SculptSettings) != text:
        obj.SculptSettings = text


def surface_of(state: sculpt_state.SculptState) -> Any:
    """The Part.BSplineSurface of a state: exactly its poles, knots, degrees and weights."""
    s, a = state.settings, state.arrays
    nu, nv = s["controls"]
    weights = a["Weights"].reshape(nu, nv) if a["Weights"].size else None
    return part_bspline(a["Poles"].reshape(nu, nv, 3), a["KnotsU"], a["KnotsV"], tuple(s["degree"]), weights)


def face_of(state: sculpt_state.SculptState) -> Any:
    """The Part face for a state (see :func:`surface_of`)."""
    return surface_of(state).toShape()


def set_error(obj: Any, message: str, live: Any) -> None:
    """Shows why the stored state cannot be loaded (empty: it loads) on the object."""
    if "SculptError" in obj.PropertiesList and obj.SculptError != message:
        live.writing = True
        try:
            obj.SculptError = message
        finally:
            live.writing = False
