#!/usr/bin/env python3
"""Paper Table 1: time per simulation step for each integrator, beside the paper's figures.

Prints a table, writes bench/results/table1.json (records: controls, mesh, solver, us_per_step,
paper_ms, plus iterations and the rope-pull displacement error against a converged reference)
and bench/results/table1.png. One core, median of repeated blocks, all measured in one run.
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from HapticSculpt import core  # noqa: E402

# (controls, mesh, paper explicit ms, paper implicit ms)
CONFIGS = [((4, 4), (10, 10), 0.5, 10), ((4, 4), (20, 20), 2, 11), ((4, 4), (40, 40), 10, 19),
           ((8, 8), (20, 20), 5, 100), ((8, 8), (40, 40), 25, 120), ((12, 12), (25, 25), 42, 780),
           ((12, 12), (40, 40), None, None), ((32, 32), (128, 128), None, None)]
# local_global is the default (Verlet where stable, else the implicit step); "bdf2" pins the
# implicit step, to show both in one run
SOLVERS = [("explicit", {}), ("implicit", {"cg_iterations": 5}), ("local_global", {"iterations": 1}),
           ("local_global", {"iterations": 4}), ("local_global", {"iterations": 1, "explicit_when_stable": False})]
DT = 1e-3


def scene(controls, mesh, solver, settings):
    ds = core.patch(controls, (3, 3), mesh, (100.0, 100.0))
    ds.integrator = solver
    for k, v in settings.items():
        setattr(ds, k, v)
    ds.sleep_enabled = False
    ds.tool.reel_time = 0.2
    ds.set_cursor([0.0, 0.0, 2.0], grab=True)
    return ds


def pull(ds, steps):
    """The rope pulls the centre up 20 mm over `steps` steps; returns the mesh afterwards and
    whether local/global took its explicit Verlet branch on the last step."""
    for k in range(steps):
        ds.set_cursor([0.0, 0.0, 2.0 + 20.0 * (k + 1) / steps], grab=True)
        r = ds.step(DT)
        if r.refused:
            raise RuntimeError("refused step")
    return ds.mesh.copy(), r.verlet


def times_per_step(scenes, block=50, repeats=15):
    """Median us per step of each scene, timed round-robin in blocks so that machine noise hits
    all of a configuration's solvers alike."""
    for ds in scenes:
        pull(ds, 20)  # warm-up: factorisations
    z = 22.0
    times = [[] for _ in scenes]
    for _ in range(repeats):
        z += 0.01 * block
        for ds, t in zip(scenes, times):
            t0 = time.perf_counter()
            for k in range(block):
                ds.set_cursor([0.0, 0.0, z + 0.01 * k], grab=True)
                ds.step(DT)
            t.append((time.perf_counter() - t0) / block * 1e6)
    return [float(np.median(t)) for t in times]


def main() -> None:
    os.makedirs(os.path.join(ROOT, "bench", "results"), exist_ok=True)
    records = []
    print(f"{'controls':>9} {'mesh':>9} {'solver':>16} {'us/step':>10} {'paper ms':>9} {'error/size':>11}")
    for controls, mesh, paper_exp, paper_imp in CONFIGS:
        # converged reference of the same pull: local/global's implicit step (BDF2), 10 iterations, a
        # 64x smaller step (about 1e-6 from Verlet at 128x smaller), each cursor sample held for its
        # 1 ms: the core holds the latest cursor over a step, so the input is the same and the error
        # is the integrator's alone
        steps = 100 if mesh[0] <= 40 else 20
        ref = scene(controls, mesh, "local_global", {"iterations": 10, "explicit_when_stable": False})
        for k in range(steps):
            ref.set_cursor([0.0, 0.0, 2.0 + 20.0 * (k + 1) / steps], grab=True)
            ref.step(DT / 64, 64)
        ref_mesh = ref.mesh.copy()
        timings = times_per_step([scene(controls, mesh, solver, settings) for solver, settings in SOLVERS])
        for (solver, settings), us in zip(SOLVERS, timings):
            ds = scene(controls, mesh, solver, settings)
            verlet = False
            try:
                end, verlet = pull(ds, steps)
                err = float(np.abs(end - ref_mesh).max() / ds.size)
            except RuntimeError:
                err = float("inf")
            paper = paper_exp if solver == "explicit" else paper_imp if solver == "implicit" else None
            name = solver + (f"/{settings['iterations']}it" if "iterations" in settings else "")
            if settings.get("explicit_when_stable") is False:
                name += "/bdf2"
            rec = {"controls": f"{controls[0]}x{controls[1]}", "mesh": f"{mesh[0]}x{mesh[1]}", "solver": name,
                   "us_per_step": us, "paper_ms": paper, "error": err, "verlet": verlet}
            records.append(rec)
            print(f"{rec['controls']:>9} {rec['mesh']:>9} {name:>16} {us:10.1f} {str(paper or '-'):>9} {err:11.2e}"
                  f"{'  Verlet steps' if verlet else ''}")
    with open(os.path.join(ROOT, "bench", "results", "table1.json"), "w") as f:
        json.dump(records, f, indent=1)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(9, 5))
        labels = [f"{r['controls']}/{r['mesh']}" for r in records if r["solver"] == "explicit"]
        for name in dict.fromkeys(r["solver"] for r in records):
            ys = [r["us_per_step"] for r in records if r["solver"] == name]
            ax.plot(labels, ys, marker="o", label=name)
        for key, lab in ((3, "paper explicit"), (4, "paper implicit")):
            ys = [c[key - 1] * 1e3 if c[key - 1] else np.nan for c in CONFIGS]
            ax.plot(labels, ys, "k--" if key == 3 else "k:", label=lab)
        ax.set_yscale("log")
        ax.set_ylabel("µs per step")
        ax.set_title("Paper Table 1 configurations: time per step (this machine, one core)")
        ax.legend()
        plt.xticks(rotation=30)
        fig.tight_layout()
        fig.savefig(os.path.join(ROOT, "bench", "results", "table1.png"), dpi=100)
    except ImportError:
        print("matplotlib missing: no plot")


if __name__ == "__main__":
    main()
