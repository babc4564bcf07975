"""What a stroke changed, as text a macro can hold.

A stroke made in a threaded session depends on the device's timing, so a macro cannot replay it
by repeating the device's motion. It records the state the stroke left instead: :func:`pack`
writes the arrays and settings that differ from the state before the stroke (only the changed
entries of an array where few changed, as a plastic stroke's rest lengths are) as compressed
base64 text, and :func:`unpack` applies that to the same state before, bit for bit.
"""
from __future__ import annotations

import base64
import binascii
import json
import zlib

import numpy as np

from . import sculpt_state

_MAPS = ("MassMap", "DampingMap", "StiffnessMap", "BendingMap", "PullMap")
_SPARSE_SHARE = 0.5  # an array with fewer changed entries than this share is stored as (index, value)


def pack(before: sculpt_state.SculptState, after: sculpt_state.SculptState) -> str:
    """The change from ``before`` to ``after`` as ASCII text (empty arrays of changes are left out)."""
    header: dict = {"arrays": {}, "settings": None}
    blobs: list[bytes] = []
    for name in sculpt_state.ARRAY_NAMES:
        old, new = np.asarray(before.arrays[name], float), np.asarray(after.arrays[name], float)
        if old.shape == new.shape and np.array_equal(old, new):
            continue
        changed = np.flatnonzero(old != new) if old.shape == new.shape else None
        if changed is not None and changed.size < _SPARSE_SHARE * new.size:
            header["arrays"][name] = {"size": int(new.size), "changed": int(changed.size)}
            blobs += [changed.astype("<i4").tobytes(), new[changed].astype("<f8").tobytes()]
        else:
            header["arrays"][name] = {"size": int(new.size)}
            blobs.append(new.astype("<f8").tobytes())
    if after.settings_json() != before.settings_json():
        header["settings"] = after.settings
    head = json.dumps(header, allow_nan=False, sort_keys=True).encode()
    raw = len(head).to_bytes(4, "little") + head + b"".join(blobs)
    return base64.b64encode(zlib.compress(raw, 9)).decode("ascii")


def unpack(packed: str, before: sculpt_state.SculptState) -> sculpt_state.SculptState:
    """``before`` with the change :func:`pack` recorded; ``ValueError`` naming what is wrong if
    the text is not such a change or does not fit ``before``."""
    if not isinstance(packed, str):
        raise TypeError(f"packed: expected the text pack() wrote, got {type(packed).__name__}")
    try:
        raw = zlib.decompress(base64.b64decode(packed.encode("ascii"), validate=True))
        size = int.from_bytes(raw[:4], "little")
        header = json.loads(raw[4:4 + size])
    except (ValueError, binascii.Error, zlib.error, UnicodeEncodeError) as exc:
        raise ValueError(f"packed: not a recorded sculpt state ({exc})") from exc
    body = memoryview(raw)[4 + size:]
    arrays = {k: np.array(v, dtype=float) for k, v in before.arrays.items()}
    offset = 0

    def take(count: int, dtype: str) -> np.ndarray:
        nonlocal offset
        width = np.dtype(dtype).itemsize * count
        if offset + width > len(body):
            raise ValueError("packed: the recorded arrays are cut short")
        out = np.frombuffer(body[offset:offset + width], dtype=dtype).astype(float if dtype == "<f8" else np.int64)
        offset += width
        return out

    recorded = header.get("arrays", {})
    unknown = set(recorded) - set(sculpt_state.ARRAY_NAMES)
    if unknown:
        raise ValueError(f"packed: unknown arrays {sorted(unknown)}")
    for name in (n for n in sculpt_state.ARRAY_NAMES if n in recorded):  # (the order pack() wrote them in)
        entry = recorded[name]
        if "changed" in entry:
            index = take(int(entry["changed"]), "<i4")
            values = take(int(entry["changed"]), "<f8")
            if arrays[name].size != int(entry["size"]) or (index.size and (index.min() < 0 or index.max() >= arrays[name].size)):
                raise ValueError(f"packed: {name} does not fit this sculpt ({arrays[name].size} values)")
            arrays[name][index] = values
        else:
            values = take(int(entry["size"]), "<f8")
            if name not in _MAPS and values.size != arrays[name].size:  # (a painted map may change its grid)
                raise ValueError(f"packed: {name} does not fit this sculpt ({arrays[name].size} values)")
            arrays[name] = values
    if offset != len(body):
        raise ValueError("packed: trailing data after the recorded arrays")
    settings = header["settings"] if header.get("settings") is not None else before.settings
    return sculpt_state.SculptState(arrays, dict(settings))
