"""Devices a session can drive: what is attached (:func:`list`), the 3-DOF force devices (Haply
Inverse3 through its Inverse Service, Novint Falcon, 3D Systems Touch/Phantom through OpenHaptics,
Force Dimension through DHD), the SpaceMouse,
HID PID force feedback and replays (the mouse is the GUI's: HapticSculpt.gui.mouse_device). All
loops run in C++; these are thin, validated constructors. Forces are in the session's units: mN
with the workbench's mm, kg and s (``force_scale`` = N per session force unit)."""
from __future__ import annotations

import builtins
import glob
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


def list_devices() -> builtins.list[dict[str, Any]]:
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
                                  dead_zone=dead_zone, origin=_point(origin))


def force_feedback(input_device: Any, output: Any, full_scale_force: float, max_force: float,
                   max_stiffness: float) -> Any:
    """Cursor from ``input_device``, force to a HID PID device: ``output`` is its hidraw path or a
    transport (e.g. ``_core.PidEmulator()``). Forces are in the session's units (mN with mm, kg, s);
    ``full_scale_force`` maps to the device's largest magnitude."""
    driver = _core.PidForceDriver(output, full_scale_force=full_scale_force)
    return _core.ForceFeedbackDevice(native_device(input_device), driver, max_force, max_stiffness)


#: Where the Falcon's firmware file is looked for when none is given (see the README).
FALCON_FIRMWARE_ENV = "HAPTICSCULPT_FALCON_FIRMWARE"
#: USB vendor ids of the devices that need a vendor's library (usb.ids): 3D Systems, Force Dimension.
_VENDOR_USB_IDS = {"openhaptics": "2988", "dhd": "1451"}


#: Where the Haply Inverse Service listens ("host:port"), if not on this machine's port 10001.
HAPLY_SERVICE_ENV = "HAPTICSCULPT_HAPLY_SERVICE"


def _haply_address(service: str | None) -> tuple[str, int]:
    text = service if service is not None else os.environ.get(HAPLY_SERVICE_ENV, "127.0.0.1:10001")
    host, _, port = text.rpartition(":")
    if not host or not port.isdigit():
        raise ValueError(f"service: expected 'host:port', got {text!r}")
    return host, int(port)


def _point(origin: Sequence[float]) -> builtins.list[float]:
    values = [float(v) for v in origin]
    if len(values) != 3:
        raise ValueError(f"origin: expected 3 numbers, got {len(values)}")
    return values


#: Environment variables naming a library to load instead of the system's, per kind (a vendor's SDK
#: installed off the loader's path, e.g. /opt/OpenHaptics/Developer/lib/libHD.so).
LIBRARY_ENV = {"falcon": "HAPTICSCULPT_LIBUSB", "openhaptics": "HAPTICSCULPT_OPENHAPTICS_LIB",
               "dhd": "HAPTICSCULPT_DHD_LIB"}


def _library(library: str | Sequence[str] | None, kind: str) -> builtins.list[str] | None:
    if library is None:
        library = os.environ.get(LIBRARY_ENV[kind]) or None
    if library is None:
        return None
    return [library] if isinstance(library, str) else [str(x) for x in library]


def _usb_vendors() -> set[str]:
    """USB vendor ids attached (sysfs; no library or permission needed)."""
    found = set()
    for path in glob.glob("/sys/bus/usb/devices/*/idVendor"):
        try:
            with open(path, encoding="utf-8") as f:
                found.add(f.read().strip().lower())
        except OSError:
            pass
    return found


def falcon_firmware(firmware: str | None = None) -> str:
    """The Falcon firmware file to use: ``firmware``, else $HAPTICSCULPT_FALCON_FIRMWARE, else ""."""
    path = firmware if firmware is not None else os.environ.get(FALCON_FIRMWARE_ENV, "")
    if path and not os.path.isfile(path):
        raise ValueError(f"firmware: no such file {path!r}")
    return path


def _rate(rate: float | None) -> dict[str, float]:
    """The rate argument for a force device: none for None, so that the core's default (the haptic
    loop's, core.DEFAULTS["haptic_rate"]) applies."""
    return {} if rate is None else {"rate": float(rate)}


def haply(device_id: str = "", service: str | None = None, origin: Sequence[float] = (0.0, 0.0, 0.0),
          scale: float = 1.0, force_scale: float = 1e-3, max_force: float = 0.0, rate: float | None = None) -> Any:
    """A Haply Inverse3 through the Inverse Service (``service`` "host:port", else
    $HAPTICSCULPT_HAPLY_SERVICE, else this machine's port 10001); ``device_id`` "" takes the first
    one it lists. Where the grip is at ``start()`` maps to ``origin``."""
    host, port = _haply_address(service)
    return _core.HaplyDevice(host=host, port=port, device_id=str(device_id), origin=_point(origin), scale=scale,
                             force_scale=force_scale, max_force=max_force, **_rate(rate))


