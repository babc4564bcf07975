"""Strokes kept in the sculpt (app/stroke_log.py) and HapticSculpt.replay_stroke, the one short line
the GUI echoes for each stroke a threaded session commits; old macros' HapticSculpt.record_state
keeps working. Console mode: the GUI's listener is installed here by hand (the GUI installs it when
it loads), minus the echo, which the GUI tests read from a recorded macro."""
from __future__ import annotations

import json
import os
import time

import FreeCAD
import numpy as np
import pytest
from freecad_support import DocumentTestCase, run_freecadcmd

import HapticSculpt as hs
from HapticSculpt.app import recorded_state, sculpt_state, stroke_log
from HapticSculpt.app.sculpt_properties import read_state
from HapticSculpt.runtime import session as session_module


def keep(obj, before, title, strokes, echo=True):
    stroke_log.record(obj, before, title, strokes)


def pull(obj, depth: float) -> None:
    device = hs.ReplayDevice.stroke((0.0, 0.0, 0.0), (0.0, 0.0, depth), seconds=0.2)
    s = hs.Session().start(obj, device, stop_when_finished=True)
    assert s.wait(timeout=60)
    s.stop()


def assert_same_state(a, b):
    for name in sculpt_state.ARRAY_NAMES:
        np.testing.assert_array_equal(read_state(a).arrays[name], read_state(b).arrays[name], err_msg=name)
    assert a.SculptSettings == b.SculptSettings


