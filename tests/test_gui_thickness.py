"""A designer's first minutes, with real X events (xdotool) in FreeCAD's GUI under Xvfb: New patch
with no document open makes one (its button is never greyed); Thicken asks the thickness in a task
panel (typed, Enter), makes a Thickness that is one undo step and follows the next stroke, and a
double-click on it opens the panel again to change it; a session on it shows a held drag on the
slab as it goes (the sculpt is hidden behind it). Screenshots in build/screenshots/real_thick_*.png."""
from __future__ import annotations

import os
import time

import numpy as np

import pytest
from test_gui_real_input import NEEDS, SHOTS, Desktop, sculpt, undo, view_direction


def doc(s: dict) -> dict:
    return s["docs"][s["active"]]


def shot_changed(d: Desktop, name: str, before: np.ndarray, timeout: float = 20.0) -> np.ndarray:
    """Screenshots until the 3D view's part of the screen differs from ``before`` (redrawn)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        picture = d.shot(name)
        if np.mean(np.abs(picture[160:720, 300:1250] - before[160:720, 300:1250]) > 0.1) > 1e-2:
            return picture
    raise AssertionError(f"{name}: the screen did not change")


def thickness(s: dict) -> dict:
    return next(f for f in doc(s)["features"].values() if f["thickness"] is not None)


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD (make deps installs them)")
def test_new_patch_without_a_document_then_thicken_choosing_the_thickness(tmp_path):
    os.makedirs(SHOTS, exist_ok=True)
    d = Desktop(str(tmp_path), "CAD")
    try:
        assert d.state()["active"] is None and not d.state()["docs"], "FreeCAD started with no document"
        d.click_button("NewPatch")  # (once: it is active with no document, as FreeCAD's Part primitives are)
        s = d.wait(lambda s: s["active"] and doc(s)["sculpts"] and sculpt(s)["screen"], "a new document with a patch")
        assert len(s["docs"]) == 1 and undo(s)[0] == "Create sculpt"
        # seen from above and aside (FreeCAD 0.20 opened the new document from the top, where a
        # drag moved the patch in its own plane, unseen)
        s = d.wait(lambda s: -0.9 < view_direction(s)[2] < -0.3, "an isometric view of the first patch")
        d.shot("thick_new_patch")
        d.calibrate()
        centre = d.to_screen(sculpt(s)["screen"][0])
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        d.wait(lambda s: s["mouse_point"] is not None, "the mouse over the patch")
        # zebra stripes on the patch: they go onto the slab's top when the Thickness hides it
        d.press_button("Zebra", lambda s: any(o["display"] == "zebra" and o["surface_drawn"] for o in s["overlays"]),
                       "the zebra stripes")
        # nothing selected: Thicken takes the document's only sculpt
        d.press_button("Thicken", lambda s: s["task_dialog"], "the thickness panel")
        d.shot("thick_panel")
        d.xdo("key", "--delay", "100", "ctrl+a", "0", "Return")  # 0 mm is refused: the panel stays, says why
        d.xdo("key", "--delay", "100", "ctrl+a", "5", "Return")  # the value is selected: typing replaces it
        s = d.wait(lambda s: not s["task_dialog"] and any(f["thickness"] for f in doc(s)["features"].values()),
                   "the Thickness made", timeout=30)
        made = thickness(s)
        assert [f["thickness"] for f in doc(s)["features"].values() if f["thickness"]] == [5.0], doc(s)["features"]
        assert made["thickness"] == 5.0 and made["valid"] and made["solids"] == 1, made
        assert made["state"] == ["Up-to-date"] and made["visible"], made
        assert 0.85 * 5e4 < made["volume"] < 1.15 * 5e4, made  # 100 x 100 mm by 5 mm (a flat patch)
        assert undo(s)[0] == "Thicken", undo(s)[:3]
        s = d.wait(lambda s: any(o["surface_drawn"] and o["offset"] == 5.0 for o in s["overlays"]),
                   "the stripes on the slab's top, 5 mm up")
        assert [o["display"] for o in s["overlays"]] == ["zebra"]
        assert made["zmax"] > 4.9, made  # (the slab lies on the side the stripes went)
        made_shot = d.shot("thick_made")  # (isometric: the slab's side shows)
        d.xdo("mousemove", "640", "500", "key", "2")  # from the top
        shot_changed(d, "thick_made_top", made_shot)
        item = d.wait(lambda s: "Thickness" in s["tree"], "the Thickness in the tree")["tree"]["Thickness"]
        d.xdo("mousemove", str(item[0]), str(item[1]), "click", "--repeat", "2", "--delay", "80", "1")
        d.wait(lambda s: s["task_dialog"], "the panel to edit the thickness")
        d.xdo("key", "--delay", "100", "ctrl+a", "2", "Return")
        s = d.wait(lambda s: not s["task_dialog"] and thickness(s)["thickness"] == 2.0, "the thickness changed")
        assert thickness(s)["valid"] and 0.85 * 2e4 < thickness(s)["volume"] < 1.15 * 2e4, thickness(s)
        assert undo(s)[:2] == ["Edit thickness", "Thicken"], undo(s)[:3]
        d.shot("thick_edited")
        d.shortcut("ctrl+z", "Std_Undo")
        s = d.wait(lambda s: thickness(s)["thickness"] == 5.0 and abs(thickness(s)["volume"] - made["volume"]) < 1e-6,
                   "Undo of the edit")
        # a session on it (the Thickness selected: its sculpt's): a held drag shows on the slab as it goes
        d.press_button("Session", lambda s: sculpt(s)["session"], "the session")
        d.xdo("mousemove", "640", "500", "key", "1")  # front view: the slab's top rises up the screen
        d.calibrate()
        centre = d.to_screen(sculpt(d.state())["screen"][0])
        before = [o["cursor_at"] for o in d.state()["overlays"]]
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        # (the session's cursor following the pointer: a session's hover lights no preselection)
        d.wait(lambda s: [o["cursor_at"] for o in s["overlays"]] != before, "the session's cursor over the slab")
        d.xdo("mousedown", "1")
        try:
            for k in range(1, 13):
                d.xdo("mousemove", str(centre[0]), str(centre[1] - 6 * k))
                time.sleep(0.03)  # (a hand's pace)
            d.wait(lambda s: thickness(s)["zmax"] > made["zmax"] + 2.0, "the slab following the held drag")
            d.shot("thick_held_drag")
        finally:
            d.xdo("mouseup", "1")
        s = d.wait(lambda s: undo(s)[0] == "Sculpt stroke" and thickness(s)["state"] == ["Up-to-date"],
                   "the stroke's undo step, the slab up to date")
        assert thickness(s)["valid"] and thickness(s)["solids"] == 1 and thickness(s)["zmax"] > made["zmax"] + 2.0
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
        s = d.wait(lambda s: thickness(s)["state"] == ["Up-to-date"], "the slab up to date after the session")
        # Displays off: the zebra and the combs off in one click (Show curvature cycled three more times)
        d.press_button("Combs", lambda s: s["overlays"][0]["combs"], "the combs")
        d.press_button("DisplaysOff", lambda s: s["overlays"][0]["display"] == "shading" and not s["overlays"][0]["combs"],
                       "the displays off")
    finally:
        d.close()
