"""The FreeCAD layer in console mode: write-back, sources, undo, downstream solids, bad arguments."""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from freecad_support import DocumentTestCase

import FreeCAD
import Part

import HapticSculpt as hs
from HapticSculpt import core
from HapticSculpt.app.part_surface import compress_knots

if "/usr/share/freecad/Mod/Part" not in sys.path:
    sys.path.append("/usr/share/freecad/Mod/Part")  # BOPTools, on FreeCAD's own path in freecadcmd


def stroke(obj, lift=25.0, seconds=1.5):
    """Grab the middle of a patch, pull it up, hold, release."""
    dev = hs.ReplayDevice.stroke((0.0, 0.0, 0.0), (0.0, 0.0, lift), seconds=1.0, hold=seconds - 1.0)
    return hs.run(obj, seconds, device=dev, tool="rope")


def assert_face_matches_core(test, obj, samples=1000, seed=7):
    surface = obj.Proxy.surface
    bs = obj.Shape.Faces[0].Surface
    core_bs = surface.surface
    test.assertIsInstance(bs, Part.BSplineSurface)
    test.assertEqual((bs.UDegree, bs.VDegree), tuple(core_bs.degree))
    uk, um = compress_knots(core_bs.knots_u)
    vk, vm = compress_knots(core_bs.knots_v)
    test.assertEqual(bs.getUKnots(), uk)
    test.assertEqual(bs.getVKnots(), vk)
    test.assertEqual(bs.getUMultiplicities(), um)
    test.assertEqual(bs.getVMultiplicities(), vm)
    nu, nv = core_bs.controls
    poles = np.array([[tuple(p) for p in row] for row in bs.getPoles()])
    test.assertTrue(np.array_equal(poles, np.asarray(surface.poles)))
    w = np.array(bs.getWeights())
    if core_bs.weights is None:
        test.assertTrue(np.all(w == 1.0))
    else:
        test.assertTrue(np.array_equal(w, np.asarray(core_bs.weights)))
    rng = np.random.default_rng(seed)
    (u0, u1), (v0, v1) = core_bs.domain
    size = surface.size
    worst = 0.0
    for u, v in zip(rng.uniform(u0, u1, samples), rng.uniform(v0, v1, samples)):
        worst = max(worst, np.linalg.norm(np.array(tuple(bs.value(u, v))) - core_bs.evaluate(u, v)["point"]))
    test.assertLess(worst, 1e-12 * size)


def grid_points(obj, n=25):
    """Points of the sculpt face on an n x n parameter grid."""
    bs = obj.Shape.Faces[0].Surface
    u0, u1, v0, v1 = bs.bounds()
    return np.array([tuple(bs.value(u, v)) for u in np.linspace(u0, u1, n) for v in np.linspace(v0, v1, n)])


