#!/usr/bin/env python3
"""Faces of parts sculpted in place: what a SculptedSolid costs and how exact it is, per part.

For a box top, a cylinder side, a plate top with a hole, a face next to a fillet, that face and
the fillet sculpted as one (a stroke across their seam) and a box top mirrored in its middle plane:
the net the faces get and the share of its poles the edges hold (G1 on every edge), the time to
make the SculptedSolid, to rebuild the sewn solid after a stroke (what every stroke's commit pays)
and to draw a session frame (the compound preview), with the seam errors (G0 gap, G1 angle: 100
points per edge, the seam between two sculpted faces included), the volume change against the
volume the faces displaced, and for the mirrored top how far the result is from its mirror image. Medians of REPEAT runs, one run on this
machine. Prints a table, writes bench/results/solids.json and solids.png.

    /usr/bin/python3 bench/solids.py
"""
from __future__ import annotations

import json
import os
import statistics
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "bench", "results")
for path in (ROOT, "/usr/lib/freecad-python3/lib", os.path.join(ROOT, "tests")):
    if path not in sys.path:
        sys.path.append(path)

import FreeCAD  # noqa: E402
import Part  # noqa: E402

import HapticSculpt as hs  # noqa: E402
from HapticSculpt.app import sculpted_solid  # noqa: E402

REPEAT = 7


def parts() -> list[tuple[str, object, str, tuple[float, float, float], tuple[float, float, float]]]:
    """(name, shape, which face, where to grab, how far to pull)."""
    box = Part.makeBox(40, 30, 10)
    plate = Part.makeBox(40, 30, 10).cut(Part.makeCylinder(5, 20, FreeCAD.Vector(20, 15, -5)))
    edge = next(e for e in box.Edges if abs(e.CenterOfMass.z - 10) < 1e-9 and abs(e.CenterOfMass.y) < 1e-9)
    filleted = box.makeFillet(4, [edge])
    cylinder = Part.makeCylinder(10, 30)

    def top(shape):
        return next(f"Face{k + 1}" for k, f in enumerate(shape.Faces)
                    if isinstance(f.Surface, Part.Plane) and abs(f.CenterOfMass.z - 10) < 1e-9)
    side = next(f"Face{k + 1}" for k, f in enumerate(cylinder.Faces) if isinstance(f.Surface, Part.Cylinder))
    fillet = next(f"Face{k + 1}" for k, f in enumerate(filleted.Faces) if isinstance(f.Surface, Part.Cylinder))
    return [("box top", box, [top(box)], (20, 15, 10), (0, 0, 6), None),
            ("cylinder side", cylinder, [side], (0, 10, 15), (0, 5, 0), None),
            ("plate top, hole", plate, [top(plate)], (8, 8, 10), (0, 0, 5), None),
            ("top by a fillet", filleted, [top(filleted)], (20, 17, 10), (0, 0, -4), None),
            ("top + fillet as one", filleted, [top(filleted), fillet], (20, 4.5, 10), (0, -3, 4), None),
            ("box top, mirrored", box, [top(box)], (30, 12, 10), (0, 0, 6), ((20, 0, 0), (1, 0, 0)))]


def median_ms(fn, n: int = REPEAT) -> float:
    times = []
    for _ in range(n):
        t = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times)


