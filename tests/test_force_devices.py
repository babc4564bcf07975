"""The 3-DOF force devices from Python, through the same run-time loading a real installation
uses, with the fake libusb (an FTDI bridge and an emulated Falcon), OpenHaptics and DHD libraries
built with the C++ tests, and a mock Haply Inverse Service on loopback (haply_service_mock.py): devices.list() naming what is attached and why something is not usable,
devices.pick() preferring a force device, a threaded session with each, the limits table, and
validation at the boundary."""
from __future__ import annotations

import ctypes
import os
import time

import numpy as np
import pytest
from haply_service_mock import MockInverseService

from HapticSculpt import core
from HapticSculpt.core import native as _core
from HapticSculpt.runtime import devices

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FAKES = os.environ.get("HS_FAKE_VENDOR", os.path.join(ROOT, "build", "release", "fake_vendor"))
LIBS = {"falcon": os.path.join(FAKES, "libusb-fake.so"), "openhaptics": os.path.join(FAKES, "libHD.so"),
        "dhd": os.path.join(FAKES, "libdhd.so")}


@pytest.fixture()
def fakes():
    assert all(os.path.isfile(p) for p in LIBS.values()), f"the fake vendor libraries are built by make build: {FAKES}"
    usb, hd, dhd = (ctypes.CDLL(LIBS[k]) for k in ("falcon", "openhaptics", "dhd"))
    usb.fake_usb_reset(1)
    hd.fake_hd_reset()
    dhd.fake_dhd_reset()
    yield usb, hd, dhd
    hd.fake_hd_reset()  # (stops its scheduler)


def script(lib, prefix, rows):
    flat = (ctypes.c_double * (5 * len(rows)))(*[v for r in rows for v in r])
    getattr(lib, prefix + "script")(flat, len(rows))


def test_list_names_each_device_and_why_one_is_not_usable(fakes, tmp_path, monkeypatch):
    usb, hd, dhd = fakes
    monkeypatch.delenv(devices.FALCON_FIRMWARE_ENV, raising=False)
    usb.fake_usb_reset(0)  # a Falcon just powered up: no firmware running
    found = devices.list(libraries=LIBS)
    kinds = [d["kind"] for d in found]
    assert kinds[:3] == ["falcon", "openhaptics", "dhd"]
    falcon = found[0]
    assert falcon["force"] and not falcon["usable"] and devices.FALCON_FIRMWARE_ENV in falcon["why"]
    assert found[1]["usable"] and found[1]["name"] == "Touch"
    assert found[2]["usable"] and found[2]["name"] == "Force Dimension (DHD)"
    # the firmware file given: usable (it is loaded when the device is made)
    image = tmp_path / "falcon.bin"
    image.write_bytes(bytes(range(256)) * 4)
    assert devices.list(firmware=str(image), libraries=LIBS)[0]["usable"]
    monkeypatch.setenv(devices.FALCON_FIRMWARE_ENV, str(image))
    assert devices.list(libraries=LIBS)[0]["usable"]
    # no permission: says how to get it
    usb.fake_usb_denied(1)
    falcon = devices.list(libraries=LIBS)[0]
    assert not falcon["usable"] and "udev" in falcon["why"]
    # no Touch attached, no DHD device: nothing listed for them (their libraries load, nothing is there)
    usb.fake_usb_denied(0)
    hd.fake_hd_present(0)
    dhd.fake_dhd_devices(0)
    assert [d["kind"] for d in devices.list(libraries=LIBS)][:1] == ["falcon"]
    assert all(d["kind"] not in ("openhaptics", "dhd") for d in devices.list(libraries=LIBS))


def test_the_falcons_firmware_is_loaded_from_the_users_file(fakes, tmp_path):
    usb, _, _ = fakes
    usb.fake_usb_reset(0)
    image = bytes((7 * k) % 251 for k in range(1000))
    usb.fake_usb_expected_firmware(image, len(image))
    path = tmp_path / "falcon.bin"
    path.write_bytes(image)
    with pytest.raises(RuntimeError, match="firmware is not loaded"):
        devices.falcon(firmware="", library=LIBS["falcon"])
    dev = devices.falcon(firmware=str(path), library=LIBS["falcon"])
    assert usb.fake_usb_firmware_running() == 1
    dev.start()  # homes
    assert dev.sample(0.0)["valid"]
    dev.stop()


def test_pick_prefers_a_force_device(fakes):
    dev = devices.pick(libraries=LIBS)
    assert isinstance(dev, _core.FalconDevice)
    usb, hd, _ = fakes
    usb.fake_usb_devices(0)
    assert isinstance(devices.pick(libraries=LIBS), _core.OpenHapticsDevice)
    hd.fake_hd_present(0)
    assert isinstance(devices.pick(libraries=LIBS), _core.DhdDevice)


