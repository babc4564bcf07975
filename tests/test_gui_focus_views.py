"""A designer's first hour, with real X events (xdotool) in FreeCAD's GUI under Xvfb: a click that
gives the view the keyboard is no stroke, a session that changes nothing leaves the document
unmodified and takes its cursor away at Stop, constraint jacks show outside a session, a session
follows the pointer into a second view (its HUD too), and the displays cover the face's own
shading and its selection highlight at every zoom. Screenshots: real_focus_*.png."""
from __future__ import annotations

import os
import time

import numpy as np
import pytest
from freecad_support import make_addon_home, run_freecadcmd
from test_gui_real_input import NEEDS, SHOTS, STYLES, USER_CFG, Desktop, sculpt, undo

# Part's default face colour magenta and the selection colour orange (FreeCAD's packed 0xRRGGBBAA),
# neither of which a curvature (green/blue) or zebra (grey) display has.
COLOURS = ('<FCUInt Name="DefaultShapeColor" Value="4278255360"/>'
           '<FCUInt Name="SelectionColor" Value="4286578688"/>')


def saved_patch(tmp_path) -> str:
    """A saved document with a clay patch and a point constraint (so it opens unmodified)."""
    path = str(tmp_path / "patch.FCStd")
    run_freecadcmd(f"""
        import FreeCAD, HapticSculpt
        doc = FreeCAD.newDocument("Patch")
        obj = HapticSculpt.make_sculpt(doc, material="clay")
        HapticSculpt.add_constraint(obj, "point", near=(25.0, 0.0, 0.0))
        doc.recompute()
        doc.saveAs({path!r})
        answer({{}})
        """, str(tmp_path / "make"))
    return path


def desktop(tmp_path, path: str, colours: bool = False) -> Desktop:
    home = os.path.join(str(tmp_path), "home")
    make_addon_home(home)
    cfg = USER_CFG.format(style=STYLES["CAD"])
    if colours:
        cfg = cfg.replace('<FCText Name="NavigationStyle">', COLOURS + '<FCText Name="NavigationStyle">')
    with open(os.path.join(home, "user.cfg"), "w") as f:
        f.write(cfg)
    d = Desktop(str(tmp_path), "CAD", open_file=path)
    s = d.wait(lambda s: s["active"] and s["docs"][s["active"]]["sculpts"] and s["views"], "the file to open")
    camera = s["views"][0]["camera"]
    click_command(d, "Std_ViewFitAll")  # (a file saved without its GUI opens close up)
    d.wait(lambda s: s["views"][0]["camera"] != camera, "Fit all")
    return d