class TestWriteBack(DocumentTestCase):
    def test_face_after_stroke_is_the_core_surface(self):
        obj = hs.make_sculpt(self.doc, controls=(9, 7), degree=(3, 2), mesh=(30, 24))
        report = stroke(obj)
        self.assertEqual(report.refused_steps, 0)
        self.assertEqual(obj.Strokes, 1)
        self.assertGreater(np.ptp(np.asarray(obj.Proxy.surface.poles)[..., 2]), 5.0)
        assert_face_matches_core(self, obj)

    def test_rational_source_face_is_the_core_surface(self):
        cyl = self.doc.addObject("Part::Cylinder", "Cyl")
        self.doc.recompute()
        obj = hs.make_sculpt(self.doc, source=(cyl, "Face1"), controls=(8, 6))
        self.assertIsNotNone(obj.Proxy.surface.surface.weights)
        stroke(obj, lift=3.0)
        assert_face_matches_core(self, obj)

    def test_undo_restores_previous_state_exactly_and_redo_reapplies(self):
        obj = hs.make_sculpt(self.doc, mesh=(24, 24))
        stroke(obj)
        before = np.array(obj.Proxy.surface.poles)
        settings_before = obj.SculptSettings
        cid = hs.add_constraint(obj, "point", uv=(0.5, 0.5))
        stroke(obj, lift=-20.0)
        after = np.array(obj.Proxy.surface.poles)
        self.assertFalse(np.array_equal(before, after))
        self.doc.undo()  # the second stroke
        self.doc.undo()  # the constraint
        self.assertTrue(np.array_equal(np.asarray(obj.Proxy.surface.poles), before))
        self.assertEqual(obj.SculptSettings, settings_before)
        self.assertEqual(obj.Proxy.surface.constraints, [])
        face_poles = np.array([[tuple(p) for p in r] for r in obj.Shape.Faces[0].Surface.getPoles()])
        self.assertTrue(np.array_equal(face_poles, before))
        self.doc.redo()
        self.doc.redo()
        self.assertTrue(np.array_equal(np.asarray(obj.Proxy.surface.poles), after))
        self.assertEqual([c["id"] for c in obj.Proxy.surface.constraints], [cid])

    def test_undo_and_redo_leave_sculpts_solids_and_thicknesses_up_to_date(self):
        """Their Shape comes back with their state: the tree must not ask for a recompute, and one
        changes nothing. An edited base still waits for its recompute, and so does what it feeds."""
        box = self.doc.addObject("Part::Box", "Box")
        self.doc.recompute()
        solid = hs.sculpt_solid(self.doc, box, ["Face6"])
        patch = hs.make_sculpt(self.doc, mesh=(24, 24))
        thick = hs.make_thickness(patch, 2.0)
        self.doc.recompute()
        stroke(patch)
        hs.run(solid, 0.4, device=hs.ReplayDevice.stroke((5, 5, 10), (5, 5, 13.0), seconds=0.3, hold=0.1))
        self.doc.recompute()
        ours = (patch, solid, solid.Sculpts[0], thick)
        for step in (self.doc.undo, self.doc.undo, self.doc.redo, self.doc.redo):
            step()
            self.assertEqual([o.State for o in ours], [["Up-to-date"]] * 4, step.__name__)
        volume = solid.Shape.Volume
        self.doc.recompute()
        self.assertEqual(solid.Shape.Volume, volume)
        self.doc.openTransaction("Height")  # (a base edited, then its edit undone and redone: still to recompute)
        box.Height = 12.0
        self.doc.recompute()
        self.doc.commitTransaction()
        self.doc.undo()
        self.doc.redo()
        self.assertIn("Touched", box.State)
        self.assertIn("Touched", solid.State)

    def test_a_session_and_hold_edges_leave_a_sculpted_solid_up_to_date(self):
        """A threaded session on a solid's face (its frames and its last reset rebuild the solid),
        then Hold edges: the tree must not ask for a recompute (it marked the solid touched)."""
        box = self.doc.addObject("Part::Box", "Box")
        self.doc.recompute()
        solid = hs.sculpt_solid(self.doc, box, ["Face6"])
        self.doc.recompute()
        face = solid.Sculpts[0]
        session = hs.Session().start(face, hs.ReplayDevice.stroke((5, 5, 10), (5, 5, 13.0), seconds=0.3, hold=0.1),
                                     stop_when_finished=True)
        deadline = time.monotonic() + 60.0
        while session.running and time.monotonic() < deadline:
            time.sleep(0.02)
        session.stop()
        self.assertEqual(self.doc.UndoNames[0], "Sculpt stroke")
        self.assertEqual([o.State for o in (box, face, solid)], [["Up-to-date"]] * 3)
        hs.hold_boundary(face, "G1")
        self.assertEqual(self.doc.UndoNames[0], "Hold edges")
        self.assertEqual([o.State for o in (box, face, solid)], [["Up-to-date"]] * 3)

    def test_each_stroke_is_one_transaction(self):
        obj = hs.make_sculpt(self.doc)
        n = self.doc.UndoCount
        stroke(obj)
        self.assertEqual(self.doc.UndoCount, n + 1)
        self.assertEqual(self.doc.UndoNames[0], "Sculpt stroke")

    def test_constraints_hold_through_a_stroke(self):
        obj = hs.make_sculpt(self.doc, mesh=(30, 30))
        cid = hs.add_constraint(obj, "point", uv=(0.25, 0.25), target=(-25.0, -25.0, 0.0))
        nid = hs.add_constraint(obj, "normal", near=(25.0, 25.0, 0.0))
        stroke(obj)
        s = obj.Proxy.surface
        self.assertLess(s.constraint_error(cid), 0.5)
        self.assertLess(s.constraint_error(nid), 0.1)
        kinds = [c["kind"] for c in obj.Proxy.surface.constraints]
        self.assertEqual(kinds, ["point", "normal"])
        self.assertIn('"normal"', obj.SculptSettings)


