"""Features built on a SculptedSolid follow a threaded session stroke by stroke: after each stroke's
release the solid is a valid closed solid (not a compound of faces) and a Part Cut with a box and a
PartDesign Body on it (the SculptedSolid as its base feature, a fillet on a bottom edge) have
recomputed without error, in the stroke's own undo step."""
from __future__ import annotations

import sys
import time

import FreeCAD
import numpy as np
import Part
from freecad_support import DocumentTestCase

import HapticSculpt as hs

if "/usr/share/freecad/Mod" not in sys.path:
    sys.path.append("/usr/share/freecad/Mod")  # the PartDesign package, on FreeCAD's own path in freecadcmd


def two_pulls() -> hs.ReplayDevice:
    """Grab the top at (20, 15), pull up 6 mm, let go; grab at (10, 10), pull up 4 mm, let go."""
    t1, xyz1, _, b1 = hs.ReplayDevice.stroke((20.0, 15.0, 10.0), (20.0, 15.0, 16.0), seconds=0.6, hold=0.4).arrays()
    t2, xyz2, _, b2 = hs.ReplayDevice.stroke((10.0, 10.0, 10.0), (10.0, 10.0, 14.0), seconds=0.6, hold=0.4).arrays()
    return hs.ReplayDevice(np.concatenate([t1, t2 + t1[-1] + 0.3]), np.vstack([xyz1, xyz2]),
                           buttons=np.concatenate([b1, b2]))


def up_to_date(obj) -> bool:
    return obj.State == ["Up-to-date"] and obj.Shape.isValid()


class TestFeaturesOnASculptedSolid(DocumentTestCase):
    def setUp(self) -> None:
        super().setUp()
        box = self.doc.addObject("Part::Feature", "Box")
        box.Shape = Part.makeBox(40, 30, 10)
        self.doc.recompute()
        top = next(f"Face{k + 1}" for k, f in enumerate(box.Shape.Faces) if abs(f.CenterOfMass.z - 10) < 1e-9)
        self.solid = hs.sculpt_solid(self.doc, box, [top], controls=(6, 6), mesh=(24, 24))
        tool = self.doc.addObject("Part::Box", "Tool")
        tool.Length, tool.Width, tool.Height = 10, 10, 30
        tool.Placement.Base = FreeCAD.Vector(-5, -5, -5)
        self.cut = self.doc.addObject("Part::Cut", "Cut")
        self.cut.Base, self.cut.Tool = self.solid, tool
        self.body = self.doc.addObject("PartDesign::Body", "Body")
        self.body.BaseFeature = self.solid
        self.doc.recompute()
        bottom = next(f"Edge{k + 1}" for k, e in enumerate(self.solid.Shape.Edges)
                      if abs(e.CenterOfMass.z) < 1e-9 and abs(e.CenterOfMass.y) < 1e-9)
        self.fillet = self.body.newObject("PartDesign::Fillet", "Fillet")
        self.fillet.Base = (self.body.Group[0], [bottom])
        self.fillet.Radius = 2.0
        self.doc.recompute()
        self.assertTrue(up_to_date(self.cut) and up_to_date(self.fillet))

    def check_after_stroke(self, volumes: list[float]) -> None:
        solid = self.solid.Shape
        self.assertEqual(len(solid.Solids), 1, "a solid, not a compound of faces")
        self.assertTrue(solid.isValid() and solid.Solids[0].Shells[0].isClosed())
        self.assertGreater(abs(solid.Volume - volumes[-1]), 1.0, "the stroke changed the solid")
        self.assertGreater(solid.Volume, volumes[0] + 1.0, "the stroke pulled the top up")
        for feature in (self.cut, self.fillet, self.body):
            self.assertTrue(up_to_date(feature), f"{feature.Name}: {feature.State}")
        cut = solid.cut(self.cut.Tool.Shape).Volume  # (of the solid as it is now)
        self.assertAlmostEqual(self.cut.Shape.Volume, cut, delta=1e-6 * cut)
        self.assertLess(self.fillet.Shape.Volume, solid.Volume)  # (the fillet took off its edge's material)
        self.assertGreater(self.fillet.Shape.Volume, solid.Volume - 40 * 4)
        self.assertEqual(self.body.Shape.Volume, self.fillet.Shape.Volume)
        volumes.append(solid.Volume)

    def test_each_stroke_leaves_a_solid_and_its_features_recomputed(self):
        volumes = [self.solid.Shape.Volume]
        fillet = self.fillet.Shape.Volume
        undo = self.doc.UndoCount
        session = hs.Session().start(self.solid.Sculpts[0], two_pulls(), stop_when_finished=True)
        end = time.monotonic() + 60.0
        while len(volumes) < 3 and time.monotonic() < end:
            if session.poll():
                self.check_after_stroke(volumes)
            time.sleep(0.02)
        self.assertEqual(len(volumes), 3, "two strokes committed")
        self.assertTrue(session.wait(timeout=30))
        self.assertEqual(session.status()["error"], "")
        while self.doc.UndoCount > undo:
            self.doc.undo()  # the strokes (and the session's end): the features go back with them
        self.assertEqual(self.solid.Shape.Volume, volumes[0])
        self.assertEqual(self.fillet.Shape.Volume, fillet)
        self.assertAlmostEqual(self.cut.Shape.Volume, volumes[0] - 5 * 5 * 10, delta=1e-6)