class TestStrokeLog(DocumentTestCase):
    def setUp(self) -> None:
        super().setUp()
        session_module.set_commit_listener(keep)

    def tearDown(self) -> None:
        session_module.set_commit_listener(None)
        for name in list(FreeCAD.listDocuments()):
            if name != self.doc.Name and name.startswith("Replay"):
                FreeCAD.closeDocument(name)
        super().tearDown()

    def test_a_session_that_changes_nothing_keeps_no_stroke(self):
        obj = hs.make_sculpt(self.doc, material="clay")
        undo = len(self.doc.UndoNames)
        s = hs.Session().start(obj, hs.ReplayDevice([0.0, 0.3], [[0, 0, 60], [0, 0, 60]], buttons=[0, 0]),
                               stop_when_finished=True)
        assert s.wait(timeout=60)
        s.stop()
        self.assertEqual(stroke_log.records(obj), {})
        self.assertEqual(len(self.doc.UndoNames), undo)

    def test_strokes_kept_in_the_saved_document_replay_bit_for_bit_into_a_new_one(self):
        obj = hs.make_sculpt(self.doc, material="clay")
        pull(obj, 20.0)
        pull(obj, -15.0)
        kept = stroke_log.records(obj)
        self.assertGreaterEqual(len(kept), 2)
        self.assertEqual(sorted(kept), [f"Stroke{k:03d}" for k in range(1, len(kept) + 1)])
        # Undo forgets a stroke with the stroke (it was kept in the stroke's transaction).
        undo_names = list(self.doc.UndoNames)
        self.doc.undo()
        self.assertEqual(len(stroke_log.records(obj)), len(kept) - 1)
        self.doc.redo()
        self.assertEqual(stroke_log.records(obj), kept)
        self.assertEqual(list(self.doc.UndoNames), undo_names)
        path = os.path.join(self.tmp, "strokes.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        saved = self.doc.getObject("Sculpt")
        self.assertEqual(stroke_log.records(saved), kept)

        replay = FreeCAD.newDocument("Replay")
        fresh = hs.make_sculpt(replay, material="clay")
        with self.assertRaisesRegex(ValueError, "no open document keeps one that starts from its state"):
            hs.replay_stroke(fresh, "Stroke002")  # (strokes replay in order)
        with self.assertRaisesRegex(ValueError, "keeps no stroke 'Stroke999'"):
            hs.replay_stroke(fresh, "Stroke999")
        with self.assertRaisesRegex(TypeError, "stroke"):
            hs.replay_stroke(fresh, 3)
        self.assertEqual(len(replay.UndoNames), 1)
        for name in sorted(kept):
            self.assertTrue(hs.replay_stroke(fresh, name))
            self.assertEqual(replay.UndoNames[0], kept[name]["title"])
        self.assertFalse(hs.replay_stroke(fresh, sorted(kept)[-1]))  # the state it gives: nothing to do
        with self.assertRaisesRegex(ValueError, "Stroke001 starts from another state than Sculpt holds"):
            hs.replay_stroke(fresh, "Stroke001")
        self.assertEqual(len(replay.UndoNames), 1 + len(kept))
        assert_same_state(fresh, saved)
        self.assertEqual(fresh.Strokes, saved.Strokes)
        np.testing.assert_array_equal(np.asarray(fresh.Proxy.live.snapshot().poles).ravel(), saved.Poles)
        self.assertEqual(stroke_log.records(fresh), kept)  # the new document keeps them too

    def test_the_log_is_bounded_and_a_damaged_record_is_refused(self):
        obj = hs.make_sculpt(self.doc, material="elastic")
        before = read_state(obj)
        for _ in range(3):
            pull(obj, 10.0)
        kept = stroke_log.records(obj)
        old_limit = stroke_log.LIMIT
        try:
            stroke_log.LIMIT = 2
            self.doc.openTransaction("t")
            name = stroke_log.record(obj, before, "Sculpt stroke", 1)
            self.doc.commitTransaction()
        finally:
            stroke_log.LIMIT = old_limit
        left = stroke_log.records(obj)
        self.assertEqual(len(left), 2)
        self.assertIn(name, left)
        self.assertEqual(name, f"Stroke{len(kept) + 1:03d}")  # (names are never reused while kept)
        self.doc.undo()
        damaged = dict(kept)
        first = sorted(damaged)[0]
        damaged[first] = dict(damaged[first], change=recorded_state.pack(before, before))
        replay = FreeCAD.newDocument("Replay")
        fresh = hs.make_sculpt(replay, material="elastic")
        fresh.addProperty("App::PropertyString", "StrokeLog")
        fresh.StrokeLog = json.dumps(damaged)
        with self.assertRaisesRegex(ValueError, "does not give the state"):
            hs.replay_stroke(fresh, first)


def test_an_old_macro_with_record_state_replays_in_console_mode(tmp_path):
    """A macro as the GUI recorded them before replay_stroke: the stroke's change inline."""
    doc = FreeCAD.newDocument("Old")
    try:
        obj = hs.make_sculpt(doc, material="clay")
        before = read_state(obj)
        pull(obj, 20.0)
        packed = recorded_state.pack(before, read_state(obj))
        expected = list(obj.Poles)
    finally:
        FreeCAD.closeDocument(doc.Name)
    macro = tmp_path / "old.FCMacro"
    macro.write_text("# -*- coding: utf-8 -*-\n# Macro Begin: old.FCMacro +++++++++++++++++++++++++++++++++++++++++++++++++\n"
                     "import FreeCAD\nApp.newDocument('Unnamed')\nimport HapticSculpt\n"
                     "HapticSculpt.make_sculpt(App.getDocument('Unnamed'), material='clay')\n"
                     f"HapticSculpt.record_state(App.getDocument('Unnamed').getObject('Sculpt'), {packed!r}, "
                     "'Sculpt stroke', strokes=1)\n# Macro End: old.FCMacro +++++++++++++++++++++++++++++++++++++++++++++++++\n")
    out = run_freecadcmd(f"""
        import FreeCAD
        App = FreeCAD
        exec(open({str(macro)!r}, encoding="utf-8").read())
        obj = FreeCAD.getDocument("Unnamed").getObject("Sculpt")
        answer({{"poles": list(obj.Poles), "strokes": obj.Strokes, "undo": FreeCAD.getDocument("Unnamed").UndoNames}})
        """, str(tmp_path / "replay"))
    assert out["poles"] == expected  # (JSON floats are repr: bit for bit)
    assert out["strokes"] == 1 and out["undo"][0] == "Sculpt stroke"


@pytest.mark.parametrize("bad", [None, "", 7])
def test_replay_stroke_refuses_what_is_not_a_stroke_name(bad):
    doc = FreeCAD.newDocument("Bad")
    try:
        obj = hs.make_sculpt(doc)
        with pytest.raises(TypeError, match="stroke"):
            hs.replay_stroke(obj, bad)
        with pytest.raises(TypeError, match="obj"):
            hs.replay_stroke(doc, "Stroke001")
    finally:
        FreeCAD.closeDocument(doc.Name)


class TestAFailingListener(DocumentTestCase):
    def test_a_listener_that_fails_does_not_cost_the_stroke(self):
        def fails(obj, before, title, strokes):
            raise RuntimeError("no console")
        session_module.set_commit_listener(fails)
        try:
            obj = hs.make_sculpt(self.doc, material="clay")
            pull(obj, 20.0)
        finally:
            session_module.set_commit_listener(None)
        self.assertEqual(obj.Strokes, 1)
        self.assertIn("Sculpt stroke", self.doc.UndoNames)


def test_a_macro_with_strokes_and_edits_interleaved_in_a_session_replays_in_console_mode(tmp_path):
    """The GUI's code path without the GUI: each call runs as FreeCADGui.doCommand runs it (the line
    into the macro, then executed), and each commit the session makes is kept and echoed as the GUI's
    listener does. Edits made while the session's surface moves (an elastic patch springing back, a
    held stroke) act there on the moving poles, and in the macro on the state the lines before gave:
    the macro, replayed by freecadcmd with the saved document open, ends in the same state."""
    doc = FreeCAD.newDocument("Edits")
    lines: list[str] = []
    ref = "App.getDocument('Edits').getObject('Sculpt')"
    space = {"HapticSculpt": hs, "App": FreeCAD}

    def run(line: str) -> None:
        lines.append(line)
        exec(line, space)

    def echo(obj, before, title, strokes, echo=True):
        name = stroke_log.record(obj, before, title, strokes)
        if echo:
            run(f"HapticSculpt.replay_stroke({ref}, {name!r})")

    session_module.set_commit_listener(echo)
    try:
        run("HapticSculpt.make_sculpt(App.getDocument('Edits'), material='elastic')")
        obj = doc.getObject("Sculpt")
        # two strokes: up (released at 0.5 s), then down while the patch still springs back
        device = hs.ReplayDevice(t=[0.0, 0.4, 0.5, 1.2, 1.6, 1.7, 3.0],
                                 xyz=[[0, 0, 0], [0, 0, 30], [0, 0, 30], [20, 20, 0], [20, 20, -20], [20, 20, -20],
                                      [20, 20, -20]], buttons=[1, 1, 0, 1, 1, 0, 0])
        s = hs.Session().start(obj, device, stop_when_finished=True)

        def until(condition, what):
            end = time.monotonic() + 60
            while not condition():
                assert time.monotonic() < end, what
                s.poll()
                time.sleep(0.005)

        until(lambda: obj.Strokes >= 1, "the first stroke")  # (the patch springs back from here)
        run(f"HapticSculpt.add_constraint({ref}, 'normal', near=(10.0, -10.0, 0.0))")
        run(f"HapticSculpt.set_uniform({ref}, 'stiffness', 250.0)")
        until(lambda: s.status()["elapsed"] > 1.4, "the second stroke under way")
        run(f"HapticSculpt.set_material({ref}, 'clay')")  # (on a held stroke)
        run(f"HapticSculpt.add_constraint({ref}, 'point', near=(-30.0, 30.0, 0.0))")
        until(lambda: obj.Strokes >= 2, "the second stroke")
        run(f"HapticSculpt.keep_shape({ref})")
        until(lambda: not s.running, "the replay to end")
        s.stop()
        titles = list(doc.UndoNames)
        assert "Sculpt session end" not in titles
        assert titles.count("Sculpt stroke") == 2 and "Material: clay" in titles and "Keep shape" in titles, titles
        expected = read_state(obj)
        saved = str(tmp_path / "saved.FCStd")
        doc.saveAs(saved)
    finally:
        session_module.set_commit_listener(None)
        FreeCAD.closeDocument(doc.Name)
    macro = tmp_path / "edits.FCMacro"
    macro.write_text("import FreeCAD\nApp = FreeCAD\nimport HapticSculpt\nApp.newDocument('Edits')\n"
                     + "\n".join(lines) + "\n", encoding="utf-8")
    out = run_freecadcmd(f"""
        import FreeCAD
        FreeCAD.openDocument({saved!r})
        exec(open({str(macro)!r}, encoding="utf-8").read())
        obj = FreeCAD.getDocument("Edits").getObject("Sculpt")
        from HapticSculpt.app import sculpt_state
        answer({{name: list(map(float, getattr(obj, name))) for name in sculpt_state.ARRAY_NAMES}}
               | {{"settings": obj.SculptSettings, "strokes": obj.Strokes}})
        """, str(tmp_path / "replay"))
    for name in sculpt_state.ARRAY_NAMES:
        np.testing.assert_allclose(out[name], expected.arrays[name], rtol=0, atol=1e-9, err_msg=name)
    assert json.loads(out["settings"]) == json.loads(expected.settings_json())
    assert out["strokes"] == 2