class TestSources(DocumentTestCase):
    def check_exact(self, source, size):
        obj = hs.make_sculpt(self.doc, source=source, controls=(8, 8))
        self.assertEqual(obj.ConversionMethod, "exact")
        self.assertLess(obj.ConversionError, 1e-6 * size)
        nu, nv = obj.Proxy.surface.surface.controls
        self.assertGreaterEqual(min(nu, nv), 8)
        return obj

    def test_box_face(self):
        box = self.doc.addObject("Part::Box", "Box")
        self.doc.recompute()
        obj = self.check_exact((box, "Face6"), 10.0)
        self.assertAlmostEqual(obj.Shape.Area, box.Shape.Face6.Area, delta=1e-9)

    def test_cylinder_face_is_rational(self):
        obj = self.check_exact(Part.makeCylinder(10, 20).Faces[0], 20.0)
        self.assertIsNotNone(obj.Proxy.surface.surface.weights)
        # (OCCT's Area integrates rational faces only to ~0.1 %, so check the geometry itself)
        pts = grid_points(obj)
        self.assertLess(np.abs(np.hypot(pts[:, 0], pts[:, 1]) - 10.0).max(), 1e-12)
        self.assertAlmostEqual(pts[:, 2].min(), 0.0, delta=1e-12)
        self.assertAlmostEqual(pts[:, 2].max(), 20.0, delta=1e-12)

    def test_sphere_patch(self):
        sphere = Part.makeSphere(10, FreeCAD.Vector(), FreeCAD.Vector(0, 0, 1), -30, 40, 90)
        obj = self.check_exact(sphere.Faces[0], 10.0)
        self.assertLess(np.abs(np.linalg.norm(grid_points(obj), axis=1) - 10.0).max(), 1e-12)

    def test_lofted_bspline_face(self):
        curves = []
        for z, r in ((0, 10), (10, 14), (20, 9)):
            pts = [FreeCAD.Vector(x, r * math.sin(x / 7.0), z) for x in np.linspace(-20, 20, 6)]
            c = Part.BSplineCurve()
            c.interpolate(pts)
            curves.append(Part.Wire(c.toShape()))
        loft = Part.makeLoft(curves, False, False)
        self.check_exact(loft.Faces[0], 40.0)
        self.check_exact(loft.Faces[0].Surface, 40.0)

    def test_surface_without_exact_form_is_approximated_with_its_error(self):
        circles = [Part.Wire(Part.makeCircle(r, FreeCAD.Vector(0, 0, z))) for z, r in ((0, 10), (10, 15), (20, 8))]
        loft = Part.makeLoft(circles, False, False)  # degree 14 around: beyond the core's degree 5
        obj = hs.make_sculpt(self.doc, source=loft.Faces[0], controls=(12, 6))
        self.assertEqual(obj.ConversionMethod, "approximated")
        self.assertGreater(obj.ConversionError, 0.0)
        self.assertLess(obj.ConversionError, 0.05)
        self.assertEqual(obj.Proxy.surface.surface.controls, (12, 6))


class TestDownstream(DocumentTestCase):
    def sculpted(self):
        obj = hs.make_sculpt(self.doc, size=(60.0, 40.0), mesh=(30, 30))
        stroke(obj, lift=12.0)
        return obj

    def test_thicken_gives_a_valid_solid_of_the_right_volume(self):
        obj = self.sculpted()
        area = obj.Shape.Area
        volumes = {}
        for t in (0.5, -0.5, 2.0, -2.0):
            solid = hs.thicken(obj, t)
            self.assertTrue(solid.isValid())
            self.assertEqual(solid.ShapeType, "Solid")
            volumes[t] = solid.Volume
        for t in (0.5, -0.5):
            self.assertLess(abs(volumes[t] - area * abs(t)) / (area * abs(t)), 0.01)
        # Steiner: V(t) = A t + t^2 int H + t^3/3 int K, so the mean-curvature term cancels between sides
        self.assertLess(abs((volumes[2.0] + volumes[-2.0]) / 2 - area * 2.0) / (area * 2.0), 0.01)

    def test_cut_and_split_a_solid(self):
        obj = self.sculpted()
        box = self.doc.addObject("Part::Box", "Box")
        box.Length, box.Width, box.Height = 40.0, 20.0, 30.0
        box.Placement.Base = FreeCAD.Vector(-20, -10, -10)
        tool = self.doc.addObject("Part::Feature", "Thick")
        tool.Shape = hs.thicken(obj, 2.0)
        cut = self.doc.addObject("Part::Cut", "Cut")
        cut.Base, cut.Tool = box, tool
        self.doc.recompute()
        self.assertTrue(cut.Shape.isValid())
        self.assertLess(cut.Shape.Volume, box.Shape.Volume - 1.0)
        from BOPTools import SplitAPI
        pieces = SplitAPI.slice(box.Shape, [obj.Shape], "Split")
        self.assertEqual(len(pieces.Solids), 2)
        self.assertAlmostEqual(sum(s.Volume for s in pieces.Solids), box.Shape.Volume, delta=1e-6 * box.Shape.Volume)

    def test_step_export_reads_back_in_freecad(self):
        obj = self.sculpted()
        path = hs.export_step(obj, f"{self.tmp}/sculpt.step")
        shell = Part.read(path)
        back = shell.Faces[0].Surface
        bs = obj.Shape.Faces[0].Surface
        self.assertEqual(back.getUMultiplicities(), bs.getUMultiplicities())
        a = np.array([[tuple(p) for p in r] for r in back.getPoles()])
        b = np.array([[tuple(p) for p in r] for r in bs.getPoles()])
        self.assertLess(np.abs(a - b).max(), 1e-9 * max(1.0, np.abs(b).max()))


