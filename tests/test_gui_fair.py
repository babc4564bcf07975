"""The Fair command in the real FreeCAD GUI under Xvfb: on a creased stroke (springs alone, corners
held) it is one undo step named Fair that relaxes the shape, shown at once. Writes
build/screenshots/gui_fair_before.png and gui_fair_after.png (mean curvature shown; look at them)."""
from __future__ import annotations

import os

import numpy as np
import pytest
from freecad_support import GUI_AVAILABLE, SCREENSHOTS, run_freecad_gui

GUI_SCRIPT = """
import json, os, traceback
import FreeCAD, FreeCADGui as Gui
out = {{}}
try:
    Gui.activateWorkbench("HapticSculptWorkbench")
    import HapticSculpt as hs
    doc = FreeCAD.newDocument("FairTest")
    obj = hs.make_sculpt(doc, material="clay")
    hs.set_uniform(obj, "bending", 0.0)  # springs alone: a tent with creases to the held corners
    obj.Proxy.live.edit(lambda s: s.hold_poles([0, 7, 56, 63]), "Hold corners")
    hs.run(obj, 3.0, device=hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 25.0), seconds=1.5, hold=1.5))
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(obj)
    view = Gui.ActiveDocument.ActiveView
    view.viewIsometric()
    view.fitAll()
    Gui.runCommand("HapticSculpt_ShowCurvature")
    for _ in range(5):
        Gui.updateGui()
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(obj)
    view.saveImage({before!r}, 800, 600, "White")
    import numpy as np
    poles = np.array(obj.Poles).reshape(-1, 3)
    undo = doc.UndoCount
    out["active"] = Gui.Command.get("HapticSculpt_Fair").isActive() if hasattr(Gui, "Command") else True
    Gui.runCommand("HapticSculpt_Fair")
    for _ in range(5):
        Gui.updateGui()
    view.saveImage({after!r}, 800, 600, "White")
    out["undo_names"] = doc.UndoNames[:doc.UndoCount - undo]
    faired = np.array(obj.Poles).reshape(-1, 3)
    out["moved"] = float(np.abs(faired - poles).max())
    out["report"] = obj.Proxy.live.last_fair  # (what the report view's line says)
    out["held_moved"] = float(np.abs(faired[[0, 7, 56, 63]] - poles[[0, 7, 56, 63]]).max())
    shown = obj.Shape.Faces[0].Surface.getPoles()
    out["change"] = max(abs(shown[i][j].z - faired[i * 8 + j][2]) for i in range(8) for j in range(8))
    doc.undo()
    out["undone"] = float(np.abs(np.array(obj.Poles).reshape(-1, 3) - poles).max())
except Exception:
    out["error"] = traceback.format_exc()
json.dump(out, open({answer}, "w"))
os._exit(0)
"""


@pytest.mark.skipif(not GUI_AVAILABLE, reason="needs Xvfb and the FreeCAD GUI (make deps installs both)")
def test_fair_command_is_one_undo_step_shown_at_once(tmp_path):
    os.makedirs(SCREENSHOTS, exist_ok=True)
    before = os.path.join(SCREENSHOTS, "gui_fair_before.png")
    after = os.path.join(SCREENSHOTS, "gui_fair_after.png")
    for png in (before, after):
        if os.path.exists(png):
            os.remove(png)
    out = run_freecad_gui(GUI_SCRIPT.format(before=before, after=after, answer="{answer}"), str(tmp_path))
    assert "error" not in out, out["error"]
    assert out["active"]
    assert out["undo_names"] == ["Fair"]
    assert out["moved"] > 0.05 and out["held_moved"] == 0.0
    # it says what it moved: the poles (exactly the move made) and the peak curvature, which fell
    assert out["report"]["moved_mm"] == out["moved"]
    assert out["report"]["peak_curvature_after"] < out["report"]["peak_curvature_before"]
    assert out["change"] < 1e-9  # the face shows the faired poles at once
    assert out["undone"] == 0.0
    import matplotlib.image as mpimg
    a, b = mpimg.imread(before)[..., :3], mpimg.imread(after)[..., :3]
    assert np.abs(a - b).max() > 0.2, "the picture did not change"


NEW_PATCH_SCRIPT = """
import json, os, traceback
import FreeCAD, FreeCADGui as Gui
out = {{}}
try:
    Gui.activateWorkbench("HapticSculptWorkbench")
    import HapticSculpt as hs
    doc = FreeCAD.newDocument("NewPatchTest")
    made = {{}}
    for command in ("HapticSculpt_NewPatch", "HapticSculpt_NewClampedPatch"):
        before, undo = set(o.Name for o in doc.Objects), doc.UndoCount
        Gui.runCommand(command)
        for _ in range(3):
            Gui.updateGui()
        new = [o for o in doc.Objects if o.Name not in before]
        made[command] = {{"objects": len(new), "undo": doc.UndoNames[:doc.UndoCount - undo],
                          "edges": hs.held_boundary(new[0]), "bending": list(new[0].BendingMap),
                          "box": [new[0].Shape.BoundBox.XMin, new[0].Shape.BoundBox.XMax,
                                  new[0].Shape.BoundBox.YMin, new[0].Shape.BoundBox.YMax]}}
    out["made"] = made
except Exception:
    out["error"] = traceback.format_exc()
json.dump(out, open({answer}, "w"))
os._exit(0)
"""


@pytest.mark.skipif(not GUI_AVAILABLE, reason="needs Xvfb and the FreeCAD GUI (make deps installs both)")
def test_new_patch_offers_free_or_held_edges(tmp_path):
    """The create toolbar's New patch drop-down: New sculpt patch makes a free sheet, New clamped
    patch one with every edge held G1; each one undo step, both bending by default. The first lies
    at the origin, the second beside it (not on it)."""
    from HapticSculpt.app.api import FAIR_BENDING
    out = run_freecad_gui(NEW_PATCH_SCRIPT.format(answer="{answer}"), str(tmp_path))
    assert "error" not in out, out["error"]
    free, held = out["made"]["HapticSculpt_NewPatch"], out["made"]["HapticSculpt_NewClampedPatch"]
    assert free["objects"] == held["objects"] == 1
    assert free["undo"] == held["undo"] == ["Create sculpt"]
    assert set(free["edges"].values()) == {"free"}
    assert held["edges"] == {"u0": "G1", "u1": "G1", "v0": "G1", "v1": "G1"}
    assert free["bending"] == held["bending"] == [FAIR_BENDING]
    assert free["box"] == pytest.approx([-50, 50, -50, 50], abs=1e-6)
    assert held["box"] == pytest.approx([70, 170, -50, 50], abs=1e-6)
