"""New patch from curves as a designer does it in FreeCAD's GUI, with real X events: a file with a
sketch drawing a 100 x 80 loop, a sketch standing across it (an arc 12 mm high) and a stray line
outside it. Pressed with two of the loop's edges: it says what to select. The loop's four edges
and the stray line clicked in the 3D view, New patch from curves: refused in one line, nothing
made; the loop's edges and the arc: a patch on the loop through the arc in one undo step; a mouse
stroke beside the arc leaves the patch on it; Undo twice: the stroke, then the patch.
Screenshots in build/screenshots/real_network_*.png (look at them)."""
from __future__ import annotations

import os

import numpy as np
import pytest
from freecad_support import run_freecad_gui
from test_gui_focus_keys import tree_shown_desktop
from test_gui_follow_curve import click_in_view
from test_gui_real_input import NEEDS, SHOTS, Desktop, sculpt, undo

#: The loop (one sketch, four lines), the arc standing across it at x = 0 and the stray line at x = 70.
SCENE = """
import json, os
import FreeCAD, FreeCADGui, Part
V = FreeCAD.Vector
doc = FreeCAD.newDocument("Network")
loop = doc.addObject("Sketcher::SketchObject", "Loop")
p = [V(-50, -40, 0), V(50, -40, 0), V(50, 40, 0), V(-50, 40, 0)]
for k in range(4):
    loop.addGeometry(Part.LineSegment(p[k], p[(k + 1) % 4]), False)
ridge = doc.addObject("Sketcher::SketchObject", "Ridge")
ridge.Placement = FreeCAD.Placement(V(0, 0, 0), FreeCAD.Rotation(V(1, 1, 1), 120))  # (its x, y: y, z)
ridge.addGeometry(Part.Arc(V(-40, 0, 0), V(0, 12, 0), V(40, 0, 0)), False)
stray = doc.addObject("Sketcher::SketchObject", "Stray")
stray.addGeometry(Part.LineSegment(V(70, -30, 0), V(70, 30, 0)), False)
doc.recompute()
doc.saveAs(PATH)
json.dump({}, open({answer}, "w"))
os._exit(0)
"""