def click_command(d: Desktop, command: str) -> None:
    """Clicks FreeCAD's toolbar button for ``command`` (Std_ViewFitAll, ...) where the observer
    sees it: FreeCAD 0.20 and 1.0 lay out their View toolbars differently."""
    s = d.wait(lambda s: s["toolbars"]["buttons"][command][4], f"the {command} button")
    x, y, w, h, _ = s["toolbars"]["buttons"][command]
    d.xdo("mousemove", str(x + w // 2), str(y + h // 2), "click", "1")


def doc_state(s: dict) -> dict:
    return s["docs"][s["active"]]


def overlays_of(s: dict, view_id: int) -> list[dict]:
    return [o for o in s["overlays"] if o["view"] == view_id]


# A place off the view for the mouse while a screenshot is taken (the toolbars' empty end), and one
# off the face (the model tree).
AWAY, OFF_FACE = ("1100", "40"), ("80", "200")
needs = pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD")


@needs
def test_a_focus_click_is_no_stroke_and_an_idle_session_leaves_the_document_unmodified(tmp_path):
    os.makedirs(SHOTS, exist_ok=True)
    d = desktop(tmp_path, saved_patch(tmp_path))
    try:
        s = d.wait(lambda s: s["overlays"] and s["overlays"][0]["drawn"], "the jacks drawn without a session")
        assert not doc_state(s)["modified"] and not doc_state(s)["gui_modified"]
        d.calibrate()
        centre, east, _, _, south = [d.to_screen(p) for p in sculpt(d.state())["screen"]]
        d.xdo("mousemove", "640", "300")
        time.sleep(0.3)
        img = d.shot("focus_jacks")
        red = (img[..., 0] > 0.8) & (img[..., 1] < 0.2) & (img[..., 2] < 0.2)
        x, y = east
        assert red[y - 30:y + 30, x - 30:x + 30].sum() > 20, "no red point jack near the constraint"
        d.press_button("Session", lambda s: sculpt(s)["session"], "the session")
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        d.wait(lambda s: any(o["cursor"] for o in s["overlays"]), "the session's cursor")
        time.sleep(0.3)
        d.xdo("click", "1")  # the click a designer makes to give the view the keyboard
        time.sleep(0.3)
        d.xdo("mousemove", str(centre[0] + 1), str(centre[1] + 1))  # a hand's tremble: no stroke either
        time.sleep(0.5)
        d.shot("focus_session_clicked")
        s = d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
        s = d.wait(lambda s: not any(o["cursor"] for o in s["overlays"]), "the cursor gone at Stop")
        time.sleep(0.5)  # (a redraw)
        img = d.shot("focus_stopped")
        assert undo(s) == [] and sculpt(s)["strokes"] == 0, "the focus click made a stroke"
        assert not doc_state(s)["modified"] and not doc_state(s)["gui_modified"], ("an idle session modified the document", doc_state(s)["modified"], doc_state(s)["gui_modified"])
        grey = (np.abs(img[..., 0] - 0.9) < 0.03) & (np.abs(img[..., 1] - 0.9) < 0.03) & (np.abs(img[..., 2] - 0.9) < 0.03)
        x, y = centre
        assert grey[y - 25:y + 25, x - 25:x + 25].sum() < 10, "the cursor sphere stayed after Stop"
        assert red[east[1] - 30:east[1] + 30, east[0] - 30:east[0] + 30].sum() > 20, "the jacks went with the session"
        # a real drag still sculpts, right after the session starts
        d.press_button("Session", lambda s: sculpt(s)["session"], "the session again")
        d.drag([south] + [(south[0], south[1] - 10 * k) for k in range(1, 12)], seconds=0.6)
        s = d.wait(lambda s: undo(s) and undo(s)[0] == "Sculpt stroke", "the stroke")
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
        s = d.wait(lambda s: sculpt(s)["strokes"] == 1, "one stroke")
        assert doc_state(s)["gui_modified"], "a stroke is a change"
    finally:
        d.close()


def is_face_colour(img: np.ndarray) -> np.ndarray:
    """Pixels of the face's own colours: magenta as FreeCAD lights it (pink to salmon) and orange
    (selected), all red-dominated; a curvature display has no red, zebra stripes are grey, and
    the pure red of the cursor's x axis is left out."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return (r > 0.6) & (r - g > 0.15) & (g < 0.8 * r) & ((g > 0.1) | (b > 0.1))


def in_view(d: Desktop, shape: tuple[int, ...]) -> np.ndarray:
    """The 3D view's pixels on the screen, without the navigation cube's corner (nor what FreeCAD lays
    over the view: the toolbars' edge, 1.1's Tasks panel)."""
    w, h = d.state()["views"][0]["size"]
    (x0, y0), (x1, y1) = d.to_screen((0, 0)), d.to_screen((w - 1, h - 1))
    inside = np.zeros(shape[:2], bool)
    inside[min(y0, y1):max(y0, y1) + 1, min(x0, x1):max(x0, x1) + 1] = True
    inside[min(y0, y1):min(y0, y1) + 170, max(x0, x1) - 170:] = False
    for bar in d.state()["toolbars"]["bars"].values():  # (the calibration is only as good as the view's
        x, y, bw, bh = bar["rect"]                      # reported mouse; a toolbar's red record button
        inside[max(y, 0):y + bh, max(x, 0):x + bw] = False  # is no face)
    for x, y, pw, ph in d.state().get("overlay_panels", []):  # (FreeCAD 1.1's Tasks panel over the view:
        inside[max(y, 0):y + ph, max(x, 0):x + pw] = False     # its tint made the cursor's red axis pink)
    return inside


@needs
def test_displays_cover_the_face_and_its_selection_at_three_zooms(tmp_path):
    """The curvature display and the zebra stripes on a bowl seen from inside (where the face's
    coarser tessellation is nearer the camera than the displays' meshes), isometric, at three zooms,
    unselected and selected: inside the face's region (3 px in from its outline) not one pixel of
    the face's own shading or of its selection highlight shows through."""
    from scipy import ndimage
    path = str(tmp_path / "bowl.FCStd")
    run_freecadcmd(f"""
        import FreeCAD, Part, HapticSculpt
        doc = FreeCAD.newDocument("Bowl")
        poles = [[FreeCAD.Vector(x, y, (x * x + y * y) / 100.0) for y in (-50, -17, 17, 50)]
                 for x in (-50, -17, 17, 50)]
        surface = Part.BSplineSurface()
        surface.buildFromPolesMultsKnots(poles, [4, 4], [4, 4], [0.0, 1.0], [0.0, 1.0], False, False, 3, 3)
        HapticSculpt.make_sculpt(doc, source=surface)
        doc.recompute()
        doc.saveAs({path!r})
        answer({{}})
        """, str(tmp_path / "make"))
    d = desktop(tmp_path, path, colours=True)
    try:
        camera = d.state()["views"][0]["camera"]
        click_command(d, "Std_ViewIsometric")
        d.wait(lambda s: s["views"][0]["camera"] != camera, "the isometric view")
        leaks = {}
        for selected in (False, True):
            if selected:  # (the isometric view fits all the first time)
                camera = d.state()["views"][0]["camera"]
                click_command(d, "Std_ViewFitAll")
                d.wait(lambda s: s["views"][0]["camera"] != camera, "Fit all")
            d.calibrate()
            centre = d.to_screen(sculpt(d.state())["screen"][0])
            if selected:
                d.xdo("mousemove", str(centre[0]), str(centre[1]), "click", "1")
                d.wait(lambda s: sculpt(s)["selected"], "the sculpt selected by a click")
            for zoom in (0, 4, 8):
                d.xdo("mousemove", *map(str, d.clear_of_panels(centre)))
                time.sleep(0.3)
                if zoom:
                    camera = d.state()["views"][0]["camera"]
                    d.xdo("click", "--repeat", "4", "--delay", "100", "4")
                    d.wait(lambda s: s["views"][0]["camera"] != camera, "the wheel to zoom in")
                d.xdo("mousemove", *OFF_FACE)  # (the mouse's cursor off the face, no preselection)
                time.sleep(0.3)
                d.xdo("mousemove", *AWAY)
                time.sleep(0.5)
                name = f"{'selected' if selected else 'plain'}_{zoom}"
                img = d.shot(f"focus_depth_{name}_face")
                face = ndimage.binary_erosion(is_face_colour(img), iterations=3) & in_view(d, img.shape)
                assert face.sum() > 5000, f"the face is not on screen ({name})"
                for button, display in (("ShowCurvature", "curvature"), ("Zebra", "zebra")):
                    d.press_button(button, lambda s: s["overlays"] and s["overlays"][0]["display"] == display, display)
                    time.sleep(0.5)  # (the timer redraws at 60 Hz; a loaded machine draws late)
                    shown = is_face_colour(d.shot(f"focus_depth_{name}_{display}"))
                    leaks[f"{name}_{display}"] = int((shown & face).sum())
                d.press_button("Zebra", lambda s: s["overlays"][0]["display"] == "shading", "the zebra off")
        assert not any(leaks.values()), leaks
    finally:
        d.close()


@needs
def test_a_session_follows_the_pointer_into_another_view_with_its_hud(tmp_path):
    """A session started in one view of the document works in a second one (View > Create new view):
    the pointer brings the session's cursor and HUD there, and a rope stroke drags in it; back in
    the first view the cursor and HUD come back with it; the hidden view draws no frames."""
    os.makedirs(SHOTS, exist_ok=True)
    d = desktop(tmp_path, saved_patch(tmp_path))
    try:
        first = d.state()["views"][0]["id"]
        d.press_button("Session", lambda s: sculpt(s)["session"], "the session in the first view")
        d.calibrate()
        centre = d.to_screen(sculpt(d.state())["screen"][0])
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        d.wait(lambda s: any(o["cursor"] and o["view"] == first and o["hud"] for o in s["overlays"]),
               "the cursor and HUD in the first view")
        d.xdo("key", "alt+v")  # View > Create new view (the menu's first item)
        d.xdo("key", "Return")
        s = d.wait(lambda s: len(s["views"]) == 2 and s["inputs"] == 2 and s["views"][1]["active"], "the second view")
        second = s["views"][1]["id"]
        d.calibrate()
        _, _, _, _, south = [d.to_screen(p) for p in sculpt(d.state())["screen"]]
        d.xdo("mousemove", str(south[0]), str(south[1]))
        s = d.wait(lambda s: any(o["cursor"] and o["hud"] for o in overlays_of(s, second))
                   and not any(o["cursor"] or o["hud"] for o in overlays_of(s, first)),
                   "the cursor and HUD moved to the second view")
        before = np.array(sculpt(s)["poles"])
        d.drag([south] + [(south[0], south[1] - 10 * k) for k in range(1, 12)], seconds=0.6)
        s = d.wait(lambda s: undo(s) and undo(s)[0] == "Sculpt stroke", "a rope stroke in the second view")
        moved = np.abs(np.array(sculpt(s)["poles"]) - before).max()  # (in the plane: the new view looks from the top)
        assert moved > 1.0, f"the rope did not drag ({moved} mm)"
        d.shot("focus_second_view")
        frames = {o["view"]: o["frames"] for o in s["overlays"]}
        time.sleep(1.0)  # (frames counted over a second: the first view is hidden behind the second's tab)
        s = d.state()
        assert next(o["frames"] for o in overlays_of(s, first)) == frames[first], "the hidden view drew frames"
        d.xdo("key", "ctrl+Tab")  # back to the first view
        d.wait(lambda s: s["views"][0]["active"], "ctrl+tab to the first view")
        d.xdo("mousemove", str(centre[0]), str(centre[1] + 30))
        d.wait(lambda s: any(o["cursor"] and o["hud"] for o in overlays_of(s, first)), "the cursor and HUD back")
        d.shot("focus_first_view_again")
        d.press_button("Session", lambda s: not sculpt(s)["session"], "the session to stop")
    finally:
        d.close()


def test_a_session_sculpts_its_own_document_only(tmp_path):
    """A mouse session on a patch in a second document; the pointer back in the first document's
    view: the session's cursor and HUD stay in its own document's view, and a drag on the first
    patch is FreeCAD's (a rotation), where it sculpted the hidden document's patch out of sight and
    put its undo step in both documents."""
    d = Desktop(str(tmp_path), "CAD")
    try:
        d.xdo("mousemove", "640", "500")
        first_doc = d.new_patch()["active"]
        d.xdo("key", "ctrl+n")
        d.wait(lambda s: len(s["docs"]) == 2 and s["inputs"] == 2, "the second view to be attached")
        s = d.press_button("NewPatch", lambda s: s["active"] != first_doc and s["docs"][s["active"]]["sculpts"],
                           "a patch in the second document")
        second_doc = s["active"]
        d.press_button("Session", lambda s: sculpt(s)["session"], "a session on the second patch")
        poles = s["docs"][second_doc]["sculpts"][0]["poles"]
        undo_lists = {name: s["docs"][name]["undo"] for name in (first_doc, second_doc)}
        d.xdo("key", "ctrl+Tab")  # the first document's view
        d.wait(lambda s: s["active"] == first_doc, "ctrl+tab to the first document")
        first_view = next(v["id"] for v in d.state()["views"] if v["doc"] == first_doc)
        d.calibrate()
        _, _, _, _, south = [d.to_screen(p) for p in sculpt(d.state())["screen"]]
        d.xdo("mousemove", str(south[0]), str(south[1]))
        d.wait(lambda s: s["mouse_point"] is not None, "the pointer over the first patch")
        d.drag([south] + [(south[0], south[1] - 10 * k) for k in range(1, 12)], seconds=0.6)
        d.wait_still(lambda s: [s["docs"][n]["undo"] for n in (first_doc, second_doc)], "the drag's aftermath")
        s = d.state()
        d.shot("session_in_another_document")
        assert {n: s["docs"][n]["undo"] for n in (first_doc, second_doc)} == undo_lists
        moved = np.abs(np.array(s["docs"][second_doc]["sculpts"][0]["poles"]) - np.array(poles)).max()
        assert moved < 1e-6, f"the hidden document's patch was sculpted ({moved} mm)"
        assert s["docs"][second_doc]["sculpts"][0]["session"]
        assert not any(o["cursor"] or o["hud"] for o in s["overlays"] if o["view"] == first_view), \
            "the session's cursor or HUD in another document's view"
        d.xdo("key", "ctrl+Tab")
        d.wait(lambda s: s["active"] == second_doc, "ctrl+tab back to the session's document")
        d.press_button("Session", lambda s: not s["docs"][second_doc]["sculpts"][0]["session"], "the session to stop")
    finally:
        d.close()
