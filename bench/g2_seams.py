#!/usr/bin/env python3
"""G2 seams (issue 26): the top of a 100 x 80 x 30 block and the 12 mm round beside it sculpted as
one, their seam held G1 (tangent, as the base meets) against G2 (made curvature-continuous), with
8 and 16 controls along the seam. For each: the time to make the SculptedSolid, the core's wall
time per step under a rope pull (median of REPEAT pulls of 600 steps at 1 ms), the rebuild after a
stroke, the largest move of the surface from the G1 one (the least move that made the seam G2),
and the jump of the normal curvature across the seam at 61 points along it (the surface's own
derivatives): its largest past the end spans of the net (the sides, held G0 and not sculpted,
keep the round at the ends), after the creation and after a stroke, and the report's g2_pct
(the whole seam, ends included). One run on this machine: prints a table, writes
bench/results/g2_seams.json and g2_seams.png (the jump along the seam).

    /usr/bin/python3 bench/g2_seams.py
"""
from __future__ import annotations

import json
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "bench", "results")
for path in (ROOT, "/usr/lib/freecad-python3/lib", os.path.join(ROOT, "tests")):
    if path not in sys.path:
        sys.path.append(path)

import FreeCAD  # noqa: E402
import numpy as np  # noqa: E402
import Part  # noqa: E402
from test_freecad_g2_seams import interior, seam_jumps, seam_knot  # noqa: E402

import HapticSculpt as hs  # noqa: E402
from HapticSculpt.app.face_in_solid import face_edges  # noqa: E402
from HapticSculpt.app.sculpted_solid import rebuild, sculpted_surface  # noqa: E402

REPEAT = 5


def rounded_block(doc):
    box = Part.makeBox(100, 80, 30)
    edge = next(e for e in box.Edges if abs(e.CenterOfMass.z - 30) < 1e-9 and abs(e.CenterOfMass.y) < 1e-9)
    part = doc.addObject("Part::Feature", "Block")
    part.Shape = box.makeFillet(12, [edge])
    doc.recompute()
    faces = part.Shape.Faces
    top = next(f"Face{k + 1}" for k, f in enumerate(faces)
               if isinstance(f.Surface, Part.Plane) and abs(f.CenterOfMass.z - 30) < 1e-9)
    round_ = next(f"Face{k + 1}" for k, f in enumerate(faces) if isinstance(f.Surface, Part.Cylinder))
    seam = next(e.name for e in face_edges(part.Shape, top) if round_ in e.neighbours)
    return part, top, round_, seam


def step_seconds(obj) -> float:
    """The core's wall time per step of a rope pull at the middle of the net (a copy: the sculpt
    is not changed)."""
    from HapticSculpt.app import sculpt_state
    state = sculpt_state.capture(obj.Sculpts[0].Proxy.live.surface)
    runs = []
    for _ in range(REPEAT):
        s = sculpt_state.restore(state)
        mesh = np.array(s.mesh)
        start = mesh[mesh.shape[0] // 2, mesh.shape[1] // 2].copy()
        wall = 0.0
        for k in range(600):
            s.set_cursor(list(start + [0.0, 0.0, min(6.0, 0.02 * k)]), grab=True)
            t0 = time.perf_counter()
            s.step(1e-3)
            wall += time.perf_counter() - t0
        runs.append(wall / 600)
    return float(np.median(runs))


def jumps(obj) -> tuple[np.ndarray, np.ndarray, float]:
    surface = sculpted_surface(obj.Sculpts[0])
    j, vs = seam_jumps(surface, seam_knot(surface))
    inside = interior(surface, vs)
    return j, vs, float(j[inside].max())


def main() -> None:
    doc = FreeCAD.newDocument("g2_seams")
    part, top, round_, seam = rounded_block(doc)
    rows, profiles = [], {}
    print("G2 seams: a 100 x 80 x 30 block's top and its 12 mm round sculpted as one (REPEAT "
          f"{REPEAT}; jump = normal-curvature jump across the seam, % of the larger |curvature|)")
    print(f"{'seam':<6}{'controls':>9}{'make s':>8}{'step us':>9}{'rebuild ms':>11}{'moved mm':>10}"
          f"{'jump in %':>11}{'after stroke %':>15}{'report g2_pct':>14}")
    for along in (8, 16):
        made = {}
        for kind in ("G1", "G2"):
            t0 = time.perf_counter()
            obj = hs.sculpt_solid(doc, part, [top, round_], boundary={seam: kind}, controls=(8, along),
                                  name=f"S{kind}{along}")
            make = time.perf_counter() - t0
            made[kind] = sculpted_surface(obj.Sculpts[0])  # (as made, before its stroke)
            per_step = step_seconds(obj)
            j, vs, inner = jumps(obj)
            profiles[f"{kind} {along}"] = (vs.tolist(), (100 * j).tolist())
            moved = 0.0
            if kind == "G2":
                a, b = made["G1"], made["G2"]
                u0, u1, v0, v1 = a.bounds()
                moved = max((a.value(u, v) - b.value(u, v)).Length
                            for u in np.linspace(u0, u1, 81) for v in np.linspace(v0, v1, 41))
            dev = hs.ReplayDevice.stroke((50.0, 6.0, 29.0), (50.0, 3.0, 34.0), seconds=0.6, hold=0.7)
            hs.run(obj, 1.5, device=dev, tool="rope")
            t0 = time.perf_counter()
            rebuild(obj)
            rebuilt = time.perf_counter() - t0
            _, _, after = jumps(obj)
            report = next(r for r in hs.seam_report_of(obj) if r["edge"] == seam)
            row = {"seam": kind, "controls_along": along, "make_s": make, "step_us": 1e6 * per_step,
                   "rebuild_ms": 1e3 * rebuilt, "moved_mm": moved, "jump_inner_pct": 100 * inner,
                   "jump_inner_after_stroke_pct": 100 * after, "report_g2_pct": report.get("g2_pct"),
                   "report_g1_deg": report["g1_deg"], "report_g0_mm": report["g0_mm"]}
            rows.append(row)
            print(f"{kind:<6}{along:>9}{make:>8.2f}{row['step_us']:>9.0f}{row['rebuild_ms']:>11.1f}{moved:>10.3f}"
                  f"{row['jump_inner_pct']:>11.2g}{row['jump_inner_after_stroke_pct']:>15.2g}"
                  f"{(row['report_g2_pct'] if row['report_g2_pct'] is not None else float('nan')):>14.1f}")
        g1, g2 = (next(r for r in rows if r["seam"] == k and r["controls_along"] == along) for k in ("G1", "G2"))
        print(f"  {along} along: G2 links' step / G1 links' step = {g2['step_us'] / g1['step_us']:.2f}")
    os.makedirs(RESULTS, exist_ok=True)
    with open(os.path.join(RESULTS, "g2_seams.json"), "w") as f:
        json.dump({"rows": rows, "repeat": REPEAT}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4))
    for name, (vs, j) in profiles.items():
        ax.plot(vs, j, label=f"seam {name} controls along it")
    ax.set_xlabel("along the seam (its parameter)")
    ax.set_ylabel("normal-curvature jump across it (%)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(RESULTS, "g2_seams.png"), dpi=100)
    FreeCAD.closeDocument(doc.Name)


if __name__ == "__main__":
    main()
