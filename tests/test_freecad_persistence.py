"""Saving and opening documents in a new freecadcmd process: exact state, old files, corrupt files."""
from __future__ import annotations

import numpy as np

from freecad_support import ROOT, DocumentTestCase, run_freecadcmd

import FreeCAD

import HapticSculpt as hs
from HapticSculpt.app import sculpt_state
from HapticSculpt.app.sculpt_properties import read_state

# Run in the new process: open the file, rebuild every sculpt, step each the same way, report all
# state as float.hex so the comparison is bit for bit.
REPORT_SCRIPT = """
import FreeCAD, HapticSculpt
from HapticSculpt.app import sculpt_state
doc = FreeCAD.openDocument(PATH)
out = {}
for obj in doc.Objects:
    entry = {"type": obj.TypeId, "error": getattr(obj, "SculptError", None),
             "volume": obj.Shape.Volume if obj.TypeId == "Part::Box" else None,
             "properties": sorted(obj.PropertiesList)}
    if getattr(getattr(obj, "Proxy", None), "Type", None) == "HapticSculpt::Sculpt":
        try:
            s = obj.Proxy.surface
        except ValueError as exc:
            entry["raised"] = str(exc)
        else:
            st = sculpt_state.capture(s)
            entry["arrays"] = {k: [float(x).hex() for x in v] for k, v in st.arrays.items()}
            entry["settings"] = st.settings_json()
            s.set_cursor((0.0, 0.0, 10.0), grab=True)
            for _ in range(50):
                s.step(1e-3)
            entry["stepped"] = [float(x).hex() for x in s.poles.ravel()]
    out[obj.Name] = entry
answer(out)
"""


def report(tmp, path):
    return run_freecadcmd(f"PATH = {path!r}\n" + REPORT_SCRIPT, tmp)


class TestPersistence(DocumentTestCase):
    def sculpted(self, name="Sculpt"):
        obj = hs.make_sculpt(self.doc, controls=(9, 8), mesh=(27, 25), name=name)
        s = obj.Proxy.surface
        s.integrator = "implicit"
        s.cg_iterations = 7
        s.time_order = 1
        s.explicit_when_stable = False
        s.set_stiffness_law("cubic", 3.0)
        s.set_damping_law("saturating", 2.0)
        s.set_plasticity(True, 0.02, 0.5)
        s.mass_map.set_values(np.linspace(0.5, 2.0, 12).reshape(3, 4))
        s.damping_map.dab((0.3, 0.6), 0.25, 3.0)
        hs.add_constraint(obj, "point", uv=(0.2, 0.2))
        tangent = hs.add_constraint(obj, "tangent", uv=(0.8, 0.3))
        hs.add_constraint(obj, "normal", near=(20.0, 30.0, 0.0), normal=(0.0, 0.3, 1.0))
        hs.add_constraint(obj, "curvature", uv=(0.4, 0.7), curvature=(0.01, 0.002))
        hs.remove_constraint(obj, tangent)
        dev = hs.ReplayDevice.stroke((0, 0, 0), (5.0, -3.0, 18.0), seconds=0.4)
        hs.run(obj, 0.6, device=dev, tool="rope")
        s.set_tool("magnet")
        s.tool.radius = 17.0
        s.tool.falloff = "conical"
        hs.run(obj, 0.0, tool=None)  # write the tool change back
        return obj

    def test_state_is_bit_identical_in_a_new_process(self):
        obj = self.sculpted()
        path = f"{self.tmp}/sculpt.FCStd"
        self.doc.saveAs(path)
        expected = sculpt_state.capture(obj.Proxy.surface)
        got = report(self.tmp, path)["Sculpt"]
        self.assertEqual(got["error"], "")
        for name, values in expected.arrays.items():
            self.assertEqual(got["arrays"][name], [float(x).hex() for x in values], name)
        self.assertEqual(got["settings"], expected.settings_json())
        # and it behaves identically: a freshly restored surface stepped here gives the same poles
        here = sculpt_state.restore(read_state(obj))
        here.set_cursor((0.0, 0.0, 10.0), grab=True)
        for _ in range(50):
            here.step(1e-3)
        self.assertEqual(got["stepped"], [float(x).hex() for x in np.asarray(here.poles).ravel()])

    def test_files_without_new_properties_still_open(self):
        obj = self.sculpted()
        for prop in ("Strokes", "SculptError", "ConversionMethod"):
            obj.removeProperty(prop)
        path = f"{self.tmp}/old.FCStd"
        self.doc.saveAs(path)
        got = report(self.tmp, path)["Sculpt"]
        self.assertEqual(got["error"], "")
        self.assertIn("stepped", got)
        for prop in ("Strokes", "SculptError", "ConversionMethod"):
            self.assertIn(prop, got["properties"])


    def test_a_document_saved_by_version_0_1_opens_with_its_shape(self):
        """0.1 stored its proxies as HapticSculpt.sculpt_feature / .view_provider, before the
        package was split into layers (the fixture was saved by 0.1's GUI)."""
        fixtures = f"{ROOT}/tests/fixtures/documents"
        got = run_freecadcmd(f"""
import numpy as np
import FreeCAD, HapticSculpt
doc = FreeCAD.openDocument({fixtures + '/sculpt_0_1.FCStd'!r})
obj = doc.getObject("Sculpt")
poles = np.asarray(obj.Proxy.live.snapshot().poles)
HapticSculpt.set_material(obj, "clay")
doc.recompute()
answer({{"module": type(obj.Proxy).__module__, "poles": poles.ravel().tolist(),
         "valid": obj.Shape.isValid(), "error": obj.SculptError, "material": HapticSculpt.material_of(obj)}})
""", self.tmp)
        self.assertEqual(got["module"], "HapticSculpt.app.sculpt_feature")
        np.testing.assert_array_equal(got["poles"], np.load(f"{fixtures}/sculpt_0_1_poles.npy").ravel())
        self.assertTrue(got["valid"])
        self.assertEqual((got["error"], got["material"]), ("", "clay"))
    def test_corrupt_properties_give_a_clear_error_on_that_object_only(self):
        box = self.doc.addObject("Part::Box", "Box")
        good = hs.make_sculpt(self.doc, name="Good")
        short = hs.make_sculpt(self.doc, name="Short")
        nan = hs.make_sculpt(self.doc, name="NaN")
        bad_json = hs.make_sculpt(self.doc, name="BadJSON")
        bad_constraint = hs.make_sculpt(self.doc, name="BadConstraint")
        self.doc.recompute()
        short.Poles = list(short.Poles)[:-5]
        knots = list(nan.KnotsU)
        knots[5] = float("nan")
        nan.KnotsU = knots
        bad_json.SculptSettings = bad_json.SculptSettings[:-7]
        bad_constraint.SculptSettings = bad_constraint.SculptSettings.replace(
            '"constraints": []', '"constraints": [{"id": 1, "kind": "point", "index": 99999, "stiffness": 1.0, '
                                 '"target": [0, 0, 0]}]')
        path = f"{self.tmp}/corrupt.FCStd"
        self.doc.saveAs(path)
        got = report(self.tmp, path)
        self.assertAlmostEqual(got["Box"]["volume"], 1000.0)
        self.assertEqual(got["Good"]["error"], "")
        self.assertIn("stepped", got["Good"])
        for name, mentions in (("Short", "Poles"), ("NaN", "KnotsU"), ("BadJSON", "malformed JSON"),
                               ("BadConstraint", "constraints")):
            self.assertIn(mentions, got[name]["error"], name)
            self.assertIn(name, got[name]["error"])
            self.assertIn(mentions, got[name]["raised"], name)


