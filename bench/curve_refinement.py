#!/usr/bin/env python3
"""What following a curve by refining the net costs (issue 48): the issue's arc (the cubic through
9 points across a 100 mm patch at x = -35, 8 mm high in the middle) on a 10 x 10 clay patch of
80 x 80 mass points, followed G0 within each tolerance (0.01, 0.001, 0.0001 mm) and G1 within
0.001 mm. For each: the time to add it (the refinement passes and the curve held on the finer
net), the net it ends with, the distance FreeCAD's surface keeps from the curve (distToShape at 200
points), and the simulation's wall time per step of a rope pull beside the curve against the
same pull on the 10 x 10 patch with no curve (median of REPEAT pulls of 500 steps at 1 ms, the
default solver). One run on this machine, FreeCAD console mode: prints a table, writes
bench/results/curve_refinement.json and curve_refinement.png.

    PYTHONPATH=/usr/lib/freecad-python3/lib /usr/bin/python3 bench/curve_refinement.py
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, "/usr/lib/freecad-python3/lib"]
import FreeCAD  # noqa: E402
import Part  # noqa: E402

import HapticSculpt as hs  # noqa: E402
from HapticSculpt.app import sculpt_state  # noqa: E402

REPEAT = 3
CASES = [("G0", 0.01), ("G0", 0.001), ("G0", 0.0001), ("G1", 0.001)]


def arc() -> Part.Edge:
    curve = Part.BSplineCurve()
    curve.interpolate([FreeCAD.Vector(-35.0, y, 8.0 * np.cos(np.pi * y / 90.0)) for y in np.linspace(-45, 45, 9)])
    return curve.toShape()


def step_ms(obj) -> float:
    """Median wall milliseconds per step of a rope pull at (-20, 0) up 10 mm (500 steps), on copies
    of the sculpt's stored state (the document is not changed)."""
    runs = []
    for _ in range(REPEAT):
        surface = sculpt_state.restore(obj.Proxy.live.stored())
        start = np.array(surface.mesh).reshape(-1, 3)[surface.nearest_mesh_index([-20.0, 0.0, 5.0])]
        wall = 0.0
        for k in range(500):
            surface.set_cursor(list(start + [0.0, 0.0, min(10.0, 0.025 * k)]), grab=True)
            t0 = time.perf_counter()
            surface.step(1e-3)
            wall += time.perf_counter() - t0
        runs.append(wall / 500)
    return 1e3 * float(np.median(runs))


def distance(face, edge) -> float:
    return max(face.distToShape(Part.Vertex(p))[0] for p in edge.discretize(Number=200))


def main() -> None:
    doc = FreeCAD.newDocument("Bench")
    curve = arc()
    plain = hs.make_sculpt(doc, controls=(10, 10), mesh=(80, 80), name="Plain")
    base_ms = step_ms(plain)
    rows = []
    print(f"following the arc on a 10 x 10 patch (80 x 80 mass points); a pull's step with no curve: {base_ms:.3f} ms")
    print(f"{'curve':>6}{'tolerance mm':>14}{'add s':>8}{'net':>9}{'distance mm':>13}{'step ms':>9}{'ratio':>7}")
    for continuity, tolerance in CASES:
        obj = hs.make_sculpt(doc, controls=(10, 10), mesh=(80, 80), name=f"{continuity}_{tolerance:g}".replace(".", "_"))
        start = time.perf_counter()
        hs.add_curve_constraint(obj, curve, continuity, tolerance=tolerance)
        seconds = time.perf_counter() - start
        net = obj.Proxy.live.last_curve["refined_to"]
        gap = distance(obj.Shape.Faces[0], curve)
        ms = step_ms(obj)
        rows.append({"continuity": continuity, "tolerance_mm": tolerance, "add_s": seconds, "controls": net,
                     "distance_mm": gap, "step_ms": ms, "plain_step_ms": base_ms})
        print(f"{continuity:>6}{tolerance:>14g}{seconds:>8.2f}{f'{net[0]}x{net[1]}':>9}{gap:>13.2e}{ms:>9.3f}"
              f"{ms / base_ms:>7.2f}")
    out = os.path.join(ROOT, "bench", "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "curve_refinement.json"), "w") as f:
        json.dump({"rows": rows, "repeat": REPEAT, "mesh": [80, 80], "plain_step_ms": base_ms}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6))
    g0 = [r for r in rows if r["continuity"] == "G0"]
    a.loglog([r["tolerance_mm"] for r in g0], [r["distance_mm"] for r in g0], "o-", label="distance kept (G0)")
    a.loglog([r["tolerance_mm"] for r in g0], [r["tolerance_mm"] for r in g0], "k:", label="tolerance")
    a.set_xlabel("tolerance asked (mm)")
    a.set_ylabel("mm")
    a.legend(fontsize=8)
    labels = [f"{r['continuity']} {r['tolerance_mm']:g}" for r in rows]
    b.bar(labels, [r["step_ms"] / base_ms for r in rows])
    b.axhline(1.0, color="k", lw=0.8)
    b.set_ylabel("step time / no curve (10 x 10)")
    for k, r in enumerate(rows):
        b.text(k, r["step_ms"] / base_ms, f"{r['controls'][0]}x{r['controls'][1]}\n{r['add_s']:.1f} s", ha="center",
               va="bottom", fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "curve_refinement.png"), dpi=100)
    print("wrote bench/results/curve_refinement.json and curve_refinement.png")


if __name__ == "__main__":
    main()
