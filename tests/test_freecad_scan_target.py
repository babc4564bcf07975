"""Scan targets (hs.set_target, issue 30): an array, a mesh in the document, STL / OBJ / PLY files;
one undo step each, saved and reopened; bad targets refused by name with nothing changed; the
deviation report against known offsets and against OpenCASCADE's own projection; the Deviation
property kept up to date by a stroke; the sign outside a sculpted solid."""
from __future__ import annotations

import json
import os

import FreeCAD
import Mesh
import Part
import numpy as np
from freecad_support import DocumentTestCase

import HapticSculpt as hs


def mesh_of(shape) -> Mesh.Mesh:
    """A triangle mesh of a Part shape (Mesh's own primitives need a module freecadcmd lacks)."""
    points, facets = shape.tessellate(0.05)
    return Mesh.Mesh([[points[i] for i in facet] for facet in facets])


def pull(obj, lift: float) -> None:
    dev = hs.ReplayDevice.stroke((0.0, 0.0, 0.0), (0.0, 0.0, lift), seconds=1.0, hold=0.5)
    hs.run(obj, 1.5, device=dev, tool="rope")


def offset_points(sculpt, offsets: np.ndarray, seed: int = 3) -> np.ndarray:
    """Points at known signed distances along the normal from random points of the surface."""
    surface = sculpt.Shape.Faces[0].Surface
    rng = np.random.default_rng(seed)
    uv = rng.uniform(0.1, 0.9, (len(offsets), 2))
    out = []
    for (u, v), off in zip(uv, offsets):
        p, n = surface.value(u, v), surface.normal(u, v)
        out.append(p + n * float(off))
    return np.array([(q.x, q.y, q.z) for q in out])


