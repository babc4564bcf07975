#!/usr/bin/env python3
"""Instructions per simulation step, counted by callgrind (exact, unlike a clock on a shared
machine): the yardstick for reshaping the core without slowing it (issue 28, item 3: per-step
instructions stay the same). Each scene is a rope pulled up over a flat 100 mm patch (12 x 12
controls, 40 x 40 mesh) for STEPS steps of 1 ms with one integrator; only what runs inside
DynamicSurface::step is counted (--toggle-collect). Prints a table and writes
bench/results/step_instructions.json; ``--compare FILE`` also prints the ratio to an earlier run.

    /usr/bin/python3 bench/step_instructions.py [--compare bench/results/step_instructions.json]
"""
from __future__ import annotations

import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STEPS = 200
SCENES = {  # name: (integrator, explicit_when_stable)
    "local_global (default)": ("local_global", True),
    "local_global, implicit only": ("local_global", False),
    "explicit": ("explicit", True),
    "implicit (CG)": ("implicit", True),
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
    s.set_cursor([0.0, 0.0, 0.02 * k], grab=True)
    s.step(1e-3)
"""


def instructions(integrator: str, verlet: bool) -> int:
    """Instructions executed inside DynamicSurface::step over the scene's steps."""
    with tempfile.TemporaryDirectory() as tmp:
        script = os.path.join(tmp, "scene.py")
        with open(script, "w") as f:
            f.write(SCENE.format(root=ROOT, integrator=integrator, verlet=verlet, steps=STEPS))
        out = os.path.join(tmp, "callgrind.out")
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        "--toggle-collect=hs::DynamicSurface::step(double)", sys.executable, script],
                       check=True, capture_output=True)
        for line in open(glob.glob(out)[0]):
            if line.startswith(("summary:", "totals:")):
                return int(line.split()[1])
    raise RuntimeError("callgrind wrote no totals")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--compare", help="an earlier run's JSON: print the ratio to it")
    args = ap.parse_args()
    before = json.load(open(args.compare))["per_step"] if args.compare else {}
    rows = {}
    print(f"instructions per step inside DynamicSurface::step ({STEPS} steps, rope pull, 12 x 12 / 40 x 40)")
    for name, (integrator, verlet) in SCENES.items():
        per_step = instructions(integrator, verlet) / STEPS
        rows[name] = per_step
        ratio = f"  x{per_step / before[name]:.4f} of before" if name in before else ""
        print(f"  {name:<30}{per_step:>14,.0f}{ratio}")
    out = os.path.join(ROOT, "bench", "results", "step_instructions.json")
    with open(out, "w") as f:
        json.dump({"steps": STEPS, "per_step": rows}, f, indent=1)
    print(f"wrote {os.path.relpath(out, ROOT)}")


if __name__ == "__main__":
    main()
