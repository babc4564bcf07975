"""Devices a session can drive: what is attached (hidapi/hidraw), SpaceMouse, HID PID force
feedback, replays and the mouse. All loops run in C++; these are thin, validated constructors."""
from __future__ import annotations

import os
from typing import Any, Sequence

from . import _core

#: The udev rules for the supported devices (install with `sudo make install-udev`).
UDEV_RULES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "udev",
                          "70-hapticsculpt.rules")


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


class MouseDevice:
    """The 3D cursor follows the mouse in a FreeCAD 3D view: onto the surface under the pointer, or
    onto the view's focal plane elsewhere; the left button grabs. Only usable with the GUI up."""

    def __init__(self, name: str = "mouse") -> None:
        self.native = _core.ExternalDevice(name)
        self._callbacks: list[Any] = []
        self._buttons = 0
        self._position = (0.0, 0.0, 0.0)

    def attach(self, view: Any) -> None:
        """Follows the mouse in ``view`` (a FreeCADGui 3D view) until :meth:`detach`."""
        self.attach_all([view])

    def attach_all(self, views: Sequence[Any]) -> None:
        """Follows the mouse in each of ``views``, wherever it is, until :meth:`detach`."""
        from pivy import coin

        from .coin_events import FrontCallbacks
        self.detach()
        for view in views:
            self._callbacks.append(FrontCallbacks(view, [
                (coin.SoLocation2Event, (lambda v: lambda cb: self._on_move(v, cb))(view)),
                (coin.SoMouseButtonEvent, (lambda v: lambda cb: self._on_button(v, cb))(view))]))

    def detach(self) -> None:
        """Stops following the mouse (the device stays usable; its cursor stays where it was)."""
        for callbacks in self._callbacks:
            callbacks.remove()
        self._callbacks = []

    def move_to(self, view: Any, pixel: Sequence[int]) -> tuple[float, float, float]:
        """Puts the cursor under ``pixel`` of ``view`` (surface point if any, else the focal plane)."""
        x, y = int(pixel[0]), int(pixel[1])
        info = view.getObjectInfo((x, y))
        if info and all(k in info for k in ("x", "y", "z")):
            p = (float(info["x"]), float(info["y"]), float(info["z"]))
        else:
            v = view.getPoint(x, y)
            p = (float(v.x), float(v.y), float(v.z))
        self._position = p
        self.native.push(list(p), buttons=self._buttons)
        return p

    def press(self, held: bool) -> None:
        """Button 1 (grab) held or released at the current cursor."""
        self._buttons = 1 if held else 0
        self.native.push(list(self._position), buttons=self._buttons)

    def _on_move(self, view: Any, cb: Any) -> None:
        pos = cb.getEvent().getPosition()
        self.move_to(view, (pos[0], pos[1]))
        if self._buttons:
            cb.setHandled()  # a grab: not a selection box or a rotation

    def _on_button(self, view: Any, cb: Any) -> None:
        from pivy import coin
        event = cb.getEvent()
        if event.getButton() == coin.SoMouseButtonEvent.BUTTON1:
            pos = event.getPosition()
            self.move_to(view, (pos[0], pos[1]))
            self.press(event.getState() == coin.SoButtonEvent.DOWN)
            cb.setHandled()