class TestScanTarget(DocumentTestCase):
    def setUp(self) -> None:
        super().setUp()
        self.sculpt = hs.make_sculpt(self.doc, size=(100.0, 80.0), mesh=(32, 32), material="clay")
        self.doc.recompute()

    def deviation_property(self) -> dict:
        return json.loads(self.sculpt.Deviation)

    def test_an_array_is_one_undo_step_and_is_saved(self):
        rng = np.random.default_rng(1)
        points = np.c_[rng.uniform(-40, 40, (3000, 2)), 0.4 + rng.normal(0, 0.02, 3000)]
        before = len(self.doc.Objects)
        undo = self.doc.UndoCount
        target = hs.set_target(self.sculpt, points, weight=2.0, tolerance=0.5)
        self.assertEqual(target.TypeId, "Points::Feature")
        self.assertEqual(target.Points.CountPoints, 3000)
        self.assertEqual(self.doc.UndoNames[: self.doc.UndoCount - undo], ["Set target"])
        self.assertIs(hs.target_object(self.sculpt), target)
        report = hs.deviation_of(self.sculpt)
        self.assertAlmostEqual(report["mean_signed_mm"], 0.4, delta=0.005)
        self.assertEqual(report["points"], 3000)
        self.assertEqual(report["within_pct"], 100.0)
        self.assertEqual(self.deviation_property()["points"], 3000)
        name = target.Name
        self.doc.undo()
        self.assertIsNone(self.doc.getObject(name))
        self.assertEqual(len(self.doc.Objects), before)
        self.doc.redo()
        self.assertEqual(self.sculpt.Target.Name, name)
        path = os.path.join(self.tmp, "scan.FCStd")
        self.doc.saveAs(path)
        stored, sculpt_name = self.sculpt.Deviation, self.sculpt.Name
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        sculpt = self.doc.getObject(sculpt_name)
        self.assertEqual(sculpt.Target.Name, name)
        self.assertEqual(float(sculpt.TargetTolerance), 0.5)
        pull = hs.pull_of(sculpt)  # (the weight is the pull's strength, in the sculpt state)
        self.assertEqual((pull["enabled"], pull["strength"], pull["target"]), (True, 2.0, True))
        self.assertEqual(sculpt.Deviation, stored)
        self.assertEqual(hs.deviation_of(sculpt)["points"], 3000)

    def test_a_mesh_of_the_document_and_files(self):
        mesh = self.doc.addObject("Mesh::Feature", "Scan")
        mesh.Mesh = mesh_of(Part.makeBox(60, 60, 4, FreeCAD.Vector(-30, -30, -2)))  # top 2 mm above the patch
        self.doc.recompute()
        before = len(self.doc.Objects)
        self.assertIs(hs.set_target(self.sculpt, mesh), mesh)
        self.assertEqual(len(self.doc.Objects), before)  # linked, not copied
        self.assertAlmostEqual(hs.deviation_of(self.sculpt)["max_mm"], 2.0, places=5)
        mesh.Placement.Base = FreeCAD.Vector(0, 0, 1)  # moving the scan moves what is measured
        self.doc.recompute()
        self.assertAlmostEqual(hs.deviation_of(self.sculpt)["max_mm"], 3.0, places=5)
        self.assertAlmostEqual(self.deviation_property()["max_mm"], 3.0, places=5)

        stl = os.path.join(self.tmp, "part.stl")
        mesh_of(Part.makeSphere(30)).write(stl)
        target = hs.set_target(self.sculpt, stl)
        self.assertEqual((target.TypeId, target.Label), ("Mesh::Feature", "part"))
        self.assertGreater(hs.deviation_of(self.sculpt)["points"], 100)

        obj = os.path.join(self.tmp, "cloud.obj")  # vertices only: a point cloud
        with open(obj, "w") as f:
            f.writelines(f"v {x} {y} 1.5\n" for x in range(-30, 31, 10) for y in range(-30, 31, 10))
        target = hs.set_target(self.sculpt, obj)
        self.assertEqual(target.TypeId, "Points::Feature")
        self.assertEqual(hs.deviation_of(self.sculpt)["points"], 49)
        self.assertAlmostEqual(hs.deviation_of(self.sculpt)["max_mm"], 1.5, places=5)

        ply = os.path.join(self.tmp, "cloud.ply")
        with open(ply, "w") as f:
            f.write("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                    "property float z\nend_header\n0 0 -1\n10 0 -1\n0 10 -1\n10 10 -1\n")
        target = hs.set_target(self.sculpt, ply)
        report = hs.deviation_of(self.sculpt)
        self.assertEqual(report["points"], 4)
        self.assertAlmostEqual(report["min_signed_mm"], -1.0, places=5)

        binary = os.path.join(self.tmp, "scan.ply")  # a scanner's binary cloud, with a colour and faces after
        vertices = np.zeros(3, dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("red", "u1")])
        vertices["x"], vertices["z"] = (0, 5, 10), 2.5
        with open(binary, "wb") as f:
            f.write(b"ply\nformat binary_little_endian 1.0\ncomment scanner\nelement vertex 3\n"
                    b"property double x\nproperty double y\nproperty double z\nproperty uchar red\n"
                    b"element face 0\nproperty list uchar int vertex_indices\nend_header\n" + vertices.tobytes())
        hs.set_target(self.sculpt, binary)
        report = hs.deviation_of(self.sculpt)
        self.assertEqual(report["points"], 3)
        self.assertAlmostEqual(report["max_signed_mm"], 2.5, places=9)

    def test_bad_targets_are_refused_by_name_and_change_nothing(self):
        garbage = os.path.join(self.tmp, "garbage.stl")
        with open(garbage, "wb") as f:
            f.write(b"\x00\x01 not a mesh")
        other = FreeCAD.newDocument("Other")
        try:
            foreign = other.addObject("Mesh::Feature", "M")
            foreign.Mesh = mesh_of(Part.makeBox(1, 1, 1))
            box = self.doc.addObject("Part::Box", "Box")
            self.doc.recompute()
            objects, undo = len(self.doc.Objects), self.doc.UndoCount
            cases = [(np.zeros((0, 3)), ValueError, "no points"),
                     (np.array([[0, 0, 0], [1, np.nan, 0]]), ValueError, "point 1 is not finite"),
                     (np.ones((4, 2)), ValueError, "(n, 3)"),
                     (os.path.join(self.tmp, "missing.stl"), ValueError, "no file"),
                     (os.path.join(self.tmp, "scan.txt"), ValueError, "STL, OBJ or PLY"),
                     (garbage, ValueError, "target"),
                     (box, TypeError, "mesh or point cloud"),
                     (foreign, ValueError, "another document"),
                     (42, TypeError, "target")]
            for bad, kind, words in cases:
                with self.assertRaises(kind, msg=repr(bad)) as caught:
                    hs.set_target(self.sculpt, bad)
                self.assertIn(words, str(caught.exception))
            with self.assertRaisesRegex(ValueError, "tolerance"):
                hs.set_target(self.sculpt, np.ones((3, 3)), tolerance=-1)
            with self.assertRaisesRegex(ValueError, "weight"):
                hs.set_target(self.sculpt, np.ones((3, 3)), weight=float("nan"))
            with self.assertRaisesRegex(ValueError, "has no target"):
                hs.deviation_of(self.sculpt)
            with self.assertRaisesRegex(TypeError, "obj"):
                hs.set_target(box, np.ones((3, 3)))
            self.assertEqual((len(self.doc.Objects), self.doc.UndoCount), (objects, undo))
        finally:
            FreeCAD.closeDocument(other.Name)

    def test_deviation_of_known_offsets_agrees_with_opencascade(self):
        pull(self.sculpt, 8.0)  # a curved surface: the bump
        rng = np.random.default_rng(7)
        offsets = rng.uniform(-0.3, 0.5, 400)
        offsets[:2] = (-0.3, 0.5)
        inside = offset_points(self.sculpt, offsets)
        beyond = np.array([[80.0, 0.0, 0.0], [0.0, 70.0, 1.0]])  # past the edges (x = 50, y = 40)
        hs.set_target(self.sculpt, np.vstack([inside, beyond]), tolerance=0.25)
        report = hs.deviation_of(self.sculpt)
        self.assertEqual((report["points"], report["beyond_edge"]), (400, 2))
        # Points are kept as float32 by FreeCAD's point cloud: agreement to a few micrometres.
        self.assertAlmostEqual(report["min_signed_mm"], -0.3, delta=2e-5)
        self.assertAlmostEqual(report["max_signed_mm"], 0.5, delta=2e-5)
        self.assertAlmostEqual(report["mean_signed_mm"], offsets.mean(), delta=2e-5)
        self.assertAlmostEqual(report["within_pct"], 100 * np.mean(np.abs(offsets) <= 0.25), delta=0.5)
        # The independent measure: OpenCASCADE's projection of each point onto the face's surface.
        surface = self.sculpt.Shape.Faces[0].Surface
        stored = np.array([(v.x, v.y, v.z) for v in self.sculpt.Target.Points.Points])[:400]
        occ = []
        for x in stored:
            u, v = surface.parameter(FreeCAD.Vector(*x))
            occ.append((FreeCAD.Vector(*x) - surface.value(u, v)).Length)
        occ = np.array(occ)
        self.assertAlmostEqual(report["max_mm"], occ.max(), delta=1e-6)
        self.assertAlmostEqual(report["mean_mm"], occ.mean(), delta=1e-6)
        self.assertAlmostEqual(report["p95_mm"], np.percentile(occ, 95), delta=1e-6)
        self.assertAlmostEqual(hs.deviation_of(self.sculpt, tolerance=0.1)["within_pct"],
                               100 * np.mean(occ <= 0.1), delta=0.5)

    def test_the_deviation_property_follows_a_stroke(self):
        rng = np.random.default_rng(2)
        hs.set_target(self.sculpt, np.c_[rng.uniform(-45, 45, (2000, 2)), np.zeros(2000)], weight=0.0)  # (no pull back)
        self.assertAlmostEqual(self.deviation_property()["max_mm"], 0.0, places=9)
        pull(self.sculpt, 6.0)
        self.doc.recompute()
        after = self.deviation_property()
        self.assertGreater(after["max_mm"], 1.0)
        self.assertAlmostEqual(after["max_mm"], hs.deviation_of(self.sculpt)["max_mm"], places=9)
        self.assertEqual(self.sculpt.getEditorMode("Deviation"), ["ReadOnly"])

    def test_the_tolerance_is_a_length_and_editing_it_measures_again(self):
        """TargetTolerance shows and takes its unit in the property editor; an edit there (a
        transaction of its own) is one undo step with the report measured at the new tolerance."""
        rng = np.random.default_rng(4)
        hs.set_target(self.sculpt, np.c_[rng.uniform(-40, 40, (2000, 2)), rng.uniform(-0.2, 0.2, 2000)],
                      weight=0.0, tolerance=0.1)
        self.assertEqual(self.sculpt.getTypeIdOfProperty("TargetTolerance"), "App::PropertyLength")
        self.assertAlmostEqual(self.deviation_property()["within_pct"], 50.0, delta=4.0)
        undo = self.doc.UndoCount
        self.doc.openTransaction("Edit tolerance")
        self.sculpt.TargetTolerance = "0.15 mm"
        self.doc.commitTransaction()
        self.assertEqual(self.doc.UndoCount, undo + 1)
        self.assertEqual(self.deviation_property()["tolerance_mm"], 0.15)
        self.assertAlmostEqual(self.deviation_property()["within_pct"], 75.0, delta=4.0)
        self.doc.undo()
        self.assertEqual(self.deviation_property()["tolerance_mm"], 0.1)

    def test_the_sign_is_outside_a_sculpted_solid(self):
        box = self.doc.addObject("Part::Box", "Box")
        box.Length, box.Width, box.Height = 40, 40, 20
        self.doc.recompute()
        top = next(i for i, f in enumerate(box.Shape.Faces) if abs(f.CenterOfMass.z - 20) < 1e-9)
        solid = hs.sculpt_solid(self.doc, box, [f"Face{top + 1}"])
        self.doc.recompute()
        hs.set_target(solid, np.array([[20.0, 20.0, 20.7], [10.0, 30.0, 20.7]]))  # 0.7 mm above the top
        report = hs.deviation_of(solid)
        self.assertTrue(report["signed"])
        self.assertAlmostEqual(report["min_signed_mm"], 0.7, places=5)


