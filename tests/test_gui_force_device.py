"""A force device in FreeCAD's GUI, as a designer with a Novint Falcon meets it: a new patch, the
Session button clicked with real X events, and the session takes the Falcon (the first attached
force device) instead of the mouse, and its status line says the haptic loop runs real-time: it homes, the grip's stroke pulls the surface (one undo step,
shown at once), Undo puts it back while the session runs on. The Falcon is the emulated one behind the fake libusb built with
the C++ tests, loaded through the workbench's own run-time loading (HAPTICSCULPT_LIBUSB); the hand
on its grip follows a script (HS_FAKE_FALCON_SCRIPT). Screenshot: build/screenshots/falcon_stroke.png."""
from __future__ import annotations

import os

import numpy as np
import pytest
from freecad_support import make_addon_home
from test_gui_focus_keys import CONSOLE_SHOWN
from test_gui_real_input import NEEDS, SHOTS, STYLES, USER_CFG, Desktop, sculpt, undo

FAKES = os.environ.get("HS_FAKE_VENDOR", os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                                      "build", "release", "fake_vendor"))

# The hand on the grip (the Falcon's frame, m: y up, the workspace's middle at z = 0.11): at rest
# in the middle for 3 s, then 20 mm up over 0.6 s with the grab button held, let go at 4 s.
HAND = [(0.0, 0.0, 0.0, 0.11, 0), (3.0, 0.0, 0.0, 0.11, 1), (3.6, 0.0, 0.02, 0.11, 1), (4.0, 0.0, 0.02, 0.11, 0),
        (60.0, 0.0, 0.02, 0.11, 0)]


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD (make deps installs them)")
def test_the_session_takes_the_falcon_and_its_stroke_is_one_undo_step(tmp_path, monkeypatch):
    library = os.path.join(FAKES, "libusb-fake.so")
    assert os.path.isfile(library), f"the fake libusb is built by make build: {library}"
    script = tmp_path / "hand.txt"
    script.write_text("\n".join(" ".join(str(v) for v in row) for row in HAND))
    monkeypatch.setenv("HAPTICSCULPT_LIBUSB", library)
    monkeypatch.setenv("HS_FAKE_FALCON_SCRIPT", str(script))
    os.makedirs(SHOTS, exist_ok=True)
    d = Desktop(str(tmp_path), "Gesture")
    try:
        d.new_patch()
        before = undo(d.state())[0]
        s = d.press_button("Session", lambda s: sculpt(s)["session"], "the session")
        assert sculpt(s)["device"] == "falcon", "the session did not take the attached Falcon"
        # the HUD's status line says how the haptic loop runs (the test runs as root: SCHED_FIFO directly)
        d.wait(lambda s: any("1 kHz, real-time (root)" in o["status_text"] for o in s["overlays"]),
               "the loop's rate and priority shown")
        s = d.wait(lambda s: undo(s)[0] == "Sculpt stroke", "the Falcon's stroke as an undo step", 40)
        lifted = np.array(sculpt(s)["poles"]).reshape(-1, 3)[:, 2].max()
        assert lifted > 5.0, f"the grip's stroke did not pull the surface ({lifted} mm)"
        d.wait(lambda s: np.array(sculpt(s)["shape_poles"])[:, 2].max() > 0.7 * lifted, "the stroke to show")
        d.shot("falcon_stroke")
        # ctrl+z while the Falcon still sculpts: the flat patch shows at once, the session runs on
        d.shortcut("ctrl+z", "Std_Undo")
        s = d.wait(lambda s: undo(s)[0] == before and np.abs(np.array(sculpt(s)["shape_poles"])[:, 2]).max() < 1e-3,
                   "Undo to show the flat patch")
        assert sculpt(s)["session"] and sculpt(s)["device"] == "falcon"
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
    finally:
        d.close()


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD (make deps installs them)")
def test_a_force_dimension_device_runs_its_session_at_4_khz_and_a_preference_lowers_it(tmp_path, monkeypatch):
    """A Force Dimension omega.3 (the fake libdhd, loaded through HAPTICSCULPT_DHD_LIB as the real one
    would be) attached: the Session button's session runs at the limits table's fastest rate for it,
    4 kHz, and says so in the status line; with the preference Mod/HapticSculpt/MaxHapticRate at
    2000 (Edit > Preferences > HapticSculpt) the next session runs at 2 kHz."""
    monkeypatch.setenv("HAPTICSCULPT_DHD_LIB", os.path.join(FAKES, "libdhd.so"))
    monkeypatch.delenv("HAPTICSCULPT_LIBUSB", raising=False)
    home = make_addon_home(os.path.join(str(tmp_path), "home"))
    with open(os.path.join(home, "user.cfg"), "w") as f:  # (the Python console shown: FreeCAD 1.x hides it)
        f.write(USER_CFG.format(style=STYLES["Gesture"]).replace('<FCParamGroup Name="BaseApp">', CONSOLE_SHOWN))
    d = Desktop(str(tmp_path), "Gesture")
    try:
        d.wait(lambda s: s["console"], "the Python console shown")
        d.new_patch()
        s = d.press_button("Session", lambda s: sculpt(s)["session"], "the session")
        assert sculpt(s)["device"] == "dhd" and sculpt(s)["haptic_rate"] == 4000.0, sculpt(s)
        d.wait(lambda s: any("4 kHz, real-time" in o["status_text"] for o in s["overlays"]), "4 kHz in the status line")
        d.shot("dhd_4khz")
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
        x, y, w, h = d.state()["console"]  # (the line typed where a user types it)
        d.xdo("mousemove", str(x + w // 2), str(y + h // 2), "click", "1")
        d.wait(lambda s: s["focus"] == "Gui::PythonConsole", "the console to have the keyboard")
        d.xdo("type", "--delay", "20", 'App.ParamGet("User parameter:BaseApp/Preferences/Mod/HapticSculpt")'
                                       '.SetFloat("MaxHapticRate", 2000)')
        d.xdo("key", "Return")
        s = d.press_button("Session", lambda s: sculpt(s)["session"], "the second session")
        assert sculpt(s)["haptic_rate"] == 2000.0, sculpt(s)
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the second session to stop")
    finally:
        d.close()
