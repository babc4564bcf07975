"""A sculpt's analysis displays kept with its document: the display, the combs, the continuity
check, the slider panel and the zebra and comb settings, as JSON in a hidden property of the
sculpt's view provider (the view's state, as FreeCAD keeps a shape's display mode: saved with the
file, not an undo step). A file saved with the zebra on reopens with it on."""
from __future__ import annotations

import json
from typing import Any

PROPERTY = "Displays"
#: The overlay attributes kept, each with what a kept value must be to be taken back.
FIELDS: dict[str, type | tuple[type, ...]] = {
    "display": str, "combs": bool, "continuity": bool, "panel_visible": bool, "stripe_mode": str,
    "stripes": (int, float), "stripe_angle": (int, float), "stripe_direction": list,
    "comb_every": int, "comb_gain": (int, float)}


def settings_of(overlay: Any) -> dict[str, Any]:
    """What ``overlay`` shows, as kept."""
    out = {name: getattr(overlay, name) for name in FIELDS}
    out["stripe_direction"] = [float(c) for c in out["stripe_direction"]]
    return out


def kept(obj: Any) -> dict[str, Any]:
    """The displays kept for ``obj``, the values that are well-formed only ({} where none are)."""
    vobj = getattr(obj, "ViewObject", None)
    text = getattr(vobj, PROPERTY, "") if vobj is not None and PROPERTY in vobj.PropertiesList else ""
    try:
        found = json.loads(text) if text else {}
    except ValueError:
        return {}
    if not isinstance(found, dict):
        return {}
    good = {k: v for k, v in found.items() if k in FIELDS and isinstance(v, FIELDS[k])
            and not (isinstance(v, bool) and FIELDS[k] is not bool)}
    if "stripe_direction" in good:
        d = good["stripe_direction"]
        if len(d) != 3 or not all(isinstance(c, (int, float)) for c in d):
            del good["stripe_direction"]
        else:
            good["stripe_direction"] = tuple(float(c) for c in d)
    return good


def keep(obj: Any, settings: dict[str, Any], default: dict[str, Any]) -> None:
    """Writes ``settings`` into ``obj``'s view provider where they changed (not while its document
    is being read: the overlay made then takes them, it does not set them); a sculpt that never
    showed more than ``default`` (a new overlay's) gains no property."""
    vobj = getattr(obj, "ViewObject", None)
    if vobj is None or obj.Document.Restoring:
        return
    text = json.dumps(settings, sort_keys=True)
    if PROPERTY not in vobj.PropertiesList:
        if settings == default:
            return  # (nothing shown yet: a file needs no property for it)
        vobj.addProperty("App::PropertyString", PROPERTY, "HapticSculpt", "The analysis displays shown on the "
                         "sculpt (JSON), kept with the document")
        vobj.setEditorMode(PROPERTY, 2)
    if getattr(vobj, PROPERTY) != text:
        setattr(vobj, PROPERTY, text)