def pick_in_view(d: Desktop, picks: list[tuple[str, int]]) -> None:
    """Edges clicked in the 3D view, each (object, its edge's index), the first plainly and the
    others with ctrl: all selected."""
    s = d.state()
    for k, (name, edge) in enumerate(picks):
        points = s["docs"][s["active"]]["edge_points"][name]
        count = len(points) // 3  # (each edge's middle, then its thirds)
        click_in_view(d, points[edge::count], name, add=k > 0)
        d.wait(lambda s: sum(len(subs) for _, subs in s["selection"]) == k + 1, f"{k + 1} edges selected")


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD (make deps installs them)")
def test_new_patch_from_curves_refuses_a_stray_curve_makes_a_patch_through_the_arc_keeps_it_on_through_a_stroke(
        tmp_path):
    os.makedirs(SHOTS, exist_ok=True)
    path = str(tmp_path / "network.FCStd")
    run_freecad_gui(f"PATH = {path!r}\n" + SCENE, str(tmp_path))
    d = Desktop(str(tmp_path), "CAD", open_file=path)
    try:
        d.wait(lambda s: s["active"] and s["docs"][s["active"]]["screen"].get("Loop"), "the file")
        d.xdo("mousemove", "640", "500", "key", "0")  # isometric
        d.xdo("key", "--delay", "150", "v", "f")  # fit all
        d.calibrate()
        d.wait_still(lambda s: s["docs"][s["active"]]["screen"]["Loop"], "the loop on screen after the fit")
        before = d.shot("network_before")
        # pressed with two edges selected: it says what to select (it was greyed out, with no reason)
        loop = [("Loop", k) for k in range(4)]
        pick_in_view(d, loop[:2])
        d.click_button("NewFromCurves")
        d.wait(lambda s: "New patch from curves: 2 curves selected: select 3 or 4 curves that close into a loop"
               in (s.get("report") or ""), "what to select, in the report view")
        empty = d.to_screen([20, next(v for v in d.state()["views"] if v["active"])["size"][1] // 2])  # (beside it all)
        d.xdo("mousemove", str(empty[0]), str(empty[1]), "click", "1")
        d.wait(lambda s: s["selection"] == [], "nothing selected")
        # the loop and a line outside it: refused, one line in the report view, nothing made
        pick_in_view(d, loop + [("Stray", 0)])
        d.click_button("NewFromCurves")
        s = d.wait(lambda s: "New patch from curves: curve: 'Stray Edge1' runs off the face" in (s.get("report") or ""),
                   "the refusal in the report view")
        assert "Traceback" not in s["report"], s["report"][-2000:]
        assert not s["docs"][s["active"]]["sculpts"] and undo(s) == [], undo(s)
        # the loop and the arc: a patch on the loop through the arc, one undo step
        d.xdo("mousemove", str(empty[0]), str(empty[1]), "click", "1")
        d.wait(lambda s: s["selection"] == [], "nothing selected")
        pick_in_view(d, loop + [("Ridge", 0)])
        d.click_button("NewFromCurves")  # (once: a second click would make a second patch)
        s = d.wait(lambda s: s["docs"][s["active"]]["sculpts"] and sculpt(s)["curves"], "the patch", timeout=60)
        [(kind, distance, _)] = sculpt(s)["curves"]
        assert kind == "G0" and distance <= 0.001, sculpt(s)["curves"]
        assert undo(s)[0] == "Patch from curves", undo(s)[:3]
        poles = np.array(sculpt(s)["poles"]).reshape(-1, 3)
        assert 11.0 < poles[:, 2].max() < 20.0 and poles[:, 2].min() > -1e-6, "raised over the arc, on the loop"
        assert np.ptp(poles[:, 0]) == pytest.approx(100.0) and np.ptp(poles[:, 1]) == pytest.approx(80.0)
        assert "a patch on 4 boundary curves through 1 curve inside" in s["report"], s["report"][-1000:]
        made = d.shot_changed("network_made", before, "the patch")
        # a mouse stroke 25 mm beside the arc: the patch still passes through it
        beside = d.points_to_screen([(25.0, 0.0, 7.0)])[0]
        d.press_button("Session", lambda s: sculpt(s)["session"], "the session")
        d.drag([beside] + [(beside[0], beside[1] - 8 * k) for k in range(1, 7)], seconds=0.6)
        d.wait(lambda s: undo(s)[0] == "Sculpt stroke", "the stroke")
        d.click_button("Session")
        s = d.wait(lambda s: not sculpt(s)["session"], "the session to stop")
        assert np.abs(np.array(sculpt(s)["poles"]).reshape(-1, 3) - poles).max() > 0.1, "the stroke moved the patch"
        [(kind, distance, _)] = sculpt(s)["curves"]
        assert kind == "G0" and distance <= 0.001, sculpt(s)["curves"]
        d.shot_changed("network_stroked", made, "the stroke")
        # Undo twice: the stroke, then the patch
        d.shortcut("ctrl+z", "Std_Undo")
        d.wait(lambda s: undo(s)[0] == "Patch from curves", "Undo of the stroke")
        d.shortcut("ctrl+z", "Std_Undo")
        d.wait(lambda s: not s["docs"][s["active"]]["sculpts"], "Undo of the patch: no patch")
        d.shot("network_undone")
    finally:
        d.close()


#: One sketch drawing three sides of a square: a boundary that does not close.
OPEN_LOOP = """
import json, os
import FreeCAD, FreeCADGui, Part
V = FreeCAD.Vector
doc = FreeCAD.newDocument("Open")
sides = doc.addObject("Sketcher::SketchObject", "Sides")
p = [V(-50, -40, 0), V(50, -40, 0), V(50, 40, 0), V(-50, 40, 0)]
for k in range(3):
    sides.addGeometry(Part.LineSegment(p[k], p[k + 1]), False)
doc.recompute()
doc.saveAs(PATH)
json.dump({}, open({answer}, "w"))
os._exit(0)
"""


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD (make deps installs them)")
def test_one_sketch_whose_sides_do_not_close_is_refused_saying_where(tmp_path):
    """A sketch of three sides picked in the tree alone, New patch from curves: refused saying
    which end meets no other (it said "1 curve selected", as for a single line), nothing made."""
    path = str(tmp_path / "open.FCStd")
    run_freecad_gui(f"PATH = {path!r}\n" + OPEN_LOOP, str(tmp_path))
    d = tree_shown_desktop(str(tmp_path), open_file=path)
    try:
        item = d.wait(lambda s: "Sides" in s["tree"], "the sketch in the tree")["tree"]["Sides"]
        d.xdo("mousemove", str(item[0]), str(item[1]), "click", "1")
        d.wait(lambda s: [o for o, _ in s["selection"]] == ["Sides"], "the sketch selected in the tree")
        d.click_button("NewFromCurves")
        s = d.wait(lambda s: "New patch from curves: " in (s.get("report") or ""), "the refusal in the report view")
        said = s["report"][s["report"].index("New patch from curves: "):]
        assert "do not close" in said and "'Sides Edge" in said and "selected" not in said.split("\n")[0], said
        assert "Traceback" not in s["report"], s["report"][-2000:]
        assert not s["docs"][s["active"]]["sculpts"] and undo(s) == [], undo(s)
        d.shot("network_open_refused")
    finally:
        d.close()
