#!/usr/bin/env python3
"""Batch replay: one recorded stroke replayed in FreeCAD console mode onto many parts or settings,
each part a task on Dask distributed (campaign.py), each writing its STEP file, its document and a
figure.

The stroke is a cursor trajectory in ReplayDevice's text format (``--trajectory FILE``: what a
session records, or ``HapticSculpt.ReplayDevice.save``); without one, a scripted rope stroke (grab
at the centre, pull 15 mm up over 1 s, hold 0.2 s, let go) is written to OUT/stroke.txt and used.

A part is a dict with a ``name`` and any of: ``controls`` [u, v], ``mesh`` [g, h], ``size`` [w, h]
(mm), ``material`` ("clay" or "elastic"), ``edges`` ("free", "held" or what hs.hold_boundary
takes), ``bending`` (the bending map's ratio), ``source`` {"step": path, "face": "Face1"} (a face
of a STEP file instead of a flat patch). ``--parts FILE.json`` gives a list of them; without it,
eight: both materials, free and held edges, 8 x 8 and 12 x 12 controls.

Each part runs in a FreeCAD console process of its own (one application per part: FreeCAD's
documents are per process), so a part's record does not depend on the worker that ran it or the
order (the stroke is replayed at fixed steps by hs.run); ``--workers 0`` runs them here in order.
Writes OUT/<name>.step, OUT/<name>.FCStd, OUT/<name>.png (height map and middle section) and
OUT/batch_replay.json (per part: its settings, the stroke's steps and refused steps, the lift, the
faces and area of the STEP file read back, the wall time), and prints a table.

    python3 bench/batch_replay.py [--trajectory stroke.txt] [--parts parts.json] [--out build/batch_replay]
                                  [--seconds S] [--workers N | --scheduler tcp://HOST:PORT]
"""
from __future__ import annotations

import argparse
import itertools
import json
import os
import subprocess
import sys
from typing import Any

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.dirname(os.path.abspath(__file__))]
import campaign  # noqa: E402

FREECAD_LIB = "/usr/lib/freecad-python3/lib"
#: What a part may say, and its default (the GUI's New patch: clay, free edges, the fair bending).
PART_KEYS = {"name": None, "controls": [8, 8], "mesh": [40, 40], "size": [100.0, 100.0], "material": "clay",
             "edges": "free", "bending": None, "source": None}


def default_parts() -> list[dict[str, Any]]:
    """Both materials, free and held edges, 8 x 8 and 12 x 12 controls."""
    return [{"name": f"{material}_{edges}_{n}x{n}", "controls": [n, n], "material": material, "edges": edges}
            for material, edges, n in itertools.product(("clay", "elastic"), ("free", "held"), (8, 12))]


def checked_parts(parts: Any) -> list[dict[str, Any]]:
    """The parts with their defaults filled in; ValueError naming what is wrong."""
    if not isinstance(parts, list) or not parts:
        raise ValueError("parts: a non-empty list of parts (dicts with a name)")
    out, names = [], set()
    for i, part in enumerate(parts):
        if not isinstance(part, dict) or not isinstance(part.get("name"), str) or not part["name"]:
            raise ValueError(f"parts[{i}]: a dict with a non-empty 'name'")
        unknown = set(part) - set(PART_KEYS)
        if unknown:
            raise ValueError(f"parts[{i}] ({part['name']}): unknown keys {sorted(unknown)} (known: {sorted(PART_KEYS)})")
        if part["name"] in names or not part["name"].replace("_", "").replace("-", "").isalnum():
            raise ValueError(f"parts[{i}]: name {part['name']!r} must be unique and of letters, digits, - and _")
        names.add(part["name"])
        out.append({**PART_KEYS, **part})
    return out


def replay(task: dict[str, Any]) -> dict[str, Any]:
    """One part (a campaign task): runs it in a FreeCAD console process of its own and returns its
    record; RuntimeError with the process's last words if it fails."""
    done = subprocess.run([sys.executable, os.path.abspath(__file__), "--one", json.dumps(task)],
                          capture_output=True, text=True, timeout=1800)
    lines = done.stdout.strip().splitlines()
    if done.returncode != 0 or not lines:
        raise RuntimeError(f"part {task['part']['name']}: exit {done.returncode}: {done.stderr.strip()[-2000:]}")
    return json.loads(lines[-1])


