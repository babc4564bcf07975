"""The pull toward a scan (issue 30): data springs draw the surface onto its target in hs.run and
in a threaded session (kept at its stop as one undo step, with no stroke made); the switch and the strength are one undo step each and saved; the
pull map, painted or set to 0, takes the pull away there; a changed target link is followed;
outliers and a hole do not pull or tear it; bad calls are refused by name."""
from __future__ import annotations

import os

import FreeCAD
import numpy as np
from freecad_support import DocumentTestCase

import HapticSculpt as hs


def plane_scan(height: float, n: int = 90, half: float = 55.0, seed: int = 0) -> np.ndarray:
    """A scan of the plane z = height over the patch, 0.02 mm noise."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.linspace(-half, half, n), np.linspace(-half, half, n), indexing="ij")
    return np.c_[x.ravel(), y.ravel(), height + rng.normal(0, 0.02, n * n)]


class TestPull(DocumentTestCase):
    def setUp(self) -> None:
        super().setUp()
        self.sculpt = hs.make_sculpt(self.doc, controls=(8, 8), size=(100.0, 100.0), mesh=(32, 32))

    def z(self) -> np.ndarray:
        return np.asarray(self.sculpt.Proxy.live.surface.mesh)[..., 2]

    def test_run_draws_the_surface_onto_the_scan_and_the_switch_stops_it(self):
        hs.set_target(self.sculpt, plane_scan(3.0), tolerance=0.1)
        self.assertEqual(hs.deviation_of(self.sculpt)["within_pct"], 0.0)
        hs.run(self.sculpt, 0.5)
        report = hs.deviation_of(self.sculpt)
        self.assertGreater(report["within_pct"], 99.0)
        self.assertLess(abs(report["mean_signed_mm"]), 0.02)
        self.assertEqual(hs.pull_of(self.sculpt)["anchored"], 32 * 32)
        # Off: one undo step, and a run leaves the surface where it is.
        undo = self.doc.UndoCount
        hs.set_pull(self.sculpt, False)
        self.assertEqual(self.doc.UndoNames[: self.doc.UndoCount - undo], ["Stop pulling toward target"])
        hs.set_target(self.sculpt, plane_scan(6.0), weight=0.0)  # (weight 0: set, but off)
        hs.run(self.sculpt, 0.2)
        self.assertAlmostEqual(float(self.z().mean()), 3.0, delta=0.02)  # (not drawn toward 6 mm)
        self.assertEqual(float(np.abs(np.asarray(self.sculpt.Proxy.live.surface.external_forces)).max()), 0.0)
        hs.set_pull(self.sculpt, True, strength=2.0)
        hs.run(self.sculpt, 0.5)
        self.assertAlmostEqual(float(self.z().mean()), 6.0, delta=0.02)  # the new target, followed
        self.doc.undo()  # the run
        self.doc.undo()  # the switch
        self.assertFalse(hs.pull_of(self.sculpt)["enabled"])

    def test_a_session_without_a_stroke_keeps_what_the_pull_did_as_one_undo_step(self):
        hs.set_target(self.sculpt, plane_scan(3.0), tolerance=0.1)
        undo = self.doc.UndoCount
        t = np.linspace(0.0, 1.0, 41)  # (the device hovers away from the patch, its button up)
        hover = hs.ReplayDevice(t, np.tile([80.0, 80.0, 30.0], (41, 1)), buttons=np.zeros(41, dtype=int))
        session = hs.Session().start(self.sculpt, hover, stop_when_finished=True)
        self.assertTrue(session.wait(timeout=30))
        self.assertEqual(session.status()["error"], "")
        self.assertEqual(self.doc.UndoNames[: self.doc.UndoCount - undo], ["Pulled toward target"])
        self.assertGreater(hs.deviation_of(self.sculpt)["within_pct"], 99.0)  # (the document's state)
        self.doc.undo()
        self.assertEqual(float(np.abs(np.asarray(self.sculpt.Poles)).reshape(-1, 3)[:, 2].max()), 0.0)
        # Switched off, a session moves nothing and adds no step.
        hs.set_pull(self.sculpt, False)
        undo = self.doc.UndoCount
        session = hs.Session().start(self.sculpt, hover, stop_when_finished=True)
        self.assertTrue(session.wait(timeout=30))
        self.assertEqual(self.doc.UndoCount, undo)

    def test_a_zero_pull_map_and_a_cleared_target_pull_nothing(self):
        hs.set_target(self.sculpt, plane_scan(3.0))
        hs.set_uniform(self.sculpt, "pull", 0.0)
        hs.run(self.sculpt, 0.3)
        self.assertEqual(float(np.abs(self.z()).max()), 0.0)
        hs.set_uniform(self.sculpt, "pull", 1.0)
        # Painted away over one half (u < 0.5): that half stays nearer its place than the other.
        hs.paint(self.sculpt, "pull", [(0.15, v) for v in np.linspace(0.0, 1.0, 30)], radius=0.35, factor=1e-6,
                 strength=1.0)
        self.assertLess(float(np.asarray(self.sculpt.Proxy.live.surface.pull_map.values)[0].max()), 0.1)
        hs.run(self.sculpt, 0.05)
        z = self.z()
        self.assertLess(float(z[:4].mean()), 0.5 * float(z[-4:].mean()))
        hs.clear_target(self.sculpt)
        self.assertFalse(hs.pull_of(self.sculpt)["target"])
        hs.run(self.sculpt, 0.01)
        self.assertEqual(float(np.abs(np.asarray(self.sculpt.Proxy.live.surface.external_forces)).max()), 0.0)

    def test_outliers_and_a_hole_neither_pull_nor_tear_it(self):
        points = plane_scan(2.0, n=120)
        hole = np.hypot(points[:, 0] - 10, points[:, 1] + 5) < 18
        points = points[~hole]
        rng = np.random.default_rng(3)
        out = rng.random(len(points)) < 0.01
        points[out, 2] += 5.0 * rng.choice([-1.0, 1.0], int(out.sum()))
        hs.set_target(self.sculpt, points, tolerance=0.1)
        hs.run(self.sculpt, 0.8)
        z = self.z()
        self.assertLess(float(np.abs(z - 2.0).max()), 0.1)  # the hole bridged flat, no outlier's bump
        report = hs.deviation_of(self.sculpt)
        self.assertAlmostEqual(report["within_pct"], 99.0, delta=0.5)  # (the outliers are the 1 % outside)

    def test_saved_with_the_document(self):
        hs.set_target(self.sculpt, plane_scan(1.0), weight=3.0)
        hs.paint(self.sculpt, "pull", [(0.5, 0.5)], radius=0.2, factor=1e-6, strength=1.0)
        painted, name = np.asarray(self.sculpt.PullMap).copy(), self.sculpt.Name
        path = os.path.join(self.tmp, "pull.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        sculpt = self.doc.getObject(name)
        np.testing.assert_array_equal(np.asarray(sculpt.PullMap), painted)
        pull = hs.pull_of(sculpt)
        self.assertEqual((pull["enabled"], pull["strength"], pull["target"]), (True, 3.0, True))
        hs.run(sculpt, 0.3)
        self.assertGreater(hs.deviation_of(sculpt)["within_pct"], 50.0)

    def test_bad_calls_are_refused_by_name(self):
        hs.set_target(self.sculpt, plane_scan(1.0))
        for kwargs, name in (({"strength": -1.0}, "strength"), ({"strength": float("nan")}, "strength"),
                             ({"strength": "strong"}, "strength"), ({"enabled": 1}, "enabled")):
            with self.subTest(kwargs=kwargs), self.assertRaisesRegex((ValueError, TypeError), name):
                hs.set_pull(self.sculpt, **kwargs)
        with self.assertRaisesRegex(ValueError, "value"):
            hs.set_uniform(self.sculpt, "pull", -1.0)
        self.assertTrue(hs.pull_of(self.sculpt)["enabled"])
