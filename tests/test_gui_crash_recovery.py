"""Nothing released is lost to a crash: FreeCAD's real GUI under Xvfb, real X input (xdotool).
Three strokes released in a saved document and three in one never saved, FreeCAD killed (SIGKILL)
with the second session running, started again: FreeCAD's own Document Recovery brings both back
with every stroke, whatever its recovery interval (15 minutes here, FreeCAD's default).
Screenshots: build/screenshots/real_crash_recovery_*.png."""
from __future__ import annotations

import pytest
from test_gui_real_input import NEEDS, Desktop, sculpt, undo

pytestmark = pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD")


def three_strokes(d: Desktop) -> dict:
    """A session on the active document's patch and three pulls up from its centre, each released
    and committed; the state after the third (the session still runs)."""
    s = d.press_button("Session", lambda s: sculpt(s)["session"], "a session")
    d.calibrate()
    centre = d.to_screen(sculpt(s)["screen"][0])
    for k in range(1, 4):
        at = (centre[0] + 40 * (k - 2), centre[1])
        d.drag([at] + [(at[0], at[1] - 12 * j) for j in range(1, 7)], seconds=0.5)
        s = d.wait(lambda s: sculpt(s)["strokes"] == k, f"stroke {k} committed")
    return s


def written(s: dict, doc: str) -> bool:
    """Whether ``doc``'s recovery file holds its every undo step (no write pending)."""
    done = s["recovery"]["docs"].get(doc)
    return not s["recovery"]["pending"] and done is not None and done["undo_steps"] == len(s["docs"][doc]["undo"])


def test_released_strokes_come_back_through_freecads_recovery_after_a_kill(tmp_path):
    path = str(tmp_path / "saved.FCStd")
    d = Desktop(str(tmp_path), "CAD")
    try:
        d.xdo("mousemove", "640", "500")
        saved = d.new_patch()["active"]
        d.save_as(path)
        d.focus()  # (no window manager gives the keys back to the main window after a dialog)
        three_strokes(d)
        d.xdo("mousemove", "640", "500")
        unsaved = d.new_patch()["active"]  # (ctrl+n: a second document; the first one's session stops)
        three_strokes(d)
        s = d.wait(lambda s: written(s, saved) and written(s, unsaved), "both recovery files written")
        assert undo(s)[:3] == ["Sculpt stroke"] * 3, undo(s)
        before = {doc: s["docs"][doc]["sculpts"][0] for doc in (saved, unsaved)}
        costs = [s["recovery"]["docs"][doc]["seconds"] for doc in (saved, unsaved)]
        print(f"recovery file written in {costs[0] * 1e3:.1f} ms (saved), {costs[1] * 1e3:.1f} ms (never saved)")
        assert max(costs) < 1.0, costs  # (a few ms measured: a runaway write would show here)
        d.shot("crash_recovery_before_kill")
    finally:
        d.close()  # SIGKILL, the second session running
    d = Desktop(str(tmp_path), "CAD")
    try:
        d.wait_window("Document Recovery", timeout=60, click_in=True)
        d.shot("crash_recovery_dialog")
        d.xdo("key", "Return")  # Start Recovery
        s = d.wait(lambda s: len(s["docs"]) == 2 and all(doc["sculpts"] for doc in s["docs"].values()),
                   "both documents recovered")
        d.wait_window("Document Recovery", click_in=True)
        d.xdo("key", "Return")  # Finish
        by_file = {doc["file"]: doc for doc in s["docs"].values()}
        assert set(by_file) == {path, ""}, list(by_file)
        for doc, file in ((saved, path), (unsaved, "")):
            back = by_file[file]["sculpts"][0]
            assert back["strokes"] == 3, (file, back["strokes"])
            assert back["poles"] == before[doc]["poles"], f"{file or 'the unsaved document'}: the poles differ"
        d.wait(lambda s: s["active"] and s["docs"][s["active"]]["sculpts"] and s["overlays"], "the recovered view")
        d.shot("crash_recovery_recovered")
    finally:
        d.close()