def test_a_session_runs_at_the_devices_fastest_rate_from_the_limits_table(fakes):
    """A Falcon and a Touch: 1 kHz; a Force Dimension device (DHD names its model only once
    opened: its rows' fastest, 4 kHz); a user's limit lowers it, never below 100 Hz; the
    passivity bound the device takes is the one at that rate."""
    dev, rate = devices.pick_with_rate(libraries=LIBS)
    assert isinstance(dev, _core.FalconDevice) and rate == 1000.0
    usb, hd, _ = fakes
    usb.fake_usb_devices(0)
    dev, rate = devices.pick_with_rate(libraries=LIBS)
    assert isinstance(dev, _core.OpenHapticsDevice) and rate == 1000.0
    hd.fake_hd_present(0)
    dev, rate = devices.pick_with_rate(libraries=LIBS)
    assert isinstance(dev, _core.DhdDevice) and rate == 4000.0
    assert dev.capabilities["max_stiffness"] > 3.9 * devices.pick_with_rate(libraries=LIBS, max_rate=1000)[0] \
        .capabilities["max_stiffness"]  # (K <= 2 b / T: four times the rate, four times as stiff)
    assert devices.pick_with_rate(libraries=LIBS, max_rate=2000)[1] == 2000.0
    assert devices.pick_with_rate(libraries=LIBS, max_rate=20)[1] == 100.0
    assert devices.pick_with_rate(libraries=LIBS, rate=3000)[1] == 3000.0  # (a rate given is the rate)
    assert devices.fastest_rate("omega.3") == 4000.0 and devices.fastest_rate("Touch X") == 1000.0
    assert devices.fastest_rate("a device nobody knows") == 1000.0
    for bad in (-1.0, float("nan")):
        with pytest.raises(ValueError, match="max_rate"):
            devices.pick_with_rate(libraries=LIBS, max_rate=bad)


def test_the_haply_service_is_listed_and_picked_first(fakes):
    with MockInverseService(devices=("049D", "04BA")) as service:
        libraries = dict(LIBS, haply=service.address)
        found = devices.list(libraries=libraries)
        assert [(d["kind"], d["usable"]) for d in found[:3]] == [("haply", True), ("haply", True), ("falcon", True)]
        assert found[1]["device_id"] == "04BA"
        dev = devices.pick(libraries=libraries)
        assert isinstance(dev, _core.HaplyDevice)
        dev.start()
        assert dev.device_id == "049D" and dev.sample(0.0)["valid"]
        dev.stop()
        assert service.first_command["session"]["configure"]["basis"] == {"permutation": "XYZ"}
    with MockInverseService(in_use=True) as service:
        haply = devices.list(libraries=dict(LIBS, haply=service.address))[0]
        assert haply["kind"] == "haply" and not haply["usable"] and "in use" in haply["why"]
    # no service: nothing listed for it, and a clear error when asked for
    assert all(d["kind"] != "haply" for d in devices.list(libraries=dict(LIBS, haply=f"127.0.0.1:{service.port}")))
    with pytest.raises(RuntimeError, match="Inverse Service"):
        devices.haply(service=f"127.0.0.1:{service.port}").start()
    with pytest.raises(ValueError, match="host:port"):
        devices.haply(service="localhost")


@pytest.mark.parametrize("kind", ["haply", "falcon", "openhaptics", "dhd"])
def test_a_threaded_session_with_each_device_pulls_the_surface(fakes, kind):
    usb, hd, dhd = fakes
    ramp = [(t, min(1.0, t / 0.6) * 0.02, 1.0 if t < 0.8 else 0.0) for t in (0.0, 0.6, 0.8, 5.0)]
    if kind == "haply":  # Haply: z up; the grip where it is at the start maps to the origin
        with MockInverseService([(t, 0.0, 0.0, up, b) for t, up, b in ramp]) as service:
            run_stroke(devices.haply(service=service.address))
            assert service.largest_force > 0.01  # N: the grip was pulled back
        return
    if kind == "falcon":  # the Falcon's frame: y up, the workspace's middle at z = 0.11 m
        script(usb, "fake_usb_", [(t, 0.0, up, 0.11, b) for t, up, b in ramp])
        dev = devices.falcon(library=LIBS["falcon"])
    elif kind == "openhaptics":  # HD: y up
        script(hd, "fake_hd_", [(t, 0.0, up, 0.0, b) for t, up, b in ramp])
        dev = devices.openhaptics(library=LIBS["openhaptics"])
    else:  # DHD: z up
        script(dhd, "fake_dhd_", [(t, 0.0, 0.0, up, b) for t, up, b in ramp])
        dev = devices.dhd(library=LIBS["dhd"])
    run_stroke(dev)


def run_stroke(dev) -> None:
    """A threaded session on a flat patch until its first stroke ends: the surface was lifted."""
    surface = core.patch((8, 8), (3, 3), (24, 24), (100.0, 100.0))
    rt = _core.HapticRuntime(surface, dev)
    rt.start()
    deadline = time.monotonic() + 30
    while rt.status()["strokes"] < 1 and time.monotonic() < deadline:
        time.sleep(0.01)
    rt.stop()
    status = rt.status()
    assert status["error"] == "" and status["strokes"] == 1
    assert np.max(surface.poles[..., 2]) > 0.05  # mm: the stroke lifted the surface


def test_the_limits_table_is_the_passivity_bound():
    rows = {r["model"]: r for r in devices.limits()}
    falcon = rows["Novint Falcon"]
    assert falcon["rated_force"] == 8.0
    assert falcon["max_stiffness"] == pytest.approx([2 * falcon["damping"] * r for r in falcon["rates"]])
    assert rows["omega.3"]["max_stiffness"][1] == pytest.approx(4 * rows["omega.3"]["max_stiffness"][0])  # at 4 kHz


def test_bad_arguments_are_refused_at_the_boundary(fakes, tmp_path):
    with pytest.raises(ValueError, match="origin"):
        devices.openhaptics(origin=(0, 0), library=LIBS["openhaptics"])
    with pytest.raises(ValueError, match="firmware"):
        devices.falcon(firmware=str(tmp_path / "missing.bin"), library=LIBS["falcon"])
    with pytest.raises(ValueError, match="index"):
        devices.falcon(index=-1, library=LIBS["falcon"])
    with pytest.raises(ValueError, match="scale"):
        devices.dhd(scale=0.0, library=LIBS["dhd"])
    with pytest.raises(RuntimeError, match="has no symbol"):
        devices.dhd(library=LIBS["openhaptics"])
