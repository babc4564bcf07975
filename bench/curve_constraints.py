#!/usr/bin/env python3
"""Curve constraints (issue 26): what holding a curve costs and how exactly it holds. A flat 100 mm
patch of n x n cubic controls (12, 24, 48) follows a curve through five points across it (the
smooth curve through them, 0.9 of the patch long), G0 then G1; for each: the time to add it (the
least move and the elimination), the links it makes and their masters, the core's wall time per
step of a rope pull beside the curve (median of REPEAT pulls of 600 steps at 1 ms, the default
solver) against the same pull with no curve, and after the pull the largest distance of the
surface from the curve and (G1) of its normal from the one held. One run on this machine: prints
a table, writes bench/results/curve_constraints.json and curve_constraints.png.

    /usr/bin/python3 bench/curve_constraints.py
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT]
from HapticSculpt import core  # noqa: E402
from HapticSculpt.app import curve_constraint as cc  # noqa: E402

REPEAT = 5
CURVE = [(-45.0, -30.0, 0.0), (-20.0, -5.0, 0.0), (0.0, -12.0, 0.0), (20.0, 5.0, 0.0), (45.0, 10.0, 0.0)]


def patch(n: int) -> core.DynamicSurface:
    return core.patch((n, n), mesh=(max(40, 2 * n), max(40, 2 * n)))


def pull_seconds(state, n: int) -> tuple[float, np.ndarray]:
    """Median wall time per step of a rope pull at (10, 30) up 10 mm, and the poles it ends with."""
    from HapticSculpt.app import sculpt_state
    runs = []
    for _ in range(REPEAT):
        s = sculpt_state.restore(state)
        start = np.array(s.mesh).reshape(-1, 3)[s.nearest_mesh_index([10.0, 30.0, 0.0])]
        wall = 0.0
        for k in range(600):
            s.set_cursor(list(start + [0.0, 0.0, min(10.0, 0.03 * k)]), grab=True)
            t0 = time.perf_counter()
            s.step(1e-3)
            wall += time.perf_counter() - t0
        runs.append(wall / 600)
    return float(np.median(runs)), np.asarray(s.poles, float).reshape(-1, 3)


def main() -> None:
    from HapticSculpt.app import sculpt_state
    rows = []
    print(f"curve constraints on a flat 100 mm patch (REPEAT {REPEAT}, rope pull 600 steps at 1 ms)")
    print(f"{'controls':>9}{'curve':>6}{'add ms':>8}{'links':>7}{'masters':>9}{'step us':>9}{'x plain':>8}"
          f"{'dist mm':>10}{'normal deg':>11}")
    for n in (12, 24, 48):
        plain = patch(n)
        base, _ = pull_seconds(sculpt_state.capture(plain), n)
        rows.append({"controls": n, "curve": "none", "step_us": 1e6 * base})
        print(f"{n:>9}{'none':>6}{'':>8}{'':>7}{'':>9}{1e6 * base:>9.0f}{1.0:>8.2f}")
        for continuity in ("G0", "G1"):
            s = patch(n)
            t0 = time.perf_counter()
            record, moved, links = cc.make(s, CURVE, continuity, None, cc.FIRST_ID, [], [])
            add = time.perf_counter() - t0
            s.set_poles(moved.reshape(n, n, 3))
            s.hold_poles([], links)
            step, poles = pull_seconds(sculpt_state.capture(s), n)
            distance, degrees = cc.misses(s.surface, record, poles)
            masters = float(np.mean([len(link[1]) for link in links]))
            rows.append({"controls": n, "curve": continuity, "add_ms": 1e3 * add, "links": len(links),
                         "mean_masters": masters, "step_us": 1e6 * step, "ratio": step / base,
                         "distance_mm": distance, "normal_deg": degrees, "samples": len(record.uv)})
            print(f"{n:>9}{continuity:>6}{1e3 * add:>8.0f}{len(links):>7}{masters:>9.1f}{1e6 * step:>9.0f}"
                  f"{step / base:>8.2f}{distance:>10.1e}{degrees:>11.1e}")
    out = os.path.join(ROOT, "bench", "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "curve_constraints.json"), "w") as f:
        json.dump({"rows": rows, "repeat": REPEAT, "curve": CURVE}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for continuity in ("G0", "G1"):
        got = [r for r in rows if r["curve"] == continuity]
        ax.plot([r["controls"] for r in got], [r["ratio"] for r in got], "o-", label=f"{continuity} curve")
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.set_xlabel("controls per side")
    ax.set_ylabel("step time / no curve")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "curve_constraints.png"), dpi=100)


if __name__ == "__main__":
    main()