def falcon(index: int = 0, firmware: str | None = None, origin: Sequence[float] = (0.0, 0.0, 0.0),
           scale: float = 1.0, force_scale: float = 1e-3, max_force: float = 0.0, rate: float | None = None,
           library: str | Sequence[str] | None = None) -> Any:
    """The ``index``-th Novint Falcon on USB. Its firmware (Novint's, loaded after each power-up) comes
    from ``firmware`` or $HAPTICSCULPT_FALCON_FIRMWARE when it is not running yet. ``origin``: where
    the middle of its workspace sits in the document (mm); ``scale``: document mm per mm of travel.
    Call ``start()`` (or start a session) to home it."""
    if int(index) < 0:
        raise ValueError("index: must be >= 0")
    return _core.FalconDevice(index=int(index), firmware=falcon_firmware(firmware), library=_library(library, "falcon"),
                              origin=_point(origin), scale=scale, force_scale=force_scale, max_force=max_force,
                              **_rate(rate))


def openhaptics(origin: Sequence[float] = (0.0, 0.0, 0.0), scale: float = 1.0, force_scale: float = 1e-3,
                max_force: float = 0.0, rate: float | None = None, library: str | Sequence[str] | None = None) -> Any:
    """3D Systems Touch / Phantom (its default device) through OpenHaptics, loaded at run time."""
    return _core.OpenHapticsDevice(library=_library(library, "openhaptics"), origin=_point(origin), scale=scale,
                                   force_scale=force_scale, max_force=max_force, **_rate(rate))


def dhd(origin: Sequence[float] = (0.0, 0.0, 0.0), scale: float = 1.0, force_scale: float = 1e-3,
        max_force: float = 0.0, rate: float | None = None, library: str | Sequence[str] | None = None) -> Any:
    """The first Force Dimension device through the DHD SDK, loaded at run time."""
    return _core.DhdDevice(library=_library(library, "dhd"), origin=_point(origin), scale=scale,
                           force_scale=force_scale, max_force=max_force, **_rate(rate))


def list(firmware: str | None = None, libraries: dict[str, Any] | None = None) -> builtins.list[dict[str, Any]]:
    """What is attached, force devices first, each a dict with ``kind`` ("haply", "falcon",
    "openhaptics", "dhd", "spacemouse", "hid"), ``name``, ``model`` (its row in the limits table, "" if
    unknown), ``force`` (renders force), ``usable`` and, when it is not,
    ``why`` (no permission, the Falcon's firmware file missing, the vendor's library missing, in
    use). ``libraries`` maps a kind to the library to load instead of the system's, and "haply" to
    the Inverse Service's "host:port"."""
    libraries = libraries or {}
    out: builtins.list[dict[str, Any]] = []
    host, port = _haply_address(libraries.get("haply"))
    try:  # (a service that is not running refuses at once)
        inverse3s = _core.haply_devices(host=host, port=port, timeout=1.0)
    except RuntimeError:
        inverse3s = []
    for d in inverse3s:
        why = ("in use by another program" if d["in_use"] else
               "" if d["ready"] else "not ready (powered? see the Haply Hub)")
        out.append({"kind": "haply", "name": f"Haply Inverse3 {d['device_id']}", "device_id": d["device_id"],
                    "model": "Haply Inverse3", "force": True, "usable": not why, "why": why})
    try:
        falcons = _core.usb_falcons(library=_library(libraries.get("falcon"), "falcon"))
    except RuntimeError as e:  # no libusb: Falcons can only be seen through sysfs
        falcons = []
        if any(_sysfs_has("0403", "cb48")):
            out.append({"kind": "falcon", "name": "Novint Falcon", "force": True, "usable": False, "why": str(e)})
    for k, f in enumerate(falcons):
        why = f["why"]
        if not why and not f["firmware_running"]:
            try:
                given = falcon_firmware(firmware)
            except ValueError as e:
                why = str(e)
            else:
                if not given:
                    why = (f"its firmware is not loaded (it must be, after each power-up): set ${FALCON_FIRMWARE_ENV} "
                           "to Novint's firmware file (see the README)")
        out.append({"kind": "falcon", "name": f"Novint Falcon (USB {f['bus']}:{f['address']})", "index": k,
                    "model": "Novint Falcon", "force": True, "usable": not why, "why": why})
    vendors = _usb_vendors()
    for kind, probe, name in (("openhaptics", _core.openhaptics_probe, "3D Systems Touch/Phantom (OpenHaptics)"),
                              ("dhd", _core.dhd_probe, "Force Dimension (DHD)")):
        p = probe(library=_library(libraries.get(kind), kind))
        if p["loaded"]:
            if p["attached"] > 0:
                out.append({"kind": kind, "name": p["model"] or name, "model": p["model"], "force": True, "usable": True,
                            "why": ""})
            elif _VENDOR_USB_IDS[kind] in vendors:
                out.append({"kind": kind, "name": name, "model": "", "force": True, "usable": False, "why": p["why"]})
        elif _VENDOR_USB_IDS[kind] in vendors:  # its device is there, its library is not
            out.append({"kind": kind, "name": name, "model": "", "force": True, "usable": False,
                        "why": f"the vendor's library is not installed: {p['why']}"})
    for d in list_devices():
        access = not os.path.exists(d["path"]) or os.access(d["path"], os.R_OK | os.W_OK)  # (hidraw: a node)
        out.append({"kind": d["kind"], "name": d["spacemouse"] or d["name"], "path": d["path"], "model": "", "force": False,
                    "usable": access,
                    "why": "" if access else "no permission to open it: install the udev rules (sudo make install-udev)"
                    })
    return out


