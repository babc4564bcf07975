"""A tool's lengths (a rope's slack, a brush's radius) are declared for a 100 mm patch and shrink with
a smaller part: the same stroke, scaled with the part, lifts a 10 mm cube's top as far for its size
as a 100 mm box's. (With the patch's 5 mm slack on the cube, the rope stayed slack and the top rose
half as far.)"""
from __future__ import annotations

import math
import os

import FreeCAD
import numpy as np
from freecad_support import DocumentTestCase

import HapticSculpt as hs
from HapticSculpt import core
from HapticSculpt.app import sculpt_state
from HapticSculpt.gui.panel import tool_sliders


def top_of_box(doc, size: float):
    box = doc.addObject("Part::Box", "Box%d" % int(size))
    box.Length = box.Width = box.Height = size
    doc.recompute()
    top = next(i for i, f in enumerate(box.Shape.Faces) if abs(f.CenterOfMass.z - size) < 1e-9)
    solid = hs.sculpt_solid(doc, box, ["Face%d" % (top + 1)])
    doc.recompute()
    return solid


def lift_fraction(doc, solid, size: float) -> float:
    """A rope grabbed at the top's middle and raised by 30 % of the part's size over 0.3 s, then
    let settle 0.5 s: how far the top rose, over the raise."""
    t = np.linspace(0.0, 0.3, 31)
    lift = 0.3 * size
    xyz = [(size / 2, size / 2, size + lift * min(1.0, ti / 0.24)) for ti in t]
    before = solid.Shape.BoundBox.ZMax
    hs.run(solid, 0.3, device=hs.ReplayDevice(t, xyz))
    hs.run(solid, 0.5)
    doc.recompute()
    return (solid.Shape.BoundBox.ZMax - before) / lift


class TestToolScale(DocumentTestCase):
    def test_a_small_parts_tools_are_scaled_to_it(self):
        small = top_of_box(self.doc, 10.0).Sculpts[0]  # (the solid's face sculpt)
        scale = sculpt_state.tool_scale(small.Proxy.live.surface)
        self.assertAlmostEqual(scale, 10.0 * math.sqrt(2.0) / sculpt_state.TOOL_PART_DIAGONAL, delta=1e-3)
        self.assertAlmostEqual(small.Proxy.live.surface.tool.threshold, 5.0 * scale)  # the new sculpt's rope
        hs.set_tool(small, "magnet")
        self.assertAlmostEqual(small.Proxy.live.surface.tool.radius, 10.0 * scale)
        self.assertAlmostEqual(small.Proxy.live.surface.tool.stiffness, 10.0)  # (not a length)
        hs.set_tool(small, "rope", stiffness=20.0)
        self.assertAlmostEqual(small.Proxy.live.surface.tool.threshold, 5.0 * scale)
        # a patch of 100 mm and a larger one keep the declared lengths
        for size in (100.0, 400.0):
            patch = hs.make_sculpt(self.doc, size=(size, size))
            self.assertEqual(patch.Proxy.live.surface.tool.threshold, 5.0)
            hs.set_tool(patch, "flatten")
            self.assertEqual(patch.Proxy.live.surface.tool.radius, 10.0)
        # the slider spans its range about the small part's own default
        (_, _, low, high), = [s for s in tool_sliders("rope", scale) if s[0] == "tool.rope.threshold"]
        self.assertAlmostEqual(math.sqrt(low * high), 5.0 * scale)
        # what a user set is what is saved and read back, scaled or not
        hs.set_tool(small, "smooth", radius=0.7)
        path, name = os.path.join(self.tmp, "small.FCStd"), small.Name
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        reopened = self.doc.getObject(name).Proxy.live.surface.tool
        self.assertEqual((reopened.name, reopened.radius), ("smooth", 0.7))

    def test_a_stroke_lifts_a_small_part_as_far_for_its_size_as_a_large_one(self):
        small, large = (lift_fraction(self.doc, top_of_box(self.doc, s), s) for s in (10.0, 100.0))
        self.assertGreater(large, 0.8)
        self.assertLess(abs(small - large), 0.1 * large, (small, large))

    def test_a_tiny_parts_tool_lengths_stay_positive(self):
        surface = core.patch(size=(1e-4, 1e-4))
        self.assertGreater(sculpt_state.tool_scale(surface), 0.0)  # (floored: a tool length stays > 0)
        sculpt_state.choose_tool(surface, "magnet")
        self.assertGreater(surface.tool.radius, 0.0)