class TestNoScanThere(DocumentTestCase):
    def test_past_the_scans_edge_and_in_its_hole_the_display_shows_no_scan(self):
        """The colour map's NaN (grey): a surface point past the scan's edge by more than a spacing
        and a half, or inside a hole; over the scan, the distance along the normal, also where the
        surface is tilted to the scan and off it."""
        from HapticSculpt import core
        from HapticSculpt.app.scan_deviation import mesh_deviation
        from HapticSculpt.app.scan_target import point_spacing
        x, y = np.meshgrid(np.arange(0.0, 50.0001, 0.5), np.arange(0.0, 50.0001, 0.5), indexing="ij")
        scan = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
        scan = scan[np.hypot(scan[:, 0] - 25.0, scan[:, 1] - 25.0) > 5.0]  # a hole of radius 5 mm
        spacing = point_spacing(scan)
        self.assertAlmostEqual(spacing, 0.5, delta=0.03)
        tree, tol = core.PointTree(scan), 0.1
        u, v = np.meshgrid(np.linspace(-20.0, 70.0, 91), np.linspace(-20.0, 70.0, 91), indexing="ij")
        flat = np.stack([u, v, np.full(u.shape, 0.05)], axis=-1)
        normals = np.broadcast_to(np.array([0.0, 0.0, 1.0]), flat.shape)
        signed = mesh_deviation(flat, normals, tree, scan, 0, 1.5 * spacing + tol)
        past = (u < -1.0) | (u > 51.0) | (v < -1.0) | (v > 51.0) | (np.hypot(u - 25.0, v - 25.0) < 4.0)
        over = (u >= 0) & (u <= 50) & (v >= 0) & (v <= 50) & (np.hypot(u - 25.0, v - 25.0) > 6.0)
        self.assertTrue(np.isnan(signed[past]).all())
        np.testing.assert_allclose(signed[over], -0.05, atol=1e-12)
        # tilted 20 degrees and 5 mm off over the scan's middle: measured, not "no scan"
        t = np.radians(20.0)
        tilted = np.stack([u * 0.2 + 10.0, v * 0.2 + 10.0, 5.0 + (u * 0.2) * np.tan(t)], axis=-1)
        n = np.array([-np.sin(t), 0.0, np.cos(t)])
        signed = mesh_deviation(tilted, np.broadcast_to(n, tilted.shape), tree, scan, 0, 1.5 * spacing + tol)
        self.assertFalse(np.isnan(signed).any())
        self.assertTrue((signed < -3.0).all())
