"""The workbench in the real FreeCAD GUI under Xvfb: it loads as an addon, its commands run, and the
sculpt face is drawn. Writes build/screenshots/gui_workbench.png (look at it; docs/ holds the copy
the README shows)."""
from __future__ import annotations

import os

import numpy as np
import pytest
from freecad_support import GUI_AVAILABLE, ROOT, SCREENSHOTS, run_freecad_gui

GUI_SCRIPT = """
import json, os, traceback
import FreeCAD, FreeCADGui as Gui
out = {{}}
try:
    Gui.activateWorkbench("HapticSculptWorkbench")
    out["workbench"] = Gui.activeWorkbench().name()
    out["commands"] = [c for c in Gui.listCommands() if c.startswith("HapticSculpt_")]
    doc = FreeCAD.newDocument("GuiTest")
    Gui.updateGui()
    out["active_new"] = Gui.Command.get("HapticSculpt_NewPatch").isActive() if hasattr(Gui, "Command") else None
    Gui.runCommand("HapticSculpt_NewPatch")
    obj = doc.getObject("Sculpt")
    import HapticSculpt as hs
    hs.run(obj, 1.5, device=hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 35.0), seconds=1.0))
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(obj)
    Gui.runCommand("HapticSculpt_Thicken")  # (asks the thickness in a task panel: test_gui_thickness types one)
    out["thicken_panel"] = Gui.Control.activeDialog()
    Gui.Control.closeDialog()
    hs.make_thickness(obj, 2.0)
    doc.recompute()
    out["objects"] = [o.Name for o in doc.Objects]
    out["icon"] = obj.ViewObject.Proxy.getIcon()
    view = Gui.ActiveDocument.ActiveView
    obj.ViewObject.ShapeColor = (0.9, 0.3, 0.1)
    doc.getObject("Thickness").ViewObject.Visibility = False
    obj.ViewObject.Visibility = True
    Gui.Selection.clearSelection()  # (selection is drawn green)
    view.viewIsometric()
    view.fitAll()
    for _ in range(5):
        Gui.updateGui()
    view.saveImage({png!r}, 800, 600, "White")
    from HapticSculpt.gui.mouse_device import MouseDevice
    mouse = MouseDevice()
    mouse.attach(view)
    size = view.getSize()
    out["mouse_centre"] = list(mouse.move_to(view, (size[0] // 2, size[1] // 2)))
    out["mouse_corner"] = list(mouse.move_to(view, (2, 2)))
    mouse.press(True)
    # (the device passes on what was pushed in turn, one sample a tick: the hover, then the press)
    out["mouse_samples"] = [mouse.native.sample(0.001 * k)["buttons"] for k in range(3)]
    mouse.detach()
    # A threaded session in the GUI: a Coin timer redraws the shape at graphics rate and commits strokes.
    import time
    sculpt2 = hs.make_sculpt(doc, name="Live", size=(50.0, 50.0))
    sculpt2.Placement.Base = FreeCAD.Vector(120, 0, 0)
    session = hs.Session().start(sculpt2, hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 20.0), seconds=0.8, hold=0.2),
                                 stop_when_finished=True)
    heights, t0 = [], time.monotonic()
    while session.running and time.monotonic() - t0 < 10:
        Gui.updateGui()
        heights.append(sculpt2.Shape.BoundBox.ZLength)
        time.sleep(0.01)
    Gui.updateGui()
    out["live_heights"] = sorted(set(round(h, 3) for h in heights))
    out["live_strokes"] = sculpt2.Strokes
    out["live_undo"] = doc.UndoNames[:2]
    # Leaving the workbench stops every session (force first, then the threads join).
    session2 = hs.Session().start(sculpt2, hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 5.0), seconds=5.0))
    time.sleep(0.2)
    running_before = session2.running
    Gui.activateWorkbench("PartWorkbench")
    Gui.updateGui()
    out["workbench_stop"] = [running_before, session2.running]
    # A document saved by 0.1 (module paths from before the layer split) opens with its view provider.
    old = FreeCAD.openDocument({legacy!r})
    vp = old.getObject("Sculpt").ViewObject.Proxy
    out["legacy_view_provider"] = [type(vp).__module__, os.path.basename(vp.getIcon())]
except Exception:
    out["error"] = traceback.format_exc()
json.dump(out, open({answer}, "w"))
os._exit(0)
"""


@pytest.mark.skipif(not GUI_AVAILABLE, reason="needs Xvfb and the FreeCAD GUI (make deps installs both)")
def test_workbench_loads_and_commands_run(tmp_path):
    os.makedirs(SCREENSHOTS, exist_ok=True)
    png = os.path.join(SCREENSHOTS, "gui_workbench.png")
    if os.path.exists(png):
        os.remove(png)
    legacy = os.path.join(ROOT, "tests", "fixtures", "documents", "sculpt_0_1.FCStd")
    out = run_freecad_gui(GUI_SCRIPT.format(png=png, legacy=legacy, answer="{answer}"), str(tmp_path))
    assert "error" not in out, out["error"]
    assert out["workbench"] == "HapticSculptWorkbench"
    assert set(out["commands"]) >= {"HapticSculpt_NewPatch", "HapticSculpt_SculptFace", "HapticSculpt_Thicken",
                                    "HapticSculpt_ExportStep"}
    assert {"Sculpt", "Thickness"} <= set(out["objects"]) and out["thicken_panel"]
    assert np.all(np.isfinite(out["mouse_centre"])) and np.all(np.isfinite(out["mouse_corner"]))
    assert abs(out["mouse_centre"][2]) < 60.0  # on the sculpt (a bump up to ~35 mm), not the far plane
    assert out["mouse_samples"] == [0, 1, 1]
    # the shape moved while the threads ran: redrawn at heights between the start and the end (a GUI
    # loop beside three other FreeCADs saw 5 heights, at 3 to 8 where idle)
    assert len(out["live_heights"]) >= 4, out["live_heights"]
    assert out["live_strokes"] == 1 and "Sculpt stroke" in out["live_undo"]
    assert out["workbench_stop"] == [True, False]
    assert out["legacy_view_provider"] == ["HapticSculpt.gui.view_provider", "HapticSculpt.svg"]
    assert out["icon"].endswith("HapticSculpt.svg") and os.path.exists(out["icon"])
    import matplotlib.image as mpimg
    img = mpimg.imread(png)[..., :3]
    orange = (img[..., 0] > 0.5) & (img[..., 1] < 0.6) & (img[..., 2] < 0.45) & (img[..., 0] - img[..., 2] > 0.3)
    assert orange.mean() > 0.02, "the sculpt face (orange) is not in the picture"
    assert np.mean(np.all(img > 0.95, axis=2)) > 0.3, "expected a white background"
