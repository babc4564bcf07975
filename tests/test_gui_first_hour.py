"""A designer's first hour, as a fresh-eyes trial met it: FreeCAD's real GUI under Xvfb, real X
input (xdotool). A stroke on a very stiff sculpt says in the HUD why it barely moved; a session
sets the selection aside until it stops (its green tint hid the shading) and commands act on the
session's sculpt; Start/stop sculpting in another document moves the session there; the displays
shown come back with the file. Screenshots: build/screenshots/real_first_hour_*.png."""
from __future__ import annotations

import os

import pytest
from test_gui_panel_hud import calibrate, overlay
from test_gui_real_input import NEEDS, Desktop, sculpt, undo

pytestmark = pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD")
STIFFNESS = 2  # the stiffness slider's row in the panel


def set_slider(d: Desktop, k: int, to: float) -> None:
    """Drags slider k's knob to the fraction ``to`` of its track, as a hand does."""
    s = d.state()
    x0, y0, x1, y1 = overlay(s)["hud"][f"track{k + 1}"]
    f = overlay(s)["sliders"][k][3]
    y = (y0 + y1) / 2
    d.drag([d.to_screen([x0 + (f + (to - f) * t / 7) * (x1 - x0), y]) for t in range(8)], seconds=0.5)


def pull(d: Desktop, at: tuple[int, int], strokes: int) -> dict:
    """A drag 120 pixels up from ``at``; the state once it is committed as stroke number ``strokes``
    and the HUD has drawn a new line for it (the observer can read the document's count before the
    HUD's next frame)."""
    before = overlay(d.state())["status_text"]
    d.drag([at] + [(at[0], at[1] - 15 * k) for k in range(1, 9)], seconds=0.6)
    return d.wait(lambda s: sculpt(s)["strokes"] == strokes and "last stroke" in overlay(s)["status_text"]
                  and overlay(s)["status_text"] != before, f"stroke {strokes} and the HUD's line for it")


def test_a_stiff_sculpt_says_why_a_stroke_barely_moved_and_a_session_owns_the_selection(tmp_path):
    d = Desktop(str(tmp_path), "CAD")
    try:
        d.xdo("mousemove", "640", "500")
        s = d.new_clamped_patch()
        d.press_button("Panel", lambda s: f"track{STIFFNESS + 1}" in overlay(s)["hud"], "the slider panel")
        calibrate(d)
        centre = d.to_screen(sculpt(s)["screen"][0])
        d.xdo("mousemove", str(centre[0]), str(centre[1]), "click", "1")
        d.wait(lambda s: sculpt(s)["selected"], "the patch selected by a click")
        s = d.press_button("Session", lambda s: sculpt(s)["session"], "a mouse session")
        s = d.wait(lambda s: not sculpt(s)["selected"], "the selection cleared at the start")
        # the stiffest the slider goes: a pull of some 30 mm moves the clamped patch by hundredths
        set_slider(d, STIFFNESS, 1.0)
        s = d.wait(lambda s: undo(s)[0] == "Set stiffness" and overlay(s)["sliders"][STIFFNESS][1] > 5e4,
                   "the stiffness at its top")
        s = pull(d, centre, 1)
        text = overlay(s)["status_text"]
        d.shot("first_hour_stiff_stroke")
        assert "holds it, lower it in the slider panel" in text, text
        # commands act on the session's sculpt with nothing selected: the zebra display
        d.press_button("Zebra", lambda s: overlay(s)["display"] == "zebra", "the zebra display")
        d.press_button("Zebra", lambda s: overlay(s)["display"] == "shading", "the zebra display off")
        # the softest: the same pull moves it, and the HUD says how far, with no hint
        set_slider(d, STIFFNESS, 0.0)
        d.wait(lambda s: undo(s)[0] == "Set stiffness" and overlay(s)["sliders"][STIFFNESS][1] < 10,
               "the stiffness at its bottom")
        s = pull(d, centre, 2)
        text = overlay(s)["status_text"]
        d.shot("first_hour_soft_stroke")
        assert "holds it" not in text and "held there" not in text, text
        moved = float(text.split("last stroke moved it ")[1].split(" mm")[0])
        assert moved > 5.0, text
        # ctrl+z takes the stroke back, and the HUD no longer speaks of it
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        d.shortcut("ctrl+z", "Std_Undo")
        d.wait(lambda s: undo(s)[0] == "Set stiffness" and "last stroke" not in overlay(s)["status_text"],
               "ctrl+z: the stroke and the HUD's line for it gone")
        # the selection set aside at the start comes back at the stop
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
        d.wait(lambda s: sculpt(s)["selected"], "the patch selected again")
    finally:
        d.close()


def test_start_stop_moves_a_session_to_another_document_and_displays_come_back_with_the_file(tmp_path):
    path = str(tmp_path / "zebra.FCStd")
    d = Desktop(str(tmp_path), "CAD")
    try:
        d.xdo("mousemove", "640", "500")
        s = d.new_clamped_patch()
        first = s["active"]
        d.press_button("Zebra", lambda s: overlay(s)["display"] == "zebra", "the zebra display")
        d.press_button("Combs", lambda s: overlay(s)["combs"], "the curvature combs")
        d.save_as(path)
        d.focus()  # (no window manager gives the keys back to the main window after a dialog)
        d.press_button("Session", lambda s: sculpt(s)["session"], "a session in the first document")
        s = d.new_patch()  # (ctrl+n: a second document, and a patch in it)
        second = s["active"]
        assert second != first and s["docs"][first]["sculpts"][0]["session"]
        s = d.press_button("Session", lambda s: s["active"] == second and sculpt(s)["session"],
                           "Start/stop sculpting in the second document: the session moved there")
        assert not s["docs"][first]["sculpts"][0]["session"], "the first document's session still runs"
        assert s["session"]
        d.wait(lambda s: "sculpting Sculpt with the mouse" in overlay(s)["status_text"], "the HUD to say so")
        d.shot("first_hour_session_moved")
    finally:
        d.close()  # (killed: the file on disk is what was saved)
    os.remove(os.path.join(str(tmp_path), "state.json"))
    d = Desktop(str(tmp_path), "CAD", open_file=path)
    try:
        s = d.wait(lambda s: s["active"] and s["docs"][s["active"]]["sculpts"] and s["overlays"], "the file to open")
        s = d.wait(lambda s: overlay(s)["display"] == "zebra" and overlay(s)["combs"] and overlay(s)["drawn"],
                   "the zebra display and the combs back, as saved")
        assert not s["docs"][s["active"]]["modified"], "reopening marked the document modified"
        d.shot("first_hour_reopened_zebra")
    finally:
        d.close()
