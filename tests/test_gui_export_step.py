"""Export STEP as a designer uses it, with real X input (tests/test_gui_real_input.py's Desktop):
with nothing selected it takes the document's only sculpt, its task panel offers
<folder>/<label>.step in FreeCAD's file chooser (its save dialog filtered to STEP; the folder:
the document's, else the one FreeCAD's file dialogs last used, else home), OK writes it through
one echoed HapticSculpt.export_step call, and an independent reader (cadquery's OCP) reads
the surface back."""
from __future__ import annotations

import os
import time

import numpy as np
import pytest
from freecad_support import GUI_AVAILABLE, run_freecad_gui, run_ocp
from test_freecad_step_ocp import READ_STEP
from test_gui_real_input import MACRO_DIALOG, NEEDS, RECORD_BUTTON, Desktop, sculpt


def start_macro(d: Desktop, name: str) -> None:
    """Macro > Macro recording..., the name typed, Record clicked (real keys and clicks)."""
    d.xdo("key", "alt+m")
    d.xdo("key", "m")
    d.wait_window(MACRO_DIALOG)
    d.xdo("key", "ctrl+a")
    d.xdo("type", name)
    d.xdo("mousemove", str(RECORD_BUTTON[0]), str(RECORD_BUTTON[1]), "click", "1")
    d.xdo("mousemove", "640", "500", "click", "1")


def stop_macro(d: Desktop, name: str) -> str:
    """Macro > Stop macro recording; the macro's text once FreeCAD has written it."""
    d.xdo("mousemove", "640", "500")
    d.xdo("key", "alt+m")
    d.xdo("key", "t")
    path = os.path.join(d.home, name + ".FCMacro")
    end, text = time.monotonic() + 30, ""
    while "# Macro End" not in text and time.monotonic() < end:  # (written when the recording stops)
        time.sleep(0.05)
        text = open(path, encoding="utf-8").read() if os.path.exists(path) else ""
    return text


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD (make deps installs them)")
def test_export_step_with_nothing_selected_writes_the_only_sculpt(tmp_path, monkeypatch):
    home = tmp_path / "designer"
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))  # (the panel offers the home folder for an unsaved document)
    d = Desktop(str(tmp_path), "CAD")
    try:
        start_macro(d, "export")
        # (New patch makes the document too: a ctrl+n typed as the macro dialog closed was lost once)
        d.press_button("NewPatch", lambda s: s["active"] and s["inputs"] == 1 and sculpt(s)["screen"], "a new patch")
        d.xdo("mousemove", "1100", "900", "click", "1")  # an empty corner of the view: nothing selected
        d.wait(lambda s: not sculpt(s)["selected"], "the selection to be cleared")
        d.press_button("ExportStep", lambda s: "OK" in s["task_buttons"], "the Export STEP panel")
        # the chooser's button: FreeCAD's save dialog, STEP preselected; a name typed without suffix
        # (where the button is once the panel has laid itself out: FreeCAD 1.0 moved it after OK showed)
        # (its text: "..." up to FreeCAD 1.0, "…" in 1.1)
        choose = d.wait_still(lambda s: s["task_buttons"].get("...") or s["task_buttons"]["…"],
                              "the chooser's button")
        d.shot("export_step_panel")
        d.xdo("mousemove", str(choose[0]), str(choose[1]), "click", "1")
        d.wait_window("Select a file")
        d.shot("export_step_save_dialog")
        d.xdo("key", "ctrl+a")
        d.xdo("type", str(home / "renamed"))
        d.xdo("key", "Return")
        d.wait(lambda s: "OK" in s["task_buttons"] and len(s["task_buttons"]) == 3, "the panel back")
        ok = d.wait_still(lambda s: s["task_buttons"]["OK"], "the OK button")
        d.xdo("mousemove", str(ok[0]), str(ok[1]), "click", "1")
        target = home / "renamed.step"
        s = d.wait(lambda s: not s["task_buttons"] and target.exists(), "the panel to close and the STEP file")
        d.shot("export_step_done")
        poles = np.array(sculpt(s)["poles"]).reshape(8, 8, 3)
        macro = stop_macro(d, "export")
    finally:
        d.close()
    out = run_ocp(f"PATH = {str(target)!r}\nPARAMS = [[(0.5, 0.5)]]\n" + READ_STEP, str(tmp_path))
    assert len(out) == 1 and out[0]["type"] == "Geom_BSplineSurface"
    np.testing.assert_allclose(np.array(out[0]["poles"]), poles, atol=1e-9)
    calls = [line for line in macro.splitlines() if line.startswith("HapticSculpt.export_step")]
    assert calls == [f"HapticSculpt.export_step([App.getDocument('Unnamed').getObject('Sculpt')], {str(target)!r})"], macro


