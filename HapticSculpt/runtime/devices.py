"""Devices a session can drive: what is attached (hidapi/hidraw), SpaceMouse, HID PID force
feedback and replays (the mouse is the GUI's: HapticSculpt.gui.mouse_device). All loops run in
C++; these are thin, validated constructors."""
from __future__ import annotations

import os
from typing import Any, Sequence

from ..core import native as _core

#: The udev rules for the supported devices (install with `sudo make install-udev`).
UDEV_RULES = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, "udev",
                                          "70-hapticsculpt.rules"))


def native_device(device: Any) -> Any:
    """The C++ device for a Python-side device description."""
    if isinstance(device, _core.Device):
        return device
    native = getattr(device, "native", None)
    if isinstance(native, _core.Device):
        return native
    raise TypeError(f"device: expected a ReplayDevice or a HapticSculpt device, got {type(device).__name__}")


def list_devices() -> list[dict[str, Any]]:
    """Attached HID interfaces, each with ``kind``: "spacemouse" for a known SpaceMouse, else "hid"."""
    out = []
    for d in _core.hid_devices():
        d = dict(d)
        d["kind"] = "spacemouse" if d["spacemouse"] else "hid"
        out.append(d)
    return out


def spacemouse(path: str | None = None, recording: str | None = None, mode: str = "rate",
               translation_scale: float = 100.0, rotation_scale: float = 1.5, dead_zone: float = 0.05,
               origin: Sequence[float] = (0.0, 0.0, 0.0), paced: bool = True) -> Any:
    """A SpaceMouse from its hidraw ``path`` (see :func:`list_devices`), or the first attached one, or
    from a hid-recorder ``recording`` file. ``mode``: "rate" (mm/s and rad/s at full deflection) or
    "position" (mm and rad at full deflection)."""
    if path is None and recording is None:
        found = [d for d in list_devices() if d["kind"] == "spacemouse"]
        if not found:
            raise ValueError("path: no SpaceMouse is attached (check the udev rules: devices.UDEV_RULES)")
        path = found[0]["path"]
    if recording is not None and not os.path.isfile(recording):
        raise ValueError(f"recording: no such file {recording!r}")
    return _core.SpaceMouseDevice(path=path, recording=recording, paced=paced, mode=mode,
                                  translation_scale=translation_scale, rotation_scale=rotation_scale,
                                  dead_zone=dead_zone, origin=list(map(float, origin)))


def force_feedback(input_device: Any, output: Any, full_scale_force: float, max_force: float,
                   max_stiffness: float) -> Any:
    """Cursor from ``input_device``, force to a HID PID device: ``output`` is its hidraw path or a
    transport (e.g. ``_core.PidEmulator()``). Forces are in the session's units (mN with mm, kg, s);
    ``full_scale_force`` maps to the device's largest magnitude."""
    driver = _core.PidForceDriver(output, full_scale_force=full_scale_force)
    return _core.ForceFeedbackDevice(native_device(input_device), driver, max_force, max_stiffness)