class TestBadArguments(DocumentTestCase):
    def assert_refused(self, error, fn, *args, name, **kwargs):
        count, undo = len(self.doc.Objects), self.doc.UndoCount
        with self.assertRaises(error) as ctx:
            fn(*args, **kwargs)
        self.assertIn(name, str(ctx.exception))
        self.assertEqual(len(self.doc.Objects), count)
        self.assertEqual(self.doc.UndoCount, undo)

    def test_make_sculpt(self):
        self.assert_refused(ValueError, hs.make_sculpt, self.doc, controls=(3, 8), name="controls")
        self.assert_refused(ValueError, hs.make_sculpt, self.doc, degree=(6, 3), name="degree")
        self.assert_refused(TypeError, hs.make_sculpt, self.doc, controls=(8.5, 8), name="controls")
        self.assert_refused(ValueError, hs.make_sculpt, self.doc, mesh=(6, 40), name="mesh")
        self.assert_refused(ValueError, hs.make_sculpt, self.doc, size=(float("nan"), 1.0), name="size")
        self.assert_refused(TypeError, hs.make_sculpt, "doc", name="doc")
        self.assert_refused(TypeError, hs.make_sculpt, self.doc, source=42, name="source")
        self.assert_refused(ValueError, hs.make_sculpt, self.doc, centre=(1.0, 2.0), name="centre")
        self.assert_refused(ValueError, hs.make_sculpt, self.doc, centre=(float("inf"), 0, 0), name="centre")
        self.assert_refused(TypeError, hs.make_sculpt, self.doc, centre="origin", name="centre")
        self.assert_refused(TypeError, hs.make_sculpt, self.doc, centre=5, name="centre")
        other = FreeCAD.newDocument("HSOther")
        try:
            box = other.addObject("Part::Box", "Box")
            other.recompute()
            self.assert_refused(ValueError, hs.make_sculpt, self.doc, source=(box, "Face1"), name="source")
        finally:
            FreeCAD.closeDocument(other.Name)

    def test_a_flat_patch_lies_where_its_centre_says(self):
        obj = hs.make_sculpt(self.doc, size=(60.0, 40.0), centre=(100.0, -20.0, 5.0))
        box = obj.Shape.BoundBox
        self.assertAlmostEqual(box.XMin, 70.0, places=9)
        self.assertAlmostEqual(box.YMax, 0.0, places=9)
        self.assertAlmostEqual(box.ZMax, 5.0, places=9)

    def test_run_and_constraints(self):
        obj = hs.make_sculpt(self.doc)
        poles = np.array(obj.Proxy.surface.poles)
        dev = hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 10))
        self.assert_refused(ValueError, hs.run, obj, -1.0, device=dev, name="seconds")
        self.assert_refused(ValueError, hs.run, obj, float("inf"), device=dev, name="seconds")
        self.assert_refused(ValueError, hs.run, obj, 1.0, device=dev, tool="hammer", name="tool")
        self.assert_refused(TypeError, hs.run, self.doc, 1.0, name="obj")
        self.assert_refused(ValueError, hs.add_constraint, obj, "weld", uv=(0.5, 0.5), name="kind")
        self.assert_refused(ValueError, hs.add_constraint, obj, "point", uv=(1.5, 0.5), name="uv")
        self.assert_refused(ValueError, hs.add_constraint, obj, "point", name="uv/near")
        self.assert_refused(TypeError, hs.add_constraint, obj, "point", uv=(0.5, 0.5), normal=(0, 0, 1), name="normal")
        self.assert_refused(ValueError, hs.thicken, obj, 0.0, name="thickness")
        self.assert_refused(ValueError, hs.export_step, obj, f"{self.tmp}/x.stl", name="path")
        self.assertTrue(np.array_equal(np.asarray(obj.Proxy.surface.poles), poles))

    def test_replay_device(self):
        with self.assertRaisesRegex(ValueError, "xyz"):
            hs.ReplayDevice([0.0, 1.0], [[0, 0, 0], [0, float("nan"), 0]])
        with self.assertRaisesRegex(ValueError, "t:"):
            hs.ReplayDevice([0.0, 0.0], [[0, 0, 0], [0, 0, 1]])
        with self.assertRaisesRegex(ValueError, "quat"):
            hs.ReplayDevice([0.0, 1.0], [[0, 0, 0], [0, 0, 1]], quat=[[1, 0, 0, 0], [0, 0, 0, 0]])
        with self.assertRaisesRegex(ValueError, "buttons"):
            hs.ReplayDevice([0.0, 1.0], [[0, 0, 0], [0, 0, 1]], buttons=[1])


