"""Every GUI command that edits a sculpt is one undo step, named for what it did: undo gives back
the state before it and redo the state after it, bit for bit (FreeCAD's GUI under Xvfb; the real
X-event tests cover the keys, strokes and paint, this covers each command)."""
from __future__ import annotations

import pytest
from freecad_support import GUI_AVAILABLE, run_freecad_gui

GUI_SCRIPT = """
import json, os, sys, traceback
import FreeCAD, FreeCADGui as Gui
out = {"steps": []}
try:
    Gui.activateWorkbench("HapticSculptWorkbench")
    import HapticSculpt
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HapticSculpt.__file__)), "tests", "gui_input"))
    from observer_digest import digest
    doc = FreeCAD.newDocument("Undo")
    Gui.runCommand("HapticSculpt_NewPatch")
    obj = doc.getObject("Sculpt")
    Gui.Selection.addSelection(obj)
    from HapticSculpt.gui.workbench import controller
    from HapticSculpt.gui.panel import SliderPanel
    import numpy as np
    ctl = controller()
    ctl.mouse_point = np.array(obj.Proxy.live.snapshot().mesh)[10, 10]
    steps = [("HapticSculpt_Material", None), ("HapticSculpt_Material", None), ("HapticSculpt_ToolMagnet", None),
             ("HapticSculpt_Falloff", None), ("HapticSculpt_ToolOrientation", None),
             ("HapticSculpt_ToolSmooth", None), ("HapticSculpt_ToolRope", None),
             ("HapticSculpt_PointConstraint", None), ("HapticSculpt_NormalConstraint", None),
             ("HapticSculpt_CurvatureConstraint", None), ("HapticSculpt_PointConstraint", None),
             ("slider", ("stiffness", 250.0)), ("slider", ("curvature_u", 0.01)), ("HapticSculpt_KeepShape", None)]
    for command, arg in steps:
        if command == "HapticSculpt_KeepShape":  # (a pulled shape to keep: a flat one is kept already)
            HapticSculpt.run(obj, 0.6, device=HapticSculpt.ReplayDevice.stroke((0, 0, 0), (0, 0, 20.0), seconds=0.5))
        before, count = digest(obj), doc.UndoCount
        if command == "slider":
            SliderPanel.apply(obj, *arg)
        else:
            Gui.runCommand(command)
        after = digest(obj)
        name = doc.UndoNames[0] if doc.UndoCount > count else None
        doc.undo()
        undone = digest(obj)
        doc.redo()
        redone = digest(obj)
        out["steps"].append({"command": command if command != "slider" else "slider " + arg[0],
                             "new_steps": doc.UndoCount - count, "name": name, "changed": after != before,
                             "undo_exact": undone == before, "redo_exact": redone == after})
except Exception:
    out["error"] = traceback.format_exc()
json.dump(out, open({answer}, "w"))
os._exit(0)
"""


@pytest.mark.skipif(not GUI_AVAILABLE, reason="needs Xvfb and the FreeCAD GUI (make deps installs both)")
def test_every_editing_command_is_one_exact_undo_step(tmp_path):
    out = run_freecad_gui(GUI_SCRIPT, str(tmp_path))
    names = {"HapticSculpt_Material": "Material: ", "HapticSculpt_ToolMagnet": "Tool: magnet",
             "HapticSculpt_Falloff": "Tool: magnet", "HapticSculpt_ToolOrientation": "Tool: orientation",
             "HapticSculpt_ToolSmooth": "Tool: smooth", "HapticSculpt_ToolRope": "Tool: rope",
             "HapticSculpt_PointConstraint": "constraint", "HapticSculpt_NormalConstraint": "Add normal constraint",
             "HapticSculpt_CurvatureConstraint": "Add curvature constraint", "slider stiffness": "Set stiffness",
             "slider curvature_u": "Set curvature", "HapticSculpt_KeepShape": "Keep shape"}
    for step in out["steps"]:
        assert step["new_steps"] == 1 and step["changed"], step
        assert names[step["command"]] in step["name"], step
        assert step["undo_exact"] and step["redo_exact"], step
    assert len(out["steps"]) == 14


EDIT_SCRIPT = """
import json, time, traceback
import numpy as np
import FreeCAD, FreeCADGui as Gui
out = {}
try:
    Gui.activateWorkbench("HapticSculptWorkbench")
    import HapticSculpt as hs
    from HapticSculpt.gui.workbench import controller
    from HapticSculpt.gui.panel import SliderPanel
    doc = FreeCAD.newDocument("Edits")
    Gui.runCommand("HapticSculpt_NewPatch")
    obj = doc.getObject("Sculpt")
    Gui.Selection.addSelection(obj)
    ctl = controller()
    held = hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 20.0), seconds=0.5, hold=30.0)
    session = ctl.start_session(held)  # polled by the GUI's own timer from here on

    def pump_until(condition, seconds=20.0):
        end = time.monotonic() + seconds
        while not condition() and time.monotonic() < end:
            Gui.updateGui()
            time.sleep(0.01)
        return condition()
    out["pulled"] = pump_until(lambda: np.linalg.norm(session.status()["force"]) > 1.0 and
                               session.status()["elapsed"] > 1.0)
    undo_before = doc.UndoCount
    SliderPanel.apply(obj, "stiffness", 250.0)                 # the slider, released
    Gui.runCommand("HapticSculpt_ToolMagnet")                   # a tool switch
    ctl.mouse_point = np.array(obj.Proxy.live.snapshot().mesh)[5, 5]
    Gui.runCommand("HapticSculpt_PointConstraint")              # a constraint at the mouse
    out["applied"] = pump_until(lambda: len(session.applied_edits) >= 3)
    out["still_running"] = session.running
    out["edits"] = list(session.applied_edits)  # (a copy: the undo below adds its restore)
    out["undo"] = doc.UndoNames[:doc.UndoCount - undo_before]
    doc.undo()  # the constraint, while the session runs
    out["undo_restored"] = pump_until(lambda: not obj.Proxy.live.snapshot().constraints)
    ctl.stop_session()
except Exception:
    out["error"] = traceback.format_exc()
json.dump(out, open({answer}, "w"))
import os
os._exit(0)
"""


@pytest.mark.skipif(not GUI_AVAILABLE, reason="needs Xvfb and the FreeCAD GUI (make deps installs both)")
def test_gui_edits_reach_a_running_session_and_undo_restores_it_in_place(tmp_path):
    out = run_freecad_gui(EDIT_SCRIPT, str(tmp_path))
    assert out["pulled"] and out["applied"] and out["still_running"], out
    assert [e["title"] for e in out["edits"]] == ["Set stiffness", "Tool: magnet", "Add point constraint"], out
    assert all(e["applied_step"] - e["posted_step"] <= 2 for e in out["edits"]), out["edits"]
    assert out["undo"] == ["Add point constraint", "Tool: magnet", "Set stiffness"], out["undo"]
    assert out["undo_restored"]
