"""Fair strokes in the document (issue 26): HapticSculpt.fair (one undo step, held edges kept, clear
errors), make_sculpt's held edges, and the bending weight saved and reopened with the sculpt."""
from __future__ import annotations

import os
import time

import FreeCAD
import numpy as np
from freecad_support import DocumentTestCase
from test_freecad_layer import stroke

import HapticSculpt as hs
from HapticSculpt.app.api import FAIR_BENDING
from HapticSculpt.app.fairness import fair_text


def curvature_variation(obj) -> float:
    """Sum of squared third differences of the mesh along u and v (what Fair relaxes)."""
    mesh = np.array(obj.Proxy.live.snapshot().mesh)
    return float((np.diff(mesh, 3, axis=0) ** 2).sum() + (np.diff(mesh, 3, axis=1) ** 2).sum())


class TestFair(DocumentTestCase):
    def test_fair_is_one_undo_step_that_keeps_held_edges(self):
        obj = hs.make_sculpt(self.doc, material="clay", edges="held")
        self.assertEqual(hs.held_boundary(obj), {"u0": "G1", "u1": "G1", "v0": "G1", "v1": "G1"})
        hs.set_uniform(obj, "bending", 0.0)  # today's springs alone: the stroke leaves waves to fair
        stroke(obj)
        poles = np.array(obj.Poles).reshape(-1, 3)
        held = obj.Proxy.live.snapshot().held_poles
        n = self.doc.UndoCount
        variation = curvature_variation(obj)
        peak = float(np.abs(obj.Proxy.live.snapshot().curvature_grid()[..., 2:4]).max())
        report = hs.fair(obj)
        self.assertEqual(self.doc.UndoCount, n + 1)
        # it says what it moved: the poles' largest move and the peak curvature before and after
        moved = float(np.abs(np.array(obj.Poles).reshape(-1, 3) - poles).max())
        self.assertAlmostEqual(report["moved_mm"], moved, delta=1e-12)
        self.assertAlmostEqual(report["peak_curvature_before"], peak, delta=1e-12)
        self.assertAlmostEqual(report["peak_curvature_after"],
                               float(np.abs(obj.Proxy.live.snapshot().curvature_grid()[..., 2:4]).max()), delta=1e-12)
        self.assertIs(obj.Proxy.live.last_fair, report)
        self.assertIn(f"poles moved up to {moved:.2g} mm", fair_text(report))
        self.assertEqual(fair_text({**report, "moved_mm": 0.0}), "nothing moved (it was fair already)")
        self.assertEqual(self.doc.UndoNames[0], "Fair")
        after = np.array(obj.Poles).reshape(-1, 3)
        np.testing.assert_array_equal(after[held], poles[held])
        self.assertGreater(np.abs(after - poles).max(), 1e-3)
        self.assertLess(curvature_variation(obj), 0.8 * variation)
        self.assertEqual(obj.Shape.Faces[0].Surface.getPoles()[3][3].z, after[3 * 8 + 3][2])  # shown at once
        self.doc.undo()
        np.testing.assert_array_equal(np.array(obj.Poles).reshape(-1, 3), poles)

    def test_fair_during_a_session_is_taken_at_once_and_committed(self):
        obj = hs.make_sculpt(self.doc, material="clay", mesh=(24, 24), edges="G0")
        stroke(obj)
        held = obj.Proxy.live.snapshot().held_poles
        before = np.array(obj.Proxy.surface.poles).reshape(-1, 3)
        idle = hs.ReplayDevice([0.0, 30.0], [(0.0, 0.0, 60.0)] * 2, buttons=[0, 0])  # no grab: no stroke
        session = hs.Session().start(obj, idle)
        try:
            end = time.monotonic() + 30
            while session.status()["elapsed"] < 0.2:
                self.assertLess(time.monotonic(), end, "the session never ran")
                time.sleep(0.01)
            report = hs.fair(obj)  # (what it moved, known at once though the session commits it later)
            self.assertGreater(report["moved_mm"], 1e-3)
            self.assertNotEqual(report["peak_curvature_after"], report["peak_curvature_before"])
            while not session.applied_edits:
                self.assertLess(time.monotonic(), end, "the fair never applied")
                session.poll()
                time.sleep(0.01)
        finally:
            session.stop()
        self.assertIn("Fair", self.doc.UndoNames)
        after = np.array(obj.Proxy.surface.poles).reshape(-1, 3)
        np.testing.assert_array_equal(after[held], before[held])
        self.assertGreater(np.abs(after - before).max(), 1e-3)

    def test_fair_in_a_region_leaves_the_rest(self):
        obj = hs.make_sculpt(self.doc, material="clay")
        hs.set_uniform(obj, "bending", 0.0)
        stroke(obj)
        mesh = np.array(obj.Proxy.live.snapshot().mesh)
        hs.fair(obj, region=((30.0, 30.0, float(mesh[32, 32, 2])), 15.0))
        moved = np.linalg.norm(np.array(obj.Proxy.live.snapshot().mesh) - mesh, axis=-1)
        self.assertGreater(moved[28:37, 28:37].max(), 10 * moved[:10, :10].max())

    def test_fair_refuses_bad_arguments_before_changing_anything(self):
        obj = hs.make_sculpt(self.doc)
        n = self.doc.UndoCount
        for region, error in ((((0, 0), 5.0), TypeError), (((0, 0, 0), -1.0), ValueError),
                              (((500, 500, 500), 1.0), ValueError), ("here", TypeError)):
            with self.assertRaises(error):
                hs.fair(obj, region=region)
        with self.assertRaises(ValueError):
            hs.fair(obj, strength=-1.0)
        with self.assertRaises(TypeError):
            hs.fair(self.doc)
        self.assertEqual(self.doc.UndoCount, n)

    def test_held_or_free_edges_and_bad_edges(self):
        free = hs.make_sculpt(self.doc)
        self.assertEqual(set(hs.held_boundary(free).values()), {"free"})
        g0 = hs.make_sculpt(self.doc, edges="G0")
        self.assertEqual(set(hs.held_boundary(g0).values()), {"G0"})
        count = len(self.doc.Objects)
        with self.assertRaises(ValueError):
            hs.make_sculpt(self.doc, edges="glued")
        with self.assertRaises(ValueError):
            hs.make_sculpt(self.doc, controls=(3, 3), edges="held")  # no pole left free
        self.assertEqual(len(self.doc.Objects), count)

    def test_bending_weight_and_reference_survive_save_and_reopen(self):
        obj = hs.make_sculpt(self.doc, material="clay")
        hs.set_uniform(obj, "bending", 250.0)
        stroke(obj)
        reference = obj.Proxy.live.snapshot().bending_reference
        name = obj.Name
        path = os.path.join(self.tmp, "fair.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        again = self.doc.getObject(name).Proxy.live.snapshot()
        self.assertEqual(again.bending_map.values[0], 250.0)
        np.testing.assert_array_equal(again.bending_reference, reference)


class TestFairByDefault(DocumentTestCase):
    """Bending is on by default (issue 26): a new sculpt's bending map is FAIR_BENDING, and a rope
    stroke leaves a surface whose written Part.BSplineSurface is fair by its exact derivatives."""

    def test_new_sculpts_bend_by_default(self):
        for kwargs in ({}, {"material": "clay"}, {"edges": "held"}):
            obj = hs.make_sculpt(self.doc, **kwargs)
            np.testing.assert_array_equal(obj.BendingMap, [FAIR_BENDING])
        hs.set_uniform(obj, "bending", 0.0)  # still a map like the others: springs alone
        self.assertEqual(list(obj.BendingMap), [0.0])

    def test_a_stroke_on_a_held_sheet_is_fair_on_the_written_surface(self):
        from HapticSculpt.app import fairness
        obj = hs.make_sculpt(self.doc, material="clay", edges="held")
        stroke(obj)
        face = obj.Shape.Faces[0].Surface
        sections = fairness.central_sections((0.5, 0.5), diagonals=True)
        written = fairness.measure(fairness.part_derivatives(face), sections, flat=1e-5)
        core_surface = obj.Proxy.live.snapshot().surface
        ours = fairness.measure(fairness.core_derivatives(core_surface), sections, flat=1e-5)
        # The document's surface has the core's poles: the same curvature, exactly derived.
        for s in sections[:2]:
            np.testing.assert_allclose(fairness.section_curvature(fairness.part_derivatives(face), s),
                                       fairness.section_curvature(fairness.core_derivatives(core_surface), s),
                                       rtol=1e-7, atol=1e-12)
        self.assertEqual(written.sign_changes, ours.sign_changes)
        self.assertLessEqual(max(c for c, _ in written.per_section), 2, written.per_section)
