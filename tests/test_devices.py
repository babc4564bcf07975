"""The device layer from Python: fixtures through the threaded session, HID PID output through an
emulated device, udev rules matching the supported ids, and malformed input from Python."""
from __future__ import annotations

import os
import re
import time

import numpy as np
import pytest

from HapticSculpt import core
from HapticSculpt.core import native as _core
from HapticSculpt.runtime import devices
from HapticSculpt.runtime.devices import native_device
from HapticSculpt.runtime.replay_device import ReplayDevice

FIXTURES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fixtures", "hid")


def run_runtime(surface, device, seconds):
    rt = _core.HapticRuntime(surface, device)
    rt.start()
    time.sleep(seconds)
    rt.stop()
    return rt.status()


def test_udev_rules_cover_every_model_with_uaccess_only():
    text = open(devices.UDEV_RULES).read()
    rules = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]

    def ids(prefix):
        return {(int(v, 16), int(p, 16)) for v, p in
                (re.search(r'idVendor}=="([0-9a-f]{4})", ATTRS{idProduct}=="([0-9a-f]{4})"', r).groups()
                 for r in rules if r.startswith(prefix))}
    assert ids('KERNEL=="hidraw*"') == {(v, p) for v, p, _ in _core.spacemouse_models()}
    assert ids('SUBSYSTEM=="usb"') == {(0x0403, 0xcb48)}  # the Falcon, and no other USB device
    for r in rules:
        assert r.startswith(('KERNEL=="hidraw*"', 'SUBSYSTEM=="usb"')) and r.endswith('TAG+="uaccess"'), r
        assert "MODE" not in r and "GROUP" not in r and "#" not in r


@pytest.mark.parametrize("fixture", ["spacenavigator.hid", "spacemouse_compact.hid", "spacemouse_wireless.hid"])
def test_fixtures_drive_a_session(fixture):
    dev = devices.spacemouse(recording=os.path.join(FIXTURES, fixture), mode="position", translation_scale=35.0,
                             paced=True)
    status = run_runtime(core.patch((8, 8), (3, 3), (20, 20)), dev, 0.4)
    assert status["error"] == ""
    assert status["haptic_ticks"] > 20  # nothing grabbed on a resting surface: the idle polling rate
    state = dev.state
    assert state["reports"] > 0 and state["malformed"] == 0


def test_session_with_hid_pid_force_feedback_stops_every_effect():
    emulator = _core.PidEmulator()
    stroke = ReplayDevice.stroke((0, 0, 0), (0, 0, 30.0), seconds=0.3, hold=2.0)
    device = devices.force_feedback(stroke, emulator, full_scale_force=200.0, max_force=150.0, max_stiffness=500.0)
    assert device.capabilities["force_output"]
    surface = core.patch((8, 8), (3, 3), (20, 20))
    rt = _core.HapticRuntime(surface, device)
    rt.start()
    time.sleep(0.4)
    live = [e for e in emulator.effects() if e["allocated"]]
    assert len(live) == 3 and all(e["running"] for e in live)
    assert any(e["magnitude"] != 0 for e in live)
    rt.stop()
    assert not any(e["running"] for e in emulator.effects())
    assert emulator.stop_all_count == 1 and not emulator.actuators_enabled


def test_unplugged_force_device_fails_cleanly():
    emulator = _core.PidEmulator()
    emulator.unplug()
    driver = _core.PidForceDriver(emulator, 100.0)
    with pytest.raises(RuntimeError, match="HID PID"):
        driver.start()


def test_malformed_reports_and_descriptors_from_python():
    p = _core.SpaceMouseParser()
    rng = np.random.default_rng(3)
    for _ in range(5000):
        p.feed(bytes(rng.integers(0, 256, rng.integers(0, 70)).astype(np.uint8)))
    s = p.state
    assert s["malformed"] + s["unknown"] + s["reports"] == 5000
    with pytest.raises(ValueError, match="descriptor"):
        _core.parse_report_descriptor(bytes([0xA1, 0x01]))
    with pytest.raises(ValueError, match="recording"):
        devices.spacemouse(recording="/nonexistent.hid")
    with pytest.raises(ValueError, match="mode"):
        devices.spacemouse(recording=os.path.join(FIXTURES, "spacenavigator.hid"), mode="warp")


def test_external_device_rejects_non_finite_input():
    mouse = _core.ExternalDevice()
    with pytest.raises(ValueError, match="finite"):
        mouse.push([0.0, float("nan"), 0.0])
    with pytest.raises(TypeError, match="device"):
        native_device(42)


def test_list_devices_works_without_hardware():
    assert isinstance(devices.list_devices(), list)  # this machine has no HID devices attached


def test_idle_polling_and_full_rate_on_grab():
    """At rest with nothing grabbed the device is polled at idle_rate; a grab restores full rate."""
    mouse = _core.ExternalDevice()
    mouse.push([0.0, 0.0, 30.0])
    rt = _core.HapticRuntime(core.patch((8, 8), (3, 3), (20, 20)), mouse, idle_rate=100.0)
    rt.start()
    time.sleep(0.6)
    idle_ticks = rt.status()["haptic_ticks"]
    mouse.push([0.0, 0.0, 0.0], buttons=1)
    time.sleep(0.05)
    t0 = rt.status()["haptic_ticks"]
    time.sleep(0.5)
    grabbed_ticks = rt.status()["haptic_ticks"] - t0
    rt.stop()
    assert idle_ticks < 200          # ~100 Hz (plus the first moments before the surface slept)
    assert grabbed_ticks > 400       # ~1 kHz while grabbing
