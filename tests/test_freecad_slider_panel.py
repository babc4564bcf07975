"""The slider panel's values and its fine drag (console mode: the panel reads the mouse in view
pixels, handed to it by the workbench; the real drags are test_gui_panel_hud's, with the release's undo step)."""
from __future__ import annotations

import math

from freecad_support import DocumentTestCase

import HapticSculpt as hs
from HapticSculpt.gui.hud import readable
from HapticSculpt.gui.panel import FINE, SliderPanel, rounded

TRACK = (100.0, 10.0, 320.0, 20.0)  # a 220-pixel track (the HUD's), view pixels


class TestSliderValues(DocumentTestCase):
    def test_values_read_in_plain_decimals(self):
        for value, text in ((2190.0, "2190"), (100.0, "100"), (12.34, "12.3"), (0.0123, "0.0123"),
                            (1e-4, "0.0001"), (3.2e-17, "0"), (-0.5, "-0.5"), (0.1, "0.1"), (0.0, "0"), (1e5, "100000")):
            self.assertEqual(readable(value), text)

    def test_values_are_rounded_to_significant_figures(self):
        self.assertEqual(rounded(2187.76, 2), 2200.0)
        self.assertEqual(rounded(2187.76, 3), 2190.0)
        self.assertEqual(rounded(0.012345, 2), 0.012)
        self.assertEqual(rounded(0.0, 2), 0.0)

    def test_shift_moves_the_knob_a_tenth_as_far(self):
        obj = hs.make_sculpt(self.doc)
        panel = SliderPanel()
        middle = (TRACK[0] + TRACK[2]) / 2
        self.assertTrue(panel.press(middle, 15.0, {"stiffness": TRACK}, obj))
        at_press = panel.pending
        self.assertAlmostEqual(at_press, rounded(math.sqrt(1e5), 2))  # the middle of 1 .. 1e5, log scale
        panel.drag(middle + 60.0)  # 60 pixels: over a decade
        coarse = panel.pending
        self.assertGreater(math.log10(coarse / at_press), 1.0)
        panel.drag(middle, fine=False)
        panel.drag(middle, fine=True)  # Shift down where the knob is: it stays (to 3 figures, not 2)
        self.assertAlmostEqual(panel.pending, at_press, delta=0.02 * at_press)
        panel.drag(middle + 60.0, fine=True)
        fine = panel.pending
        self.assertAlmostEqual(math.log10(fine / at_press), math.log10(coarse / at_press) / FINE, delta=0.01)
        panel.drag(middle + 60.0, fine=False)  # Shift up: the knob goes back under the mouse
        self.assertEqual(panel.pending, coarse)

    def test_a_fine_drag_counts_from_where_the_mouse_was_before_its_first_move(self):
        """Pressed, Shift down, then the mouse's first move with Shift already 60 px on (Qt merges
        moves under load): the knob moves a tenth of 60 px from the press. (It counted from the
        first move it saw, and a fine drag under make test's load stopped 20 px short.)"""
        obj = hs.make_sculpt(self.doc)
        panel, middle = SliderPanel(), (TRACK[0] + TRACK[2]) / 2
        self.assertTrue(panel.press(middle, 15.0, {"stiffness": TRACK}, obj))
        at_press = panel.pending
        panel.drag(middle + 60.0)
        coarse = panel.pending
        self.assertTrue(panel.press(middle, 15.0, {"stiffness": TRACK}, obj))
        panel.drag(middle + 60.0, fine=True)
        self.assertAlmostEqual(math.log10(panel.pending / at_press), math.log10(coarse / at_press) / FINE, delta=0.01)

    def test_a_painted_map_is_scaled_by_its_slider_not_wiped(self):
        """The slider shows a map's mean; its edit of a painted map is scale_map (set_uniform wiped
        the painting)."""
        import numpy as np
        obj = hs.make_sculpt(self.doc)
        hs.paint(obj, "stiffness", [(0.3, 0.5), (0.7, 0.5)])
        painted = np.array(obj.Proxy.live.map_values("stiffness"))
        self.assertGreater(painted.max(), 2 * painted.min())
        undo = self.doc.UndoCount
        hs.scale_map(obj, "stiffness", 4.0)
        self.assertEqual(self.doc.UndoCount, undo + 1)
        self.assertEqual(self.doc.UndoNames[0], "Set stiffness")
        np.testing.assert_allclose(obj.Proxy.live.map_values("stiffness"), 4.0 * painted)
        self.doc.undo()
        np.testing.assert_allclose(obj.Proxy.live.map_values("stiffness"), painted)
        for bad in (0.0, -1.0, float("nan"), float("inf")):
            with self.assertRaises(ValueError):
                hs.scale_map(obj, "stiffness", bad)
        with self.assertRaises(ValueError):
            hs.scale_map(obj, "colour", 2.0)
        self.assertEqual(self.doc.UndoCount, undo)  # (undone; the refused calls left no step)