class TestToolSettings(DocumentTestCase):
    """hs.set_tool takes a tool's settings by the names the core declares (TOOL_INFO): one undo step,
    saved with the document; a refused value or name changes nothing."""

    def test_settings_by_name_are_one_undo_step_saved_and_checked(self):
        obj = hs.make_sculpt(self.doc)
        hs.set_tool(obj, "magnet", "conical", radius=17.0, stiffness=30.0)
        self.assertEqual(self.doc.UndoNames[0], "Tool: magnet")
        tool = obj.Proxy.surface.tool
        self.assertEqual((tool.name, tool.radius, tool.stiffness, tool.falloff), ("magnet", 17.0, 30.0, "conical"))
        saved = sculpt_state.tool_settings(sculpt_state.restore(read_state(obj)))
        self.assertEqual(saved, {"name": "magnet", "params": {"radius": 17.0, "stiffness": 30.0, "falloff": "conical",
                                                              "max_force": 1000.0, "ramp_time": 0.05}})
        steps = len(self.doc.UndoNames)
        for kwargs, message in (({"radius": -1.0}, "radius"), ({"reel_time": 1.0}, "no setting reel_time"),
                                ({"radius": float("nan")}, "radius")):
            with self.assertRaisesRegex(ValueError, message):
                hs.set_tool(obj, "magnet", **kwargs)
        with self.assertRaisesRegex(ValueError, "only the magnet, smooth"):
            hs.set_tool(obj, "rope", "conical")
        self.assertEqual(len(self.doc.UndoNames), steps)
        self.assertEqual(obj.Proxy.surface.tool.radius, 17.0)
        self.doc.undo()
        self.assertEqual(obj.Proxy.surface.tool.name, "rope")
        for name in hs.core.TOOLS:  # every tool's declared defaults are what a new one has
            made = hs.core.make_tool(name)
            for key, p in hs.core.TOOL_INFO[name]["parameters"].items():
                self.assertEqual(getattr(made, key), p["default"], (name, key))


