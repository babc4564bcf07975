#!/usr/bin/env python3
"""Instructions per simulation step, counted by callgrind (exact, unlike a clock on a shared
machine): the yardstick for reshaping the core without slowing it (issue 28, item 3: per-step
instructions stay the same). Each scene is a rope pulled up over a flat 100 mm patch (12 x 12
controls, 40 x 40 mesh) for STEPS steps of 1 ms with one integrator (the Verlet scene: steps of
0.25 ms, where local/global's explicit branch is stable, released half way); only what runs inside
DynamicSurface::step is counted (--toggle-collect). Prints a table and writes
bench/results/step_instructions.json; ``--compare FILE`` also prints the ratio to an earlier run.

Valgrind counts each byte of libc's ``rep stosb`` memset (and memcpy's ``rep movsb``) as one
instruction, where the vectorised loop GCC emits instead for the same fill counts one per 32 bytes;
which of the two a zero-fill becomes is up to the inliner. So the table also gives the count
without libc's memset and memcpy ("without fills") beside the bytes they moved.

    /usr/bin/python3 bench/step_instructions.py [--compare bench/results/step_instructions.json]
"""
from __future__ import annotations

import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STEPS = 200
SCENES = {  # name: (integrator, explicit_when_stable, step, steps the rope is held)
    "local_global (default)": ("local_global", True, 1e-3, STEPS),
    "local_global, implicit only": ("local_global", False, 1e-3, STEPS),
    "local_global, Verlet branch": ("local_global", True, 2.5e-4, STEPS // 2),
    "explicit": ("explicit", True, 1e-3, STEPS),
    "implicit (CG)": ("implicit", True, 1e-3, STEPS),
}
SCENE = """
import sys
sys.path.insert(0, {root!r})
from HapticSculpt import core
s = core.patch((12, 12), mesh=(40, 40))
s.integrator = {integrator!r}
s.explicit_when_stable = {verlet!r}
s.sleep_enabled = False
s.bending_map.set_uniform(10.0)
for k in range({steps}):
    s.set_cursor([0.0, 0.0, 0.02 * min(k, {held})], grab=k < {held})
    s.step({dt!r})
"""


def instructions(integrator: str, verlet: bool, dt: float, held: int) -> tuple[int, int]:
    """Instructions executed inside DynamicSurface::step over the scene's steps: all, and those in
    libc's memset and memcpy."""
    with tempfile.TemporaryDirectory() as tmp:
        script = os.path.join(tmp, "scene.py")
        with open(script, "w") as f:
            f.write(SCENE.format(root=ROOT, integrator=integrator, verlet=verlet, steps=STEPS,
                                  dt=dt, held=held))
        out = os.path.join(tmp, "callgrind.out")
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        "--toggle-collect=hs::DynamicSurface::step(double)", sys.executable, script],
                       check=True, capture_output=True)
        total = fills = None
        for line in open(glob.glob(out)[0]):
            if line.startswith(("summary:", "totals:")):
                total = int(line.split()[1])
        listing = subprocess.run(["callgrind_annotate", "--threshold=100", out], check=True,
                                 capture_output=True, text=True).stdout
        fills = sum(int(line.split()[0].replace(",", "")) for line in listing.splitlines()
                    if re.search(r":__(memset|memcpy|memmove)\w*", line) and line.strip()[0].isdigit())
        if total is None:
            raise RuntimeError("callgrind wrote no totals")
        return total, fills


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--compare", help="an earlier run's JSON: print the ratio to it")
    args = ap.parse_args()
    earlier = json.load(open(args.compare)) if args.compare else {}
    before, before_bare = earlier.get("per_step", {}), earlier.get("per_step_without_fills", {})
    rows, bare = {}, {}
    print(f"instructions per step inside DynamicSurface::step ({STEPS} steps, rope pull, 12 x 12 / 40 x 40)")
    print(f"  {'scene':<30}{'all':>12}{'':>9}{'without fills':>16}{'':>9}{'fills':>10}")
    for name, scene in SCENES.items():
        total, fills = instructions(*scene)
        rows[name], bare[name] = total / STEPS, (total - fills) / STEPS
        ratio = f"  x{rows[name] / before[name]:.4f}" if name in before else " " * 9
        ratio_bare = f"  x{bare[name] / before_bare[name]:.4f}" if name in before_bare else " " * 9
        print(f"  {name:<30}{rows[name]:>12,.0f}{ratio}{bare[name]:>16,.0f}{ratio_bare}{fills / STEPS:>10,.0f}")
    if before:
        print("  (xR: ratio to " + os.path.relpath(args.compare) + ")")
    out = os.path.join(ROOT, "bench", "results", "step_instructions.json")
    with open(out, "w") as f:
        json.dump({"steps": STEPS, "per_step": rows, "per_step_without_fills": bare}, f, indent=1)
    print(f"wrote {os.path.relpath(out, ROOT)}")


if __name__ == "__main__":
    main()