def _sysfs_has(vendor: str, product: str) -> builtins.list[bool]:
    hits = []
    for path in glob.glob("/sys/bus/usb/devices/*/idVendor"):
        try:
            with open(path, encoding="utf-8") as f, open(os.path.join(os.path.dirname(path), "idProduct"), encoding="utf-8") as g:
                hits.append(f.read().strip() == vendor and g.read().strip() == product)
        except OSError:
            pass
    return hits


#: The limits table's rows of each kind of force device (DHD names its model only once opened).
KIND_MODELS = {"dhd": ("omega", "delta", "sigma", "lambda"), "openhaptics": ("Touch", "Phantom"),
               "falcon": ("Novint Falcon",)}


def fastest_rate(model: str, kind: str = "") -> float:
    """The fastest servo rate (Hz) the limits table gives the device ``model`` (a row whose model
    is a case-insensitive prefix of it: "omega.3" 4 kHz, a Falcon 1 kHz); for a model not named or
    not in the table, the slowest of the fastest rates of its ``kind``'s rows (every Force Dimension row: 4 kHz); else
    the haptic loop's default (a device the table does not know is not driven faster than tested)."""
    rows = limits()
    for row in rows:
        if model and model.lower().startswith(row["model"].lower()):
            return float(row["rates"][1])
    family = [float(r["rates"][1]) for r in rows
              if r["model"].lower().startswith(tuple(m.lower() for m in KIND_MODELS.get(kind, ())))]
    return min(family) if family else float(_core.DEFAULTS["haptic_rate"])


def pick(firmware: str | None = None, libraries: dict[str, Any] | None = None, **mapping: Any) -> Any | None:
    """The device a session should use: the first usable force device (Inverse3, Falcon,
    Touch/Phantom, Force Dimension), else the first usable SpaceMouse, else None (the caller takes
    the mouse).
    ``mapping``: origin, scale, force_scale, max_force, rate for a force device."""
    return pick_with_rate(firmware, libraries, **mapping)[0]


def pick_with_rate(firmware: str | None = None, libraries: dict[str, Any] | None = None, max_rate: float = 0.0,
                   **mapping: Any) -> tuple[Any | None, float]:
    """:func:`pick`, and the haptic rate (Hz) to run its session at: a force device's fastest from
    the limits table (:func:`fastest_rate`), at most ``max_rate`` where that is > 0 (a user's
    preference), unless ``mapping`` gives the rate; the loop's default for the others."""
    libraries = libraries or {}
    default = float(_core.DEFAULTS["haptic_rate"])
    if not max_rate >= 0:  # (NaN too)
        raise ValueError(f"max_rate: must be >= 0 Hz (0: the device's fastest), got {max_rate}")
    for d in list(firmware, libraries):
        if not d["usable"]:
            continue
        rate = float(mapping.get("rate", default))
        if d["force"] and "rate" not in mapping:
            rate = fastest_rate(d["model"], d["kind"])
            rate = min(rate, max(float(max_rate), 100.0)) if max_rate > 0 else rate
            mapping = dict(mapping, rate=rate)
        if d["kind"] == "haply":
            return haply(d["device_id"], libraries.get("haply"), **mapping), rate
        if d["kind"] == "falcon":
            return falcon(d["index"], firmware, library=libraries.get("falcon"), **mapping), rate
        if d["kind"] == "openhaptics":
            return openhaptics(library=libraries.get("openhaptics"), **mapping), rate
        if d["kind"] == "dhd":
            return dhd(library=libraries.get("dhd"), **mapping), rate
        if d["kind"] == "spacemouse":
            return spacemouse(d["path"], origin=mapping.get("origin", (0.0, 0.0, 0.0))), default
    return None, default


def limits() -> builtins.list[dict[str, Any]]:
    """The force devices' limits table (README "Force devices"): rated force (N), damping (N s/m),
    servo rates (Hz) and the passive stiffness bound at each (N/m), with their source."""
    return _core.device_limits()