class TestRegionalSteps(DocumentTestCase):
    """hs.set_regional: a stroke near a corner of a large sculpt steps a region of it, the far
    poles stay exactly where they were; the setting is one undo step, saved and reopened; bad
    arguments are refused by name."""

    def test_a_stroke_steps_a_region_and_the_setting_is_kept(self):
        obj = hs.make_sculpt(self.doc, controls=(32, 32), mesh=(128, 128), size=(400.0, 400.0), name="Large")
        self.doc.recompute()
        hs.set_regional(obj, True, wake=0.05)
        surface = obj.Proxy.surface
        self.assertEqual((surface.regional, surface.region_wake, surface.region_margin), (True, 0.05, 4))
        before = np.asarray(surface.poles).reshape(32, 32, 3).copy()
        # (a short stroke: the elastic sheet's motion spreads, and past 0.1 s the region is the whole net)
        dev = hs.ReplayDevice.stroke((-140.0, -140.0, 0.0), (-140.0, -140.0, 2.0), seconds=0.05, hold=0.0)
        hs.run(obj, 0.05, device=dev, tool="rope")
        surface = obj.Proxy.surface
        region = surface.active_region
        self.assertFalse(region["whole"])
        r0, r1, c0, c1 = region["poles"]
        after = np.asarray(surface.poles).reshape(32, 32, 3)
        self.assertGreater(after[..., 2].max(), 0.2)
        np.testing.assert_array_equal(after[r1:], before[r1:])  # beyond the region: untouched
        np.testing.assert_array_equal(after[:, c1:], before[:, c1:])
        path = f"{self.tmp}/regional.FCStd"
        self.doc.saveAs(path)
        got = report(self.tmp, path)["Large"]
        self.assertEqual(got["error"], "")
        settings = __import__("json").loads(got["settings"])
        self.assertEqual((settings["regional"], settings["region_wake"]), (True, 0.05))
        self.doc.undo()  # the stroke
        self.doc.undo()  # the setting
        self.assertFalse(obj.Proxy.surface.regional)

    def test_bad_arguments_are_refused_by_name(self):
        obj = hs.make_sculpt(self.doc)
        for kwargs, name in (({"enabled": 1}, "enabled"), ({"wake": 2.0}, "wake"), ({"wake": "x"}, "wake"),
                             ({"margin": 0}, "margin"), ({"margin": 2.5}, "margin")):
            with self.assertRaises(ValueError) as caught:
                hs.set_regional(obj, **kwargs)
            self.assertIn(name, str(caught.exception))
        self.assertFalse(obj.Proxy.surface.regional)


class TestEditsCommitWhatChanged(DocumentTestCase):
    """An edit compares with what the document holds as the live surface last wrote it, instead of
    reading every state property back, and writes only what changed; a property written from
    outside (a script, Undo) is read again; Undo restores every state exactly."""

    def test_each_edit_undoes_exactly_and_an_outside_write_is_seen(self):
        from test_freecad_layer import stroke
        obj = hs.make_sculpt(self.doc, controls=(16, 16), mesh=(64, 64))
        states = [read_state(obj)]
        edits = [lambda: hs.set_uniform(obj, "stiffness", 300.0), lambda: hs.set_tool(obj, "magnet", radius=17.0),
                 lambda: stroke(obj), lambda: hs.set_uniform(obj, "bending", 2.0),
                 lambda: hs.set_material(obj, "clay"), lambda: hs.set_regional(obj, True, wake=0.05, margin=2)]
        for edit in edits:
            edit()
            states.append(read_state(obj))
            self.assertEqual(sculpt_state.capture(obj.Proxy.surface).settings_json(), states[-1].settings_json())
        for expected in reversed(states[:-1]):
            self.doc.undo()
            got = read_state(obj)
            for name, values in expected.arrays.items():
                np.testing.assert_array_equal(got.arrays[name], values, name)
            self.assertEqual(got.settings_json(), expected.settings_json())
            live = sculpt_state.capture(obj.Proxy.surface)
            np.testing.assert_array_equal(live.arrays["Poles"], expected.arrays["Poles"])
        # a write the live surface does not follow (as follow_base's, under `writing`): the next
        # commit compares with the properties themselves, not with what it wrote last, so the
        # document ends as the surface is
        live = obj.Proxy.live
        live.writing = True
        try:
            obj.MassMap = [2.5]
        finally:
            live.writing = False
        hs.set_uniform(obj, "damping", 5.0)
        self.assertEqual(list(obj.DampingMap), [5.0])
        self.assertEqual(list(obj.MassMap), list(sculpt_state.capture(obj.Proxy.surface).arrays["MassMap"]))
        self.assertNotEqual(list(obj.MassMap), [2.5])
