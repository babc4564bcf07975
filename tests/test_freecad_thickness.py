"""The parametric Thickness (hs.make_thickness): a valid solid of the sculpt's face, one undo step,
recomputed after each stroke (run and threaded session) and when its Thickness is edited, kept
through save and reopen, and refused with a clear error for a thickness that is not > 0."""
from __future__ import annotations

import os
import time

import FreeCAD
import numpy as np
from freecad_support import DocumentTestCase

import HapticSculpt as hs


def pull(obj, lift: float) -> None:
    """Grab the middle of the patch, pull it up by ``lift`` mm, hold, let go (synchronous run)."""
    dev = hs.ReplayDevice.stroke((0.0, 0.0, 0.0), (0.0, 0.0, lift), seconds=1.0, hold=0.5)
    hs.run(obj, 1.5, device=dev, tool="rope")


class TestThickness(DocumentTestCase):
    def setUp(self) -> None:
        super().setUp()
        self.sculpt = hs.make_sculpt(self.doc, size=(60.0, 40.0), mesh=(30, 30), material="clay")
        pull(self.sculpt, 8.0)

    def check(self, feature, thickness: float) -> None:
        shape = feature.Shape
        self.assertEqual(feature.State, ["Up-to-date"])
        self.assertTrue(shape.isValid())
        self.assertEqual(len(shape.Solids), 1)
        expected = hs.thicken(self.sculpt, thickness).Volume  # (the plain offset of the face as it is now)
        self.assertAlmostEqual(shape.Volume, expected, delta=1e-9 * expected)
        area = self.sculpt.Shape.Area
        self.assertLess(abs(shape.Volume - area * thickness) / (area * thickness), 0.15)  # (Steiner: curvature terms)

    def test_one_undo_step_and_edited_thickness(self):
        undo = self.doc.UndoCount
        feature = hs.make_thickness(self.sculpt, 3.0)
        self.assertTrue(hs.app.thickness.is_thickness(feature))
        self.assertEqual(feature.Source, self.sculpt)
        self.assertEqual(feature.Thickness.Value, 3.0)
        self.check(feature, 3.0)
        self.assertEqual(self.doc.UndoNames[: self.doc.UndoCount - undo], ["Thicken"])
        self.doc.openTransaction("Edit thickness")
        feature.Thickness = 1.5
        self.doc.recompute()
        self.doc.commitTransaction()
        self.check(feature, 1.5)
        self.doc.undo()
        self.assertEqual(feature.Thickness.Value, 3.0)
        self.doc.recompute()
        self.check(feature, 3.0)
        name = feature.Name
        self.doc.undo()
        self.assertIsNone(self.doc.getObject(name))

    def test_its_sculpt_deleted_then_undone_leaves_it_to_recompute(self):
        """Deleting the sculpt puts the thickness in error; Undo brings the sculpt back and leaves the
        thickness touched, so the next recompute mends it (the undo's own clean-up cleared its mark:
        it stayed in error, Recompute greyed)."""
        feature = hs.make_thickness(self.sculpt, 2.0)
        name = self.sculpt.Name
        self.doc.openTransaction("Delete")
        self.doc.removeObject(name)
        self.doc.commitTransaction()
        self.doc.recompute()
        self.assertIn("Invalid", feature.State)
        self.doc.undo()
        self.sculpt = self.doc.getObject(name)
        self.assertEqual(feature.Source, self.sculpt)
        self.assertIn("Touched", feature.State)
        self.doc.recompute()
        self.check(feature, 2.0)

    def test_recomputes_after_each_stroke_and_its_undo(self):
        feature = hs.make_thickness(self.sculpt, 2.0)
        before = feature.Shape.Volume
        top = feature.Shape.BoundBox.ZMax
        pull(self.sculpt, 14.0)
        self.check(feature, 2.0)
        self.assertGreater(feature.Shape.BoundBox.ZMax, top + 1.0, "it followed the stroke")
        self.doc.undo()  # the stroke: the thickness goes back with it
        self.assertAlmostEqual(feature.Shape.Volume, before, delta=1e-9 * before)
        self.assertAlmostEqual(feature.Shape.BoundBox.ZMax, top, delta=1e-9)

    def test_a_held_strokes_frames_show_on_it_and_go_at_the_end(self):
        """A GUI session's frames while a stroke is held show on the thickness (the sculpt hides
        behind it: a drag showed only the rope); the frames gone, it is the stored face's again,
        up to date (not touched), with no undo step of its own."""
        from HapticSculpt.app.live_surface import read_state
        feature = hs.make_thickness(self.sculpt, 2.0)
        top, volume, steps = feature.Shape.BoundBox.ZMax, feature.Shape.Volume, self.doc.UndoCount
        base = read_state(self.sculpt)
        raised = np.asarray(self.sculpt.Proxy.surface.poles, float) + np.array([0.0, 0.0, 5.0])
        self.sculpt.Proxy.live.show_poles(raised, base, preview=True)
        self.assertAlmostEqual(feature.Shape.BoundBox.ZMax, top + 5.0, delta=1e-6)
        self.sculpt.Proxy.live.reset_shape()
        self.assertAlmostEqual(feature.Shape.BoundBox.ZMax, top, delta=1e-9)
        self.assertAlmostEqual(feature.Shape.Volume, volume, delta=1e-9 * volume)
        self.assertEqual(feature.State, ["Up-to-date"])
        self.assertEqual(self.doc.UndoCount, steps)

    def test_recomputes_after_each_stroke_of_a_threaded_session(self):
        feature = hs.make_thickness(self.sculpt, 2.0)
        tops = [feature.Shape.BoundBox.ZMax]
        session = hs.Session().start(self.sculpt, hs.ReplayDevice.stroke((0.0, 0.0, 8.0), (0.0, 0.0, 20.0),
                                                                         seconds=0.6, hold=0.3),
                                     stop_when_finished=True)
        end = time.monotonic() + 30.0
        while session.poll() == 0 and time.monotonic() < end:
            time.sleep(0.02)
        self.check(feature, 2.0)
        self.assertGreater(feature.Shape.BoundBox.ZMax, tops[0] + 1.0)
        self.assertTrue(session.wait(timeout=30))

    def test_save_and_reopen(self):
        feature = hs.make_thickness(self.sculpt, 2.5)
        volume = feature.Shape.Volume
        path = os.path.join(self.tmp, "thick.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        again = self.doc.getObject("Thickness")
        self.sculpt = self.doc.getObject("Sculpt")
        self.assertTrue(hs.app.thickness.is_thickness(again))
        self.assertEqual(again.Source, self.sculpt)
        self.assertAlmostEqual(again.Shape.Volume, volume, delta=1e-9 * volume)
        pull(self.sculpt, 14.0)  # it still follows the sculpt
        self.check(again, 2.5)
        self.assertGreater(again.Shape.Volume, 0.0)
        self.assertNotAlmostEqual(again.Shape.Volume, volume, delta=1.0)

    def test_bad_thickness_is_refused_and_adds_nothing(self):
        count, undo = len(self.doc.Objects), self.doc.UndoCount
        for bad, error in ((0.0, ValueError), (-2.0, ValueError), (float("nan"), ValueError),
                           (float("inf"), ValueError), ("2", TypeError)):
            with self.assertRaises(error, msg=bad) as caught:
                hs.make_thickness(self.sculpt, bad)
            self.assertIn("thickness", str(caught.exception))
        with self.assertRaisesRegex(ValueError, "thickness: OCCT|does not give one valid solid"):
            hs.make_thickness(self.sculpt, 1e-8)  # (below OCCT's tolerance: no offset)
        with self.assertRaisesRegex(TypeError, "obj: expected a HapticSculpt Sculpt"):
            hs.make_thickness(self.doc.addObject("Part::Box", "Box"), 2.0)
        self.doc.removeObject("Box")
        self.assertEqual(len(self.doc.Objects), count)
        self.assertEqual(self.doc.UndoCount, undo)
        self.assertTrue(np.isfinite(self.sculpt.Shape.Area))