class TestReplayDevice(DocumentTestCase):
    def test_file_round_trip_is_exact_and_replays_identically(self):
        rng = np.random.default_rng(3)
        t = np.cumsum(rng.uniform(1e-3, 2e-2, 80))
        xyz = rng.normal(size=(80, 3)) * 7.0 + [0, 0, 10]
        q = rng.normal(size=(80, 4))
        b = (rng.uniform(size=80) < 0.8).astype(int)
        dev = hs.ReplayDevice(t, xyz, q, b)
        dev.save(f"{self.tmp}/traj.txt")
        back = hs.ReplayDevice.load(f"{self.tmp}/traj.txt")
        for a, c in zip(dev.arrays(), back.arrays()):
            self.assertTrue(np.array_equal(a, c))
        ends = []
        for device in (dev, back):
            obj = hs.make_sculpt(self.doc, mesh=(20, 20))
            hs.run(obj, 1.0, device=device, tool="magnet")
            ends.append(np.array(obj.Proxy.surface.poles))
        self.assertTrue(np.array_equal(ends[0], ends[1]))

    def test_interpolation(self):
        dev = hs.ReplayDevice([0.0, 1.0], [[0, 0, 0], [10, 0, 0]], buttons=[1, 0])
        s = dev.sample(0.25)
        self.assertEqual(s.position, (2.5, 0.0, 0.0))
        self.assertTrue(s.grab)
        self.assertFalse(dev.sample(1.0).grab)
        self.assertEqual(dev.sample(5.0).position, (10.0, 0.0, 0.0))


class TestCore(DocumentTestCase):
    def test_live_surface_drives_everything_else(self):
        obj = hs.make_sculpt(self.doc)
        s = obj.Proxy.surface
        self.assertIsInstance(s, core.DynamicSurface)
        s.integrator = "implicit"
        s.stiffness_map.dab((0.5, 0.5), 0.2, 400.0)
        hs.run(obj, 0.2)
        self.assertIn('"implicit"', obj.SculptSettings)
        self.assertFalse(obj.Proxy.surface.stiffness_map.uniform)


class TestReadme(DocumentTestCase):
    def test_scripting_example_runs(self):
        import os
        import re
        from freecad_support import ROOT
        with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
            block = re.search(r"## Scripting.*?```python\n(.*?)```", f.read(), re.S).group(1)
        block = block.replace('"/tmp/sculpt.step"', repr(os.path.join(self.tmp, "sculpt.step")))
        scope = {}
        exec(compile(block, "README.md", "exec"), scope)
        self.assertEqual(scope["obj"].Strokes, 1)
        self.assertGreater(scope["obj"].Shape.BoundBox.ZMax, 1.0)  # the rope lifted the patch
        self.assertTrue(os.path.getsize(os.path.join(self.tmp, "sculpt.step")) > 0)
        shape = scope["solid"].Shape
        self.assertTrue(shape.isValid())
        self.assertEqual(len(shape.Solids), 1)
        self.assertGreater(shape.BoundBox.ZMax, 31.0)  # the box's top pulled up
        FreeCAD.closeDocument(scope["doc"].Name)


class TestPackage(DocumentTestCase):
    def test_package_xml_is_read_by_freecad(self):
        import os
        from freecad_support import ROOT
        meta = FreeCAD.Metadata(os.path.join(ROOT, "package.xml"))
        self.assertEqual(meta.Name, "HapticSculpt")
        bench = meta.Content["workbench"][0]
        self.assertEqual(bench.Classname, "HapticSculptWorkbench")
        self.assertEqual(bench.FreeCADMin, "0.20.0")  # higher makes 0.20 skip the addon
        self.assertTrue(os.path.isfile(os.path.join(ROOT, bench.Icon)))
        self.assertIn("numpy", [d["package"] for d in bench.Depend])
        with open(os.path.join(ROOT, "InitGui.py"), encoding="utf-8") as f:
            self.assertIn(f"class {bench.Classname}(", f.read())
