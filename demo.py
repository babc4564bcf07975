#!/usr/bin/env python3
"""`make demo`: a scripted sculpt session in FreeCAD console mode.

Creates a 100 x 100 mm patch (8x8 bicubic poles, 40x40 mass points) of a plastic material, holds its corners with point
constraints, tilts a normal and fixes a curvature, drags it with a scripted rope stroke, writes the
result back as a Part.BSplineSurface face, saves an .FCStd, exports STEP (read back to check), and
renders a PNG with FreeCAD's own 3D view under Xvfb. Prints a short summary.
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
import textwrap

import numpy as np

ROOT = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, ROOT)
sys.path.append("/usr/lib/freecad-python3/lib")
import FreeCAD  # noqa: E402  (before Part)
import Part  # noqa: E402

import HapticSculpt as hs  # noqa: E402

RENDER = """
import FreeCAD, FreeCADGui as Gui, os
doc = FreeCAD.openDocument({fcstd!r})
Gui.updateGui()
view = Gui.ActiveDocument.ActiveView
obj = doc.getObject("Sculpt")
obj.ViewObject.ShapeColor = (0.35, 0.55, 0.85)
view.viewIsometric()
view.fitAll()
for _ in range(5):
    Gui.updateGui()
view.saveImage({png!r}, 1000, 750, "White")
os._exit(0)
"""

NO_SPLASH_CFG = ('<?xml version="1.0" encoding="UTF-8" standalone="no" ?>\n<FCParameters><FCParamGroup Name="Root">'
                 '<FCParamGroup Name="BaseApp"><FCParamGroup Name="Preferences"><FCParamGroup Name="General">'
                 '<FCBool Name="ShowSplasher" Value="0"/></FCParamGroup></FCParamGroup></FCParamGroup></FCParamGroup>'
                 '</FCParameters>\n')


def render(fcstd: str, png: str) -> str:
    """A picture of the saved document from FreeCAD's 3D view (FreeCAD GUI under Xvfb)."""
    if shutil.which("Xvfb") is None or shutil.which("freecad") is None:
        return "skipped (Xvfb or freecad missing: run `make deps`)"
    script = os.path.join(os.path.dirname(png), "render_script.py")
    with open(script, "w") as f:
        f.write(textwrap.dedent(RENDER.format(fcstd=os.path.abspath(fcstd), png=os.path.abspath(png))))
    home = os.path.join(os.path.dirname(os.path.abspath(png)), ".freecad-home")  # private: this checkout as the addon
    os.makedirs(os.path.join(home, "Mod"), exist_ok=True)
    if not os.path.lexists(os.path.join(home, "Mod", "HapticSculpt")):
        os.symlink(ROOT, os.path.join(home, "Mod", "HapticSculpt"))
    with open(os.path.join(home, "user.cfg"), "w") as f:  # (no splash screen: under Xvfb it costs 3 s)
        f.write(NO_SPLASH_CFG)
    # Xvfb picks a free display itself (-displayfd): several at once, in Debian roots too, never collide.
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", "1", "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    try:
        env = dict(os.environ, DISPLAY=":" + xvfb.stdout.readline().decode().strip(), QTWEBENGINE_DISABLE_SANDBOX="1",
                   FREECAD_USER_HOME=home)
        subprocess.run(["freecad", script], env=env, capture_output=True, timeout=180)
    finally:
        xvfb.kill()
        xvfb.wait()
    os.remove(script)
    if not os.path.isfile(png):
        raise RuntimeError("FreeCAD did not write the picture")
    return png


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default="out", help="folder for the .FCStd, STEP and PNG files")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    doc = FreeCAD.newDocument("HapticSculptDemo")
    obj = hs.make_sculpt(doc, controls=(8, 8), degree=(3, 3), mesh=(40, 40), size=(100.0, 100.0))
    material = obj.Proxy.surface
    material.damping_map.set_uniform(20.0)
    material.set_plasticity(True, yield_strain=0.01, rate=5.0)  # clay-like: the stroke leaves its mark
    corners = [hs.add_constraint(obj, "point", uv=uv) for uv in ((0, 0), (0, 1), (1, 0), (1, 1))]
    normal = hs.add_constraint(obj, "normal", uv=(0.25, 0.75), normal=(0.0, -math.sin(0.25), math.cos(0.25)))
    curvature = hs.add_constraint(obj, "curvature", uv=(0.75, 0.25), curvature=(0.0, 0.0))
    start = np.array(obj.Proxy.surface.mesh[20, 20])
    device = hs.ReplayDevice.stroke(start, start + (15.0, 0.0, 40.0), seconds=1.0, hold=0.5)
    before = np.array(obj.Proxy.surface.mesh)
    report = hs.run(obj, 3.0, device=device, tool="rope")  # 1.5 s stroke, then 1.5 s settling
    s = obj.Proxy.surface
    displacement = np.linalg.norm(np.asarray(s.mesh) - before, axis=2).max()
    doc.recompute()
    fcstd = os.path.join(args.out, "sculpt.FCStd")
    step = os.path.join(args.out, "sculpt.step")
    png = os.path.join(args.out, "sculpt.png")
    doc.saveAs(os.path.abspath(fcstd))
    hs.export_step(obj, step)
    back = Part.read(step).Faces[0].Surface
    poles = np.array([[tuple(p) for p in row] for row in back.getPoles()])
    roundtrip = np.abs(poles - np.asarray(s.poles)).max()
    picture = render(fcstd, png)
    print("HapticSculpt demo")
    print(f"  max displacement            {displacement:.2f} mm")
    print(f"  corner point error (max)    {max(s.constraint_error(c) for c in corners):.3g} mm")
    print(f"  normal error                {math.degrees(s.constraint_error(normal)):.3g} deg")
    print(f"  curvature error (flat)      {s.constraint_error(curvature):.3g} 1/mm")
    print(f"  steps per second            {report.steps_per_second:.0f} ({report.steps} steps, "
          f"{report.refused_steps} refused)")
    print(f"  STEP round trip             {roundtrip:.1e} mm (poles)")
    print(f"  wrote                       {fcstd}, {step}, {picture}")


if __name__ == "__main__":
    main()
