#!/usr/bin/env python3
"""The pull toward a scan (issue 30): what it costs a simulation step against the scan's size, and
how near it draws the surface in how long, against its strength.

The scan: scan_fit.py's (a bump and a ripple over a 200 mm square, 0.05 mm noise, 1 % outliers
5 mm off, a hole). The surface: a flat 16 x 16 patch on a 64 x 64 mesh with every new sculpt's
bending (api.FAIR_BENDING), stepped at 1 ms by the default solver, as a session's simulation
thread steps it. Cost: the median step with the pull on, against the same surface kept awake by
a rope held still (no pull), their steps interleaved. Nearness: the mean and p95 distance of the mesh
from the truth after 0.25, 0.5 and 1 s of simulated time (the designer's hand off).

Prints the tables and writes bench/results/scan_pull.json and scan_pull.png.

    /usr/bin/python3 bench/scan_pull.py [--sizes 10000 100000 1000000 2000000] [--strengths 1 3 10]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.dirname(ROOT))
from scan_fit import SIZE, scan, truth_surface  # noqa: E402

from HapticSculpt import core  # noqa: E402

DT = 1e-3
FAIR_BENDING = 10.0  # (api.FAIR_BENDING: every new sculpt's)


def patch() -> core.DynamicSurface:
    s = core.DynamicSurface(core.BSplineSurface.plane((16, 16), (3, 3), (SIZE, SIZE)), (64, 64))
    s.bending_map.set_uniform(FAIR_BENDING)
    return s


def cost(points: np.ndarray, steps: int = 600) -> dict:
    """Median steps of the pulled surface and of the awake one, interleaved (the machine's load
    falls on both alike)."""
    tree = core.PointTree(points)
    pulled = patch()
    pulled.set_pull_target(tree, 0.1 * pulled.size)
    pulled.set_pull(True, 1.0)
    awake = patch()
    awake.set_tool("rope")
    awake.set_cursor((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), True)  # (held still: awake, nothing pulls)
    times: dict[str, list[float]] = {"pull": [], "awake": []}
    for k in range(steps):
        for name, s in (("pull", pulled), ("awake", awake)):
            t0 = time.perf_counter()
            s.step(DT)
            if k >= steps // 4:  # (after the first sweeps have found the scan)
                times[name].append(time.perf_counter() - t0)
    with_pull, without = (float(np.median(times[k])) * 1e6 for k in ("pull", "awake"))
    return {"points": len(points), "pull_us": with_pull, "awake_us": without, "ratio": with_pull / without}


def nearness(points: np.ndarray, strength: float, truth: core.BSplineSurface) -> dict:
    s = patch()
    s.set_pull_target(core.PointTree(points), 0.1 * s.size)
    s.set_pull(True, strength)
    out = {"strength": strength, "at": []}
    t = 0.0
    for until in (0.0, 0.25, 0.5, 1.0):
        while t < until - 1e-9:
            s.step(DT)
            t += DT
        d = np.abs(truth.project(np.asarray(s.mesh).reshape(-1, 3))["distance"])
        out["at"].append({"t": until, "mean_mm": float(d.mean()), "p95_mm": float(np.percentile(d, 95))})
    return out


def plot(costs: list[dict], near: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    n = [c["points"] for c in costs]
    a.plot(n, [c["pull_us"] for c in costs], "o-", label="pull on")
    a.plot(n, [c["awake_us"] for c in costs], "s--", label="awake, no pull")
    a.set_xscale("log")
    a.set_xlabel("scan points")
    a.set_ylabel("median step (µs), 64×64 mesh")
    a.legend()
    a.grid(alpha=0.3)
    for row in near:
        b.plot([p["t"] for p in row["at"]], [p["mean_mm"] for p in row["at"]], "o-", label=f"strength {row['strength']:g}")
    b.set_yscale("log")
    b.set_xlabel("simulated time (s)")
    b.set_ylabel("mean distance to the truth (mm)")
    b.legend()
    b.grid(alpha=0.3)
    fig.suptitle("The pull toward a scan: cost per step and nearness")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000, 2_000_000])
    ap.add_argument("--strengths", type=float, nargs="+", default=[1.0, 3.0, 10.0])
    args = ap.parse_args()
    truth = truth_surface()
    costs = []
    print(f"{'points':>9} {'pull on (µs)':>13} {'awake (µs)':>11} {'ratio':>6}")
    for n in args.sizes:
        c = cost(scan(truth, n, seed=1))
        costs.append(c)
        print(f"{c['points']:>9} {c['pull_us']:>13.0f} {c['awake_us']:>11.0f} {c['ratio']:>6.2f}")
    points = scan(truth, 100_000, seed=2)
    near = []
    print(f"\n{'strength':>8} " + " ".join(f"{'t=' + str(t) + ' s mean/p95 (mm)':>24}" for t in (0.0, 0.25, 0.5, 1.0)))
    for strength in args.strengths:
        row = nearness(points, strength, truth)
        near.append(row)
        print(f"{strength:>8g} " + " ".join(f"{p['mean_mm']:>12.3f} / {p['p95_mm']:<9.3f}" for p in row["at"]))
    out = os.path.join(ROOT, "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "scan_pull.json"), "w") as f:
        json.dump({"dt": DT, "mesh": [64, 64], "controls": [16, 16], "costs": costs, "nearness": near}, f, indent=1)
    plot(costs, near, os.path.join(out, "scan_pull.png"))
    print("wrote bench/results/scan_pull.json, bench/results/scan_pull.png")


if __name__ == "__main__":
    main()
