"""The workbench's keys and ctrl+z in the 3D view whatever widget had the keyboard last: after
typing in the Python console, the pointer over the view is enough (real X events through xdotool;
the observer reads which widget has the focus)."""
from __future__ import annotations

import os

import pytest
from freecad_support import make_addon_home
from test_gui_real_input import NEEDS, STYLES, USER_CFG, Desktop, sculpt, undo

#: The Python console shown, as View > Panels > Python console leaves it for the next start (FreeCAD
#: 0.20 shows it by default, 1.0 does not).
CONSOLE_SHOWN = ('<FCParamGroup Name="BaseApp"><FCParamGroup Name="MainWindow"><FCParamGroup Name="DockWindows">'
                 '<FCBool Name="Std_PythonView" Value="1"/></FCParamGroup></FCParamGroup>')
#: The combo view (its model tree) shown, as a designer's FreeCAD has it.
TREE_SHOWN = ('<FCParamGroup Name="BaseApp"><FCParamGroup Name="MainWindow"><FCParamGroup Name="DockWindows">'
              '<FCBool Name="Std_ComboView" Value="1"/></FCParamGroup></FCParamGroup>')


def tree_shown_desktop(tmp: str, open_file: str | None = None) -> Desktop:
    """FreeCAD under Xvfb with the model tree shown (and ``open_file`` opened)."""
    home = make_addon_home(os.path.join(tmp, "home"))
    with open(os.path.join(home, "user.cfg"), "w") as f:
        f.write(USER_CFG.format(style=STYLES["CAD"]).replace('<FCParamGroup Name="BaseApp">', TREE_SHOWN))
    return Desktop(tmp, "CAD", open_file=open_file)


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD's GUI")
def test_keys_and_undo_reach_the_view_under_the_pointer_after_the_console_had_them(tmp_path):
    home = make_addon_home(os.path.join(str(tmp_path), "home"))
    with open(os.path.join(home, "user.cfg"), "w") as f:
        f.write(USER_CFG.format(style=STYLES["CAD"]).replace('<FCParamGroup Name="BaseApp">', CONSOLE_SHOWN))
    d = Desktop(str(tmp_path), "CAD")
    try:
        d.wait(lambda s: s["console"], "the Python console shown")
        s = d.press_button("NewPatch", lambda s: s["active"] and sculpt(s)["screen"], "a new patch")
        d.calibrate()
        centre, east, west, _, _ = [d.to_screen(p) for p in sculpt(s)["screen"]]
        for at, key, kind in ((east, "p", "point"), (west, "n", "normal")):
            # the console takes the keyboard: a click in it and a line typed there
            x, y, w, h = d.state()["console"]
            d.xdo("mousemove", str(x + w // 2), str(y + h // 2), "click", "1")
            d.wait(lambda s: s["focus"] == "Gui::PythonConsole", "the console to have the keyboard")
            d.xdo("type", "--delay", "20", "hs_typed = 1")
            d.xdo("key", "Return")
            before = len(sculpt(d.state())["constraints"])
            # the pointer into the view, then the key: a constraint, not a letter in the console
            d.xdo("mousemove", str(at[0]), str(at[1]))
            d.wait(lambda s: s["focus"] != "Gui::PythonConsole" and s["mouse_point"] is not None,
                   "the view to take the keyboard under the pointer")
            d.xdo("key", key)
            s = d.wait(lambda s: len(sculpt(s)["constraints"]) == before + 1, f"{key.upper()}: a {kind} constraint")
            assert sculpt(s)["constraints"][-1][0] == kind
        d.shot("focus_keys_constraints")
        # ctrl+z after the console had the keyboard again: FreeCAD's Undo, not the console's
        x, y, w, h = d.state()["console"]
        d.xdo("mousemove", str(x + w // 2), str(y + h // 2), "click", "1")
        d.wait(lambda s: s["focus"] == "Gui::PythonConsole", "the console to have the keyboard")
        names = undo(d.state())
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        d.wait(lambda s: s["focus"] != "Gui::PythonConsole", "the view to take the keyboard")
        d.shortcut("ctrl+z", "Std_Undo")
        s = d.wait(lambda s: undo(s) == names[1:], "ctrl+z: the last constraint undone")
        assert len(sculpt(s)["constraints"]) == 1
        d.shot("focus_keys_undone")
    finally:
        d.close()


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD's GUI")
def test_a_name_typed_in_the_tree_keeps_its_letters_while_the_pointer_crosses_the_view(tmp_path):
    """A designer renames the sculpt (F2 in the tree) and the pointer drifts over the view while they
    type: P, N, C and M are letters of the name, not constraints and the map display. Once the name
    is in, the pointer over the view gives it the keys again."""
    d = tree_shown_desktop(str(tmp_path))
    try:
        s = d.press_button("NewPatch", lambda s: s["active"] and sculpt(s)["screen"], "a new patch")
        d.calibrate()
        centre, east, _, _, _ = [d.to_screen(p) for p in sculpt(s)["screen"]]
        item = d.wait(lambda s: sculpt(s)["label"] in s["tree"], "the sculpt in the tree")["tree"][sculpt(s)["label"]]
        d.xdo("mousemove", str(item[0]), str(item[1]), "click", "1")
        d.wait(lambda s: sculpt(s)["selected"], "the sculpt selected in the tree")
        d.xdo("key", "F2")
        d.wait(lambda s: s["focus_field"], "the tree's name editor to have the keyboard")
        displays = [ov["display"] for ov in d.state()["overlays"]]
        d.xdo("type", "--delay", "30", "Pan")
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        d.wait(lambda s: s["mouse_point"] is not None, "the pointer over the patch")
        d.xdo("mousemove", str(east[0]), str(east[1]))
        d.xdo("type", "--delay", "30", "el cm")
        d.xdo("key", "Return")
        s = d.wait(lambda s: sculpt(s)["label"] == "Panel cm", "the name typed in full")
        assert sculpt(s)["constraints"] == []
        assert [ov["display"] for ov in s["overlays"]] == displays
        d.shot("focus_keys_renamed")
        # the name is in: the pointer over the view gives it the keys again
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        d.wait(lambda s: not s["focus_field"] and s["focus"] != "Gui::TreeWidget", "the view to take the keyboard")
        d.xdo("key", "p")
        s = d.wait(lambda s: len(sculpt(s)["constraints"]) == 1, "P: a point constraint")
        assert sculpt(s)["constraints"][0][0] == "point"
    finally:
        d.close()


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD's GUI")
def test_keys_with_the_pointer_over_the_tree_leave_the_sculpt_alone(tmp_path):
    """P over the patch pins a point; the pointer then moves onto the model tree, no click: the view
    still has the keyboard, but P, N and M there neither take the pin away, nor add a normal where
    the pointer last was, nor show a map. Back over the view, P works again."""
    d = tree_shown_desktop(str(tmp_path))
    try:
        s = d.press_button("NewPatch", lambda s: s["active"] and sculpt(s)["screen"], "a new patch")
        d.calibrate()
        centre, east, _, _, _ = [d.to_screen(p) for p in sculpt(s)["screen"]]
        d.xdo("mousemove", str(east[0]), str(east[1]))
        d.wait(lambda s: s["mouse_point"] is not None, "the pointer over the patch")
        d.xdo("key", "p")
        s = d.wait(lambda s: len(sculpt(s)["constraints"]) == 1, "P: a point constraint")
        before, displays, view_focus = undo(s), [ov["display"] for ov in s["overlays"]], s["focus"]
        item = d.wait(lambda s: sculpt(s)["label"] in s["tree"], "the sculpt in the tree")["tree"][sculpt(s)["label"]]
        d.xdo("mousemove", str(item[0] + 60), str(item[1] + 120))  # (below the items: the tree's empty part)
        assert d.state()["focus"] == view_focus, "the view lost the keyboard: the keys would prove nothing"
        d.xdo("key", "--delay", "150", "p", "n", "m")
        # nothing may happen, so there is nothing to wait for but what the keys would have done by
        # now: a key typed next over the view is handled after them, in order
        d.xdo("mousemove", str(centre[0]), str(centre[1]))
        d.wait(lambda s: s["mouse_point"] is not None, "the pointer over the patch again")
        d.xdo("key", "c")
        s = d.wait(lambda s: len(sculpt(s)["constraints"]) == 2, "C over the view: a curvature constraint")
        assert [c[0] for c in sculpt(s)["constraints"]] == ["point", "curvature"], sculpt(s)["constraints"]
        assert undo(s)[1:] == before, undo(s)
        assert [ov["display"] for ov in s["overlays"]] == displays
        d.shot("focus_keys_over_tree")
    finally:
        d.close()
