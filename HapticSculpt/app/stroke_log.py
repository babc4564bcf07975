"""The strokes a sculpt keeps for its macros: a stroke made in a threaded session depends on the
device's timing, so what it changed (:mod:`recorded_state`'s compressed delta) is stored in the
sculpt's ``StrokeLog`` property (JSON, saved with the document) under a short name, and the macro
line that replays it only names it: ``HapticSculpt.replay_stroke(obj, 'Stroke003')``.

Each record also holds fingerprints of the state before and after, so a replay applies only to the
state the stroke started from (bit for bit), and finds its record in the sculpt it is replayed on
or, for a macro replayed into a new document, in any sculpt of the open documents (the saved
document the strokes were made in). The log keeps the newest records (:data:`LIMIT`, :data:`LIMIT_CHARS`).
"""
from __future__ import annotations

import hashlib
import json
import re
from typing import Any

import numpy as np

from . import recorded_state, sculpt_state
from .sculpt_properties import GROUP, read_state

PROPERTY = "StrokeLog"
#: The most strokes a sculpt keeps, and the most characters their records take (a stroke on a clay
#: 8 x 8 patch takes about 40 000, an elastic one 4 000): the oldest go first, the newest always stays.
LIMIT = 200
LIMIT_CHARS = 8_000_000
_NAME = re.compile(r"Stroke(\d+)\Z")


def fingerprint(state: sculpt_state.SculptState) -> str:
    """A digest of every array (as little-endian doubles) and the settings: equal states, equal text."""
    h = hashlib.sha256()
    for name in sculpt_state.ARRAY_NAMES:
        h.update(name.encode())
        h.update(np.ascontiguousarray(state.arrays[name], dtype="<f8").tobytes())
    h.update(state.settings_json().encode())
    return h.hexdigest()[:32]


def records(obj: Any) -> dict[str, dict[str, Any]]:
    """The strokes ``obj`` keeps, by name (empty for a sculpt without any)."""
    if PROPERTY not in obj.PropertiesList or not getattr(obj, PROPERTY):
        return {}
    try:
        log = json.loads(getattr(obj, PROPERTY))
    except json.JSONDecodeError as exc:
        raise ValueError(f"{obj.Name}.{PROPERTY}: malformed JSON ({exc})") from exc
    if not isinstance(log, dict):
        raise ValueError(f"{obj.Name}.{PROPERTY}: expected a JSON object")
    return log


def _store(obj: Any, log: dict[str, dict[str, Any]]) -> None:
    if PROPERTY not in obj.PropertiesList:
        obj.addProperty("App::PropertyString", PROPERTY, GROUP,
                        "Strokes made in sessions, as what each changed (JSON): what replay_stroke replays")
        obj.setEditorMode(PROPERTY, 2)
    size = sum(len(r["change"]) for r in log.values())
    while len(log) > 1 and (len(log) > LIMIT or size > LIMIT_CHARS):
        size -= len(log.pop(min(log, key=_number))["change"])
    setattr(obj, PROPERTY, json.dumps(log, sort_keys=True, separators=(",", ":")))


def _number(name: str) -> int:
    match = _NAME.match(name)
    return int(match.group(1)) if match else -1


def record(obj: Any, before: sculpt_state.SculptState, title: str, strokes: int) -> str:
    """Keeps what took ``obj`` from ``before`` to the state it holds now and returns the name it is
    kept under. Call it inside the transaction that made the change, so Undo forgets it too."""
    after = read_state(obj)
    log = records(obj)
    name = f"Stroke{max(map(_number, log), default=0) + 1:03d}"
    log[name] = {"title": title, "strokes": int(strokes), "before": fingerprint(before),
                 "after": fingerprint(after), "change": recorded_state.pack(before, after)}
    _store(obj, log)
    return name


def find(obj: Any, name: str, state: sculpt_state.SculptState) -> dict[str, Any]:
    """The record ``name`` that applies to ``state`` (or gives it): ``obj``'s own, else one kept by
    a sculpt in any open document; ``ValueError`` saying which is missing or does not fit."""
    own = records(obj).get(name)
    if own is not None:
        return own
    import FreeCAD
    prints = {fingerprint(state)}
    for doc in FreeCAD.listDocuments().values():
        for other in doc.Objects:
            if other is obj or PROPERTY not in other.PropertiesList:
                continue
            found = records(other).get(name)
            if found is not None and prints & {found["before"], found["after"]}:
                return found
    raise ValueError(f"stroke: {obj.Name} keeps no stroke {name!r}, and no open document keeps one that starts "
                     f"from its state (open the document the stroke was made in)")


def keep(obj: Any, name: str, found: dict[str, Any]) -> None:
    """Keeps a record replayed from another document in ``obj`` too (inside the replay's transaction)."""
    log = records(obj)
    if log.get(name) != found:
        log[name] = found
        _store(obj, log)
