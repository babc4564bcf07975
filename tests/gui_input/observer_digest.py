"""The fingerprint the real-input tests compare a sculpt's state by, in the GUI and in console mode."""
import hashlib
import struct

from HapticSculpt.app.sculpt_state import ARRAY_NAMES


def digest(o):
    """One fingerprint of a sculpt's whole stored state (every array, bit for bit, and the settings)."""
    h = hashlib.sha256()
    for name in ARRAY_NAMES:
        values = list(getattr(o, name))
        h.update(name.encode() + struct.pack(f"<{len(values)}d", *values))
    h.update(o.SculptSettings.encode())
    return h.hexdigest()
