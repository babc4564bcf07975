"""A stroke's change as text (app/recorded_state.py) and HapticSculpt.record_state, which a macro
uses to replay strokes made in a threaded session."""
from __future__ import annotations

import numpy as np
import pytest
from freecad_support import DocumentTestCase

import HapticSculpt as hs
from HapticSculpt import core
from HapticSculpt.app import recorded_state, sculpt_state
from HapticSculpt.app.sculpt_properties import read_state


def pulled(clay: bool) -> tuple[sculpt_state.SculptState, sculpt_state.SculptState]:
    s = core.patch((8, 8), (3, 3), (24, 24))
    if clay:
        s.set_plasticity(True, 0.01, 5.0)
    before = sculpt_state.capture(s)
    s.set_cursor([0.0, 0.0, 0.0], grab=True)
    for k in range(200):
        s.set_cursor([0.0, 0.0, 0.2 * k], grab=True)
        s.step(1e-3)
    s.set_cursor([0.0, 0.0, 40.0], grab=False)
    s.stiffness_map.dab((0.3, 0.3), 0.2, 300.0, "spherical", 0.5)
    return before, sculpt_state.capture(s)


@pytest.mark.parametrize("clay", [False, True])
def test_a_recorded_change_gives_the_state_after_bit_for_bit(clay):
    before, after = pulled(clay)
    text = recorded_state.pack(before, after)
    assert text.isascii() and "\n" not in text
    got = recorded_state.unpack(text, before)
    for name in sculpt_state.ARRAY_NAMES:
        np.testing.assert_array_equal(got.arrays[name], after.arrays[name], err_msg=name)
    assert got.settings_json() == after.settings_json()  # (the painted map's grid size is a setting)
    # Only what changed is recorded: the knots and weights are not, plastic rest lengths sparsely;
    # clay's bending reference follows its plastic flow, so it changed everywhere (5.6 kB more).
    assert len(text) < (40000 if clay else 30000), len(text)
    assert recorded_state.unpack(recorded_state.pack(before, before), before).arrays["Poles"].tobytes() == \
        before.arrays["Poles"].tobytes()


@pytest.mark.parametrize("bad, message", [
    ("not base64 !", "not a recorded sculpt state"),
    ("eJwDAAAAAAE=", "not a recorded sculpt state"),  # zlib of nothing
])
def test_text_that_is_no_recorded_change_is_refused_by_name(bad, message):
    before, _ = pulled(False)
    with pytest.raises(ValueError, match=message):
        recorded_state.unpack(bad, before)


def test_a_change_recorded_on_another_sculpt_does_not_fit():
    before, after = pulled(False)
    other = sculpt_state.capture(core.patch((6, 6), (3, 3), (24, 24)))
    with pytest.raises(ValueError, match="packed"):
        recorded_state.unpack(recorded_state.pack(before, after), other)


class TestRecordState(DocumentTestCase):
    def test_record_state_replays_a_stroke_as_one_undo_step_and_is_a_no_op_on_the_state_it_gives(self):
        obj = hs.make_sculpt(self.doc, controls=(8, 8), mesh=(24, 24), material="clay")
        before = read_state(obj)
        hs.run(obj, 0.3, hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 20.0), seconds=0.2))
        after = read_state(obj)
        text = recorded_state.pack(before, after)
        self.doc.undo()
        strokes = obj.Strokes
        self.assertTrue(hs.record_state(obj, text, "Sculpt stroke"))
        self.assertEqual(self.doc.UndoNames[0], "Sculpt stroke")
        self.assertEqual(obj.Strokes, strokes + 1)
        for name in sculpt_state.ARRAY_NAMES:
            np.testing.assert_array_equal(read_state(obj).arrays[name], after.arrays[name], err_msg=name)
        np.testing.assert_array_equal(np.asarray(obj.Proxy.live.snapshot().poles).ravel(), after.arrays["Poles"])
        undo_count = len(self.doc.UndoNames)
        self.assertFalse(hs.record_state(obj, text, "Sculpt stroke"))  # the state it gives: nothing to do
        self.assertEqual(len(self.doc.UndoNames), undo_count)
        with self.assertRaisesRegex(ValueError, "packed"):
            hs.record_state(obj, "garbage", "Sculpt stroke")
        with self.assertRaisesRegex(ValueError, "strokes"):
            hs.record_state(obj, text, "Sculpt stroke", strokes=-1)
        self.assertEqual(len(self.doc.UndoNames), undo_count)
