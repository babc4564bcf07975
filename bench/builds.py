#!/usr/bin/env python3
"""What the portable wheel costs: per-step time of the in-tree build (x86-64-v3: AVX2, FMA) against
the wheel (`make wheel`: any x86-64), same scenes, same machine, interleaved in one run.

Prints a table and writes bench/results/builds.json and builds.png. Each block runs in a new
process (the two modules hold the same C++ types, so they cannot share one); the builds alternate
block by block, so the machine's drift hits both alike. Medians of the blocks; the results (poles
after the block) must agree between the builds to 1e-9 relative, or the comparison is void.

    python3 bench/builds.py [WHEEL]     (default: the wheel in build/wheel/dist)
"""
from __future__ import annotations

import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "bench", "results")
PYTHON = "/usr/bin/python3"
SCENES = [("explicit", (12, 12), (40, 40)), ("local_global", (12, 12), (40, 40)), ("implicit", (12, 12), (40, 40)),
          ("local_global", (32, 32), (128, 128))]
STEPS, BLOCKS = 200, 9

#: One block: a rope stroke's pull held on the patch, STEPS steps timed; prints JSON.
BLOCK = r"""
import json, sys, time
sys.path.insert(0, {path!r})
import {module} as m
integrator, controls, mesh, steps = {integrator!r}, {controls!r}, {mesh!r}, {steps!r}
s = m.DynamicSurface(m.BSplineSurface.plane(controls, (3, 3), (100.0, 100.0)), mesh)
s.integrator = integrator
s.sleep_enabled = False
for k in range(30):
    s.set_cursor([0.0, 0.0, 2.0 + 0.3 * k], grab=True)
    s.step(1e-3)
t = time.perf_counter()
for _ in range(steps):
    s.step(1e-3)
us = (time.perf_counter() - t) / steps * 1e6
print(json.dumps({{"us": us, "poles": s.poles.ravel().tolist()}}))
"""


def block(build: dict, scene: tuple) -> dict:
    integrator, controls, mesh = scene
    code = BLOCK.format(path=build["path"], module=build["module"], integrator=integrator, controls=controls,
                        mesh=mesh, steps=STEPS)
    out = subprocess.run([PYTHON, "-c", code], capture_output=True, text=True, check=True,
                         env=dict(os.environ, PYTHONPATH=""))
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str]) -> int:
    wheels = argv[:1] or sorted(glob.glob(os.path.join(ROOT, "build", "wheel", "dist", "*.whl")))
    if not wheels:
        sys.exit("no wheel: run `make wheel` first (or give its path)")
    unpacked = tempfile.mkdtemp(prefix="hs-wheel-")
    zipfile.ZipFile(wheels[-1]).extractall(unpacked)
    builds = [{"name": "in-tree (x86-64-v3)", "path": ROOT, "module": "HapticSculpt._core"},
              {"name": "wheel (x86-64)", "path": unpacked, "module": "hapticsculpt_core"}]
    rows = []
    print(f"{'scene':34s} {'in-tree us/step':>16s} {'wheel us/step':>14s} {'wheel/in-tree':>14s} {'poles agree':>12s}")
    for scene in SCENES:
        times: dict[str, list[float]] = {b["name"]: [] for b in builds}
        poles = {}
        for _ in range(BLOCKS):
            for b in builds:
                r = block(b, scene)
                times[b["name"]].append(r["us"])
                poles[b["name"]] = r["poles"]
        a, w = (statistics.median(times[b["name"]]) for b in builds)
        p0, p1 = (poles[b["name"]] for b in builds)
        scale = max(abs(x) for x in p0)
        agree = max(abs(x - y) for x, y in zip(p0, p1)) / scale
        name = f"{scene[0]} {scene[1][0]}x{scene[1][1]}/{scene[2][0]}x{scene[2][1]}"
        rows.append({"scene": name, "in_tree_us": a, "wheel_us": w, "ratio": w / a, "poles_rel_diff": agree,
                     "blocks": BLOCKS, "steps": STEPS})
        print(f"{name:34s} {a:16.1f} {w:14.1f} {w / a:14.2f} {agree:12.1e}")
        if agree > 1e-9:
            print(f"  the builds disagree on {name}: {agree:.1e} relative")
    os.makedirs(RESULTS, exist_ok=True)
    with open(os.path.join(RESULTS, "builds.json"), "w") as f:
        json.dump({"wheel": os.path.basename(wheels[-1]), "rows": rows}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.2))
    ys = range(len(rows))
    ax.barh([y + 0.2 for y in ys], [r["in_tree_us"] for r in rows], 0.4, label="in-tree (AVX2)")
    ax.barh([y - 0.2 for y in ys], [r["wheel_us"] for r in rows], 0.4, label="wheel (any x86-64)")
    ax.set_yticks(list(ys), [r["scene"] for r in rows])
    ax.set_xscale("log")
    ax.set_xlabel("µs per step (median)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(RESULTS, "builds.png"), dpi=110)
    return 1 if any(r["poles_rel_diff"] > 1e-9 for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