PANEL_SCRIPT = """
import json, os, traceback
import FreeCAD, FreeCADGui as Gui
import Part
res = {}
try:
    Gui.activateWorkbench("HapticSculptWorkbench")
    import HapticSculpt as hs
    from HapticSculpt.gui import export_panel
    from HapticSculpt.gui.workbench import controller
    from HapticSculpt.app import stroke_log
    command = Gui.Command.get("HapticSculpt_ExportStep")
    doc = FreeCAD.newDocument("Parts")
    box = doc.addObject("Part::Box", "Box")
    doc.recompute()
    solid = hs.sculpt_solid(doc, box, ["Face6"])
    Gui.Selection.clearSelection()
    Gui.updateGui()
    res["only_solid"] = [o.Name for o in export_panel.exportable([], doc)]
    res["active_solid"] = command.isActive()
    patch = hs.make_sculpt(doc)
    Gui.updateGui()
    res["two"] = [o.Name for o in export_panel.exportable([], doc)]
    res["active_two"] = command.isActive()
    Gui.Selection.addSelection(patch)
    Gui.updateGui()
    res["selected"] = [o.Name for o in export_panel.exportable(Gui.Selection.getSelection(), doc)]
    res["patch"] = patch.Name
    res["active_selected"] = command.isActive()
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(box)  # (any part selected goes: a thickened sculpt is a plain Part feature)
    res["part"] = [o.Name for o in export_panel.exportable(Gui.Selection.getSelection(), doc)]
    Gui.Selection.clearSelection()
    thick_doc = FreeCAD.newDocument("Thick")  # a patch thickened: the solid the user sees, not its hidden face
    thick = hs.make_thickness(hs.make_sculpt(thick_doc), 3.0)
    thick_doc.recompute()
    res["thickened"] = [o.Name for o in export_panel.exportable([], thick_doc)]
    res["thickness"] = thick.Name
    FreeCAD.closeDocument(thick_doc.Name)
    FreeCAD.setActiveDocument(doc.Name)
    # an unsaved document: the folder FreeCAD's file dialogs last used (else home)
    params = FreeCAD.ParamGet(export_panel.LAST_FOLDER[0])
    params.SetString(export_panel.LAST_FOLDER[1], os.path.join(TMP, "last"))
    os.makedirs(os.path.join(TMP, "last"))
    res["unsaved_default"] = export_panel.ExportStepPanel([solid]).path()
    doc.saveAs(os.path.join(TMP, "parts.FCStd"))
    panel = export_panel.ExportStepPanel([solid])
    res["default"] = panel.path()
    undo = list(doc.UndoNames)
    panel.form.file.setProperty("fileName", os.path.join(TMP, "no such folder", "x.step"))
    res["refused"] = panel.accept()
    panel.form.file.setProperty("fileName", os.path.join(TMP, "part"))
    res["accepted"] = panel.accept()
    res["written"] = panel.path()
    res["last_folder"] = params.GetString(export_panel.LAST_FOLDER[1])
    again = export_panel.ExportStepPanel([solid])  # the same file again: OK asks first, then replaces it
    again.form.file.setProperty("fileName", panel.path())
    written = os.path.getmtime(panel.path())
    os.utime(panel.path(), (written - 100, written - 100))
    res["replace_first"] = [again.accept(), str(again.form.message.text()), os.path.getmtime(panel.path()) == written - 100]
    res["replace_second"] = [again.accept(), os.path.getmtime(panel.path()) > written - 100]
    shape = Part.read(panel.path())
    res["solids"] = len(shape.Solids)
    res["volume"] = [shape.Volume, solid.Shape.Volume]
    res["undo_same"] = list(doc.UndoNames) == undo
    # A session that changes nothing, ended by switching workbench: no commit, nothing kept or echoed.
    quiet = FreeCAD.newDocument("Quiet")
    obj = hs.make_sculpt(quiet, material="elastic")
    hs.add_constraint(obj, "curvature", uv=(0.5, 0.5))
    Gui.Selection.addSelection(obj)
    undo = list(quiet.UndoNames)
    still = hs.ReplayDevice([0.0, 60.0], [[0, 0, 80], [0, 0, 80]], buttons=[0, 0])
    controller().start_session(still)
    import time
    end = time.monotonic() + 1.0
    while time.monotonic() < end:
        Gui.updateGui()
    res["running"] = obj.Proxy.live.session is not None
    Gui.activateWorkbench("PartWorkbench")
    Gui.updateGui()
    res["stopped"] = obj.Proxy.live.session is None or not obj.Proxy.live.session.running
    res["quiet_undo_same"] = list(quiet.UndoNames) == undo
    res["quiet_log"] = stroke_log.records(obj)
except Exception:
    res["error"] = traceback.format_exc()
json.dump(res, open({answer}, "w"))
os._exit(0)
"""


@pytest.mark.skipif(not GUI_AVAILABLE, reason="needs Xvfb and FreeCAD")
def test_export_step_chooses_the_only_sculpted_solid_and_refuses_a_bad_file_name(tmp_path):
    out = run_freecad_gui(f"TMP = {str(tmp_path)!r}\n" + PANEL_SCRIPT, str(tmp_path))
    assert out["only_solid"] == ["SculptedSolid"] and out["active_solid"]  # (not its own hidden sculpt)
    assert out["two"] == [] and not out["active_two"]  # two candidates and none selected: which one?
    assert out["selected"] == [out["patch"]] and out["active_selected"]
    assert out["part"] == ["Box"]
    assert out["thickened"] == [out["thickness"]]
    assert out["unsaved_default"] == str(tmp_path / "last" / "SculptedSolid.step")
    assert out["default"] == str(tmp_path / "SculptedSolid.step")  # (the saved document's folder, its label)
    assert out["refused"] is False  # (said in the report view; the panel stays open)
    assert out["accepted"] is True and out["written"] == str(tmp_path / "part.step")
    assert out["last_folder"] == str(tmp_path)  # (the next export starts where this one went)
    assert out["replace_first"] == [False, "part.step exists: OK again replaces it", True]  # (nothing written)
    assert out["replace_second"] == [True, True]
    assert out["solids"] == 1 and out["volume"][0] == pytest.approx(out["volume"][1], rel=1e-6)
    assert out["undo_same"]  # exporting is no edit
    assert out["running"] and out["stopped"]
    assert out["quiet_undo_same"] and out["quiet_log"] == {}