def measure(name, shape, faces, at, by, symmetry) -> dict:
    from test_freecad_sculpted_solid import displaced_volume, mirror_distance  # (the tests' own measures)
    doc = FreeCAD.newDocument("Bench")
    base = doc.addObject("Part::Feature", "Base")
    base.Shape = shape
    doc.recompute()
    made_ms = []
    for k in range(REPEAT):
        t = time.perf_counter()
        obj = hs.sculpt_solid(doc, base, faces, boundary="G1", symmetry=symmetry, name=f"S{k}")
        made_ms.append((time.perf_counter() - t) * 1e3)
    sculpt = obj.Sculpts[0]
    snapshot = sculpt.Proxy.live.snapshot()
    nu, nv = snapshot.surface.controls
    held = len(snapshot.held_poles) / (nu * nv)
    dev = hs.ReplayDevice.stroke(at, tuple(a + b for a, b in zip(at, by)), seconds=0.6, hold=0.7)
    hs.run(obj, 1.5, device=dev, tool="rope")
    state = sculpted_solid.read_state(sculpt)
    rebuild_ms = median_ms(lambda: sculpted_solid.rebuild(obj))
    frame_ms = median_ms(lambda: sculpted_solid.preview(obj, state))
    report = hs.seam_report_of(obj)
    pieces = sculpted_solid.chain_of_solid(obj, shape).split(sculpted_solid.sculpted_surface(sculpt))
    displaced = sum(displaced_volume(shape, f, pieces[f]) for f in faces)
    mirror = None
    if symmetry is not None:
        sym = json.loads(obj.Symmetry)
        mirror = mirror_distance(pieces[faces[0]], sym["point"], sym["normal"], sym["direction"])
    volumes = _adaptive_volumes({"base": shape, "solid": obj.Shape})
    change = volumes["solid"] - volumes["base"]
    FreeCAD.closeDocument(doc.Name)
    return {"part": name, "net": [nu, nv], "held_share": held, "make_ms": statistics.median(made_ms),
            "rebuild_ms": rebuild_ms, "frame_ms": frame_ms,
            "g0_mm": max(r["g0_mm"] for r in report), "g1_deg": max(r["g1_deg"] or 0.0 for r in report),
            "displaced_mm3": displaced, "volume_change_mm3": change, "mirror_mm": mirror,
            "volume_error": abs(change - displaced) / abs(displaced) if displaced else None}


def _adaptive_volumes(shapes: dict) -> dict:
    """Volumes by OCCT's adaptive integration in cadquery's OCP (FreeCAD's Shape.Volume uses a fixed
    Gauss order: 0.9 % off on a cylinder converted to a rational B-spline)."""
    import tempfile

    from freecad_support import run_ocp
    from test_freecad_sculpted_solid import OCP_SOLIDS
    tmp = tempfile.mkdtemp(prefix="hs-bench-")
    paths = {}
    for key, shape in shapes.items():
        paths[key] = os.path.join(tmp, key + ".brep")
        shape.exportBrep(paths[key])
    return {k: v["volume"] for k, v in run_ocp(f"PATHS = {paths!r}\n" + OCP_SOLIDS, tmp).items()}


def main() -> None:
    rows = [measure(*p) for p in parts()]
    print(f"{'part':18s} {'net':>7s} {'held':>6s} {'make ms':>8s} {'rebuild ms':>10s} {'frame ms':>9s} "
          f"{'G0 gap mm':>10s} {'G1 deg':>8s} {'dV vs displaced':>16s} {'mirror mm':>10s}")
    for r in rows:
        err = f"{100 * r['volume_error']:.2f} %" if r["volume_error"] is not None else "-"
        print(f"{r['part']:18s} {r['net'][0]:>3d}x{r['net'][1]:<3d} {100 * r['held_share']:5.0f}% {r['make_ms']:8.1f} "
              f"{r['rebuild_ms']:10.1f} {r['frame_ms']:9.1f} {r['g0_mm']:10.1e} {r['g1_deg']:8.1e} {err:>16s} "
              f"{'-' if r['mirror_mm'] is None else format(r['mirror_mm'], '.1e'):>10s}")
    os.makedirs(RESULTS, exist_ok=True)
    with open(os.path.join(RESULTS, "solids.json"), "w") as f:
        json.dump({"repeat": REPEAT, "freecad": ".".join(FreeCAD.Version()[:3]), "rows": rows}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(11, 4))
    x = range(len(rows))
    for k, (key, label) in enumerate((("make_ms", "make"), ("rebuild_ms", "rebuild (each stroke)"),
                                      ("frame_ms", "session frame"))):
        ax.bar([i + 0.27 * (k - 1) for i in x], [r[key] for r in rows], 0.27, label=label)
    ax.set_xticks(list(x), [f"{r['part']}\nG0 {r['g0_mm']:.0e} mm" for r in rows])
    ax.set_ylabel("ms (median)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(RESULTS, "solids.png"), dpi=100)


if __name__ == "__main__":
    main()
