"""The continuity check as a designer uses it in FreeCAD's GUI, with real X events: a block whose
top meets its front through a 12 mm round, the top and the round sculpted as one, opened from a
file; Continuity check from the Displays drop-down draws curvature combs across every edge of the
two faces and their seam, coloured by what holds (the seam tangent: yellow; the block's edges,
creases by design: orange), the HUD gives the worst g0, g1 and g2; a mouse stroke in a session
updates them as it goes; zebra stripes cover the faces next to the sculpted ones too; the check off
again. Screenshots build/screenshots/real_continuity_*.png."""
from __future__ import annotations

import os
import time

import numpy as np
import pytest
from freecad_support import run_freecad_gui
from test_gui_real_input import NEEDS, SHOTS, Desktop, sculpt, undo

from HapticSculpt.gui.overlay import CONTINUITY_COLOURS

BLOCK = """
import json, os
import FreeCAD, FreeCADGui, Part
import HapticSculpt as hs
doc = FreeCAD.newDocument("Block")
box = Part.makeBox(100, 80, 30)
edge = next(e for e in box.Edges if abs(e.CenterOfMass.z - 30) < 1e-9 and abs(e.CenterOfMass.y) < 1e-9)
part = doc.addObject("Part::Feature", "Block")
part.Shape = box.makeFillet(12, [edge])
doc.recompute()
faces = part.Shape.Faces
top = next(f"Face{k + 1}" for k, f in enumerate(faces) if isinstance(f.Surface, Part.Plane) and abs(f.CenterOfMass.z - 30) < 1e-9)
rnd = next(f"Face{k + 1}" for k, f in enumerate(faces) if isinstance(f.Surface, Part.Cylinder))
solid = hs.sculpt_solid(doc, part, [top, rnd], controls=(8, 12))
doc.recompute()
doc.saveAs(PATH)
from HapticSculpt.app.sculpted_solid import chain_of_solid
seam = next(iter(chain_of_solid(solid).seam_edges()))
front = next(e for e, k in hs.boundary_of(solid).items() if k == "G1" and e != seam)  # (the round's with the front)
json.dump({"seams": hs.seam_report_of(solid), "seam": seam, "front": front}, open({answer}, "w"))
os._exit(0)
"""


def overlay(s: dict) -> dict:
    return next(o for o in s["overlays"] if o["object"] == sculpt(s)["name"])


def colour_share(picture: np.ndarray, colour: tuple[float, float, float]) -> float:
    return float(np.mean(np.all(np.abs(picture - colour) < 0.12, axis=2)))


@pytest.mark.skipif(not all(NEEDS), reason="needs Xvfb, xdotool, ImageMagick and FreeCAD (make deps installs them)")
def test_continuity_check_on_a_top_and_its_round_sculpted_as_one(tmp_path):
    os.makedirs(SHOTS, exist_ok=True)
    path = str(tmp_path / "block.FCStd")
    made = run_freecad_gui(f"PATH = {path!r}\n" + BLOCK, str(tmp_path))
    seam, front = made["seam"], made["front"]  # (the seam between the two; the round's tangent edge with the front)
    d = Desktop(str(tmp_path), "CAD", open_file=path)
    try:
        s = d.wait(lambda s: s["active"] and s["docs"][s["active"]]["sculpts"], "the file")
        d.xdo("mousemove", "640", "500", "key", "0")  # isometric
        d.xdo("key", "--delay", "150", "v", "f")  # fit all
        before = d.shot("continuity_before")
        s = d.press_button("ContinuityCheck", lambda s: s["overlays"] and overlay(s)["continuity"] and
                           overlay(s)["continuity_worst"].get("edges"), "the continuity check")
        worst = overlay(s)["continuity_worst"]
        assert worst["levels"][seam] == "G1", worst
        assert worst["g0_mm"] <= 1e-7, worst  # the faces meet their neighbours and each other
        assert worst["smooth"] >= 2 and worst["g1_deg"] <= 0.01, worst  # the seam and the round's tangent edge
        assert worst["g2_pct"] > 50, worst  # a plane meets a 12 mm round: the curvature jumps (G1, not G2)
        picture = d.shot_changed("continuity_on", before, "the combs drawn")
        end = time.monotonic() + 10
        while colour_share(picture, CONTINUITY_COLOURS["G1"]) < 2e-4 and time.monotonic() < end:
            picture = d.shot("continuity_on")
        assert colour_share(picture, CONTINUITY_COLOURS["G1"]) >= 2e-4, "no yellow comb (the tangent seam)"
        assert colour_share(picture, CONTINUITY_COLOURS["G0"]) >= 2e-4, "no orange comb (the block's edges)"
        # a stroke with the mouse on the top: the combs follow it during the session
        d.calibrate()
        top = d.to_screen(s["docs"][s["active"]]["screen"]["SculptedSolid"][0])
        d.press_button("Session", lambda s: sculpt(s)["session"], "the session")
        d.xdo("mousemove", str(top[0]), str(top[1]))
        time.sleep(0.3)
        d.xdo("mousedown", "1")
        for k in range(1, 9):
            time.sleep(0.1)
            d.xdo("mousemove", str(top[0]), str(top[1] - 8 * k))
        moving = d.wait(lambda s: overlay(s)["continuity_worst"] != worst, "the check measuring the moved faces")
        d.xdo("mouseup", "1")
        d.wait(lambda s: undo(s)[0] == "Sculpt stroke", "the stroke")
        d.click_button("Session")
        s = d.wait(lambda s: not sculpt(s)["session"], "the session to stop")
        after = overlay(s)["continuity_worst"]
        # the edges held G0 still meet their neighbours, the seam held G1 is still tangent, and so is
        # the round's edge with the front (tangent in the part: held G1 as the part has it)
        assert after["g0_mm"] <= 1e-7 and after["levels"][seam] == "G1" and after["levels"][front] == "G1", after
        assert after != worst, "the stroke changed what the check measures"
        assert moving["overlays"], moving
        stroked = d.shot("continuity_stroked")
        # zebra stripes cover the faces next to the sculpted ones too: the seams with them can be judged
        s = d.press_button("Zebra", lambda s: overlay(s)["neighbours_drawn"] >= 4, "the zebra on the neighbours")
        d.shot_changed("continuity_zebra", stroked, "the zebra stripes", share=0.05, level=0.3)
        s = d.press_button("ContinuityCheck", lambda s: not overlay(s)["continuity"], "the check off")
    finally:
        d.close()