def figure(face: Any, path: str, title: str) -> None:
    """A height map of the face over its parameter square and its middle section along u."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    u0, u1, v0, v1 = face.ParameterRange
    us, vs = np.linspace(u0, u1, 41), np.linspace(v0, v1, 41)
    surface = face.Surface
    pts = np.array([[tuple(surface.value(u, v)) for v in vs] for u in us])
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.8))
    im = a.imshow(pts[:, :, 2].T, origin="lower", extent=(u0, u1, v0, v1), cmap="viridis", aspect="auto")
    fig.colorbar(im, ax=a, label="z (mm)")
    a.set_xlabel("u")
    a.set_ylabel("v")
    a.set_title("height")
    mid = pts[:, len(vs) // 2]
    b.plot(mid[:, 0], mid[:, 2])
    b.set_xlabel("x (mm)")
    b.set_ylabel("z (mm)")
    b.set_title("section at v = 0.5")
    b.set_aspect("equal", adjustable="datalim")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def run_one(task: dict[str, Any]) -> dict[str, Any]:
    """A part in this process, with FreeCAD: make it, replay the stroke, export, read back, draw."""
    import time
    sys.path.append(FREECAD_LIB)
    import FreeCAD  # noqa: F401  (before Part)
    import Part

    import HapticSculpt as hs
    part, out = task["part"], task["out"]
    t0 = time.perf_counter()
    doc = FreeCAD.newDocument(part["name"])
    source = None
    if part["source"]:
        shape = Part.read(part["source"]["step"])
        source = shape.getElement(part["source"].get("face", "Face1"))
    obj = hs.make_sculpt(doc, source=source, controls=tuple(part["controls"]), mesh=tuple(part["mesh"]),
                         size=tuple(part["size"]), name="Sculpt", material=part["material"], edges=part["edges"])
    if part["bending"] is not None:
        hs.set_uniform(obj, "bending", float(part["bending"]))
    before = obj.Shape.BoundBox
    device = hs.ReplayDevice.load(task["trajectory"])
    seconds = task["seconds"] if task["seconds"] is not None else device.duration + 0.5
    report = hs.run(obj, seconds, device=device)
    after = obj.Shape.BoundBox
    step = os.path.join(out, part["name"] + ".step")
    hs.export_step(obj, step)
    doc.saveAs(os.path.join(out, part["name"] + ".FCStd"))
    back = Part.read(step)
    figure(obj.Shape.Faces[0], os.path.join(out, part["name"] + ".png"), part["name"])
    FreeCAD.closeDocument(doc.Name)
    return {"part": part, "steps": report.steps, "refused": report.refused_steps,
            "lift_mm": round(after.ZMax - before.ZMax, 9), "depth_mm": round(after.ZMax - after.ZMin, 9),
            "step_faces": len(back.Faces), "step_area_mm2": round(back.Area, 6),
            "wall_seconds": time.perf_counter() - t0}


def scripted_stroke(path: str) -> None:
    """The default stroke: grab at the centre, pull 15 mm up over 1 s, hold 0.2 s, let go."""
    from HapticSculpt.runtime.replay_device import ReplayDevice
    ReplayDevice.stroke((0.0, 0.0, 0.0), (0.0, 0.0, 15.0), seconds=1.0, hold=0.2).save(path)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--one", help=argparse.SUPPRESS)  # (a task's own process)
    ap.add_argument("--trajectory", help="the stroke: a ReplayDevice text file (default: a scripted rope pull)")
    ap.add_argument("--parts", help="a JSON file with a list of parts (default: eight, see above)")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "batch_replay"))
    ap.add_argument("--seconds", type=float, default=None, help="simulated seconds (default: the stroke's + 0.5)")
    campaign.add_arguments(ap)
    a = ap.parse_args()
    if a.one:
        print(json.dumps(run_one(json.loads(a.one))))
        return 0
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    if a.parts:
        with open(a.parts, encoding="utf-8") as f:
            parts = checked_parts(json.load(f))
    else:
        parts = checked_parts(default_parts())
    trajectory = os.path.abspath(a.trajectory) if a.trajectory else os.path.join(out, "stroke.txt")
    if not a.trajectory:
        scripted_stroke(trajectory)
    elif not os.path.isfile(trajectory):
        sys.exit(f"--trajectory: no file {trajectory}")
    if a.seconds is not None and not a.seconds > 0:
        sys.exit("--seconds: must be > 0")
    tasks = [{"part": p, "out": out, "trajectory": trajectory, "seconds": a.seconds} for p in parts]
    records = {}
    for task, record in campaign.run(replay, tasks, "parts", a.workers, a.scheduler):
        records[task["part"]["name"]] = record
    ordered = [records[p["name"]] for p in parts]  # (in the order of the parts, whatever order they finished in)
    with open(os.path.join(out, "batch_replay.json"), "w", encoding="utf-8") as f:
        json.dump({"trajectory": trajectory, "ran_on": campaign.describe(a.workers, a.scheduler), "parts": ordered},
                  f, indent=1)
    print(f"{'part':<24}{'steps':>7}{'refused':>9}{'lift (mm)':>11}{'depth (mm)':>12}{'STEP faces':>12}{'wall (s)':>10}")
    for r in ordered:
        print(f"{r['part']['name']:<24}{r['steps']:>7}{r['refused']:>9}{r['lift_mm']:>11.3f}{r['depth_mm']:>12.3f}"
              f"{r['step_faces']:>12}{r['wall_seconds']:>10.1f}")
    print(f"wrote {len(ordered)} parts (STEP, FCStd, PNG) and batch_replay.json to {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
