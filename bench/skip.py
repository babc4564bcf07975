#!/usr/bin/env python3
"""Pay only for what the scene has: per-step cost of the default solver with and without painted
maps, constraints, non-linear laws and the curvature display, and CPU use of a scene at rest.

Prints a table and writes bench/results/skip.json and skip.png. Features that were added and then
removed again must cost what the plain scene costs (the "removed" rows). Medians of repeated
blocks, all in one run on this machine.
"""
from __future__ import annotations

import json
import os
import resource
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from HapticSculpt import core  # noqa: E402
from HapticSculpt.core import native as _core  # noqa: E402

CONTROLS, MESH, DT, STEPS, BLOCKS = (12, 12), (40, 40), 1e-3, 300, 15


def scene():
    s = core.patch(CONTROLS, (3, 3), MESH)
    s.sleep_enabled = False
    s.set_cursor([0.0, 0.0, 2.0], grab=True)
    for k in range(50):
        s.set_cursor([0.0, 0.0, 2.0 + 0.2 * k], grab=True)
        s.step(DT)
    return s


def paint(s):
    for m, v in ((s.mass_map, 3.0), (s.damping_map, 20.0), (s.stiffness_map, 400.0)):
        m.dab((0.3, 0.3), 0.3, v, "spherical", 0.8)


def constrain(s):
    return [s.add_constraint(k, uv=uv) for k, uv in
            (("point", (0.1, 0.1)), ("normal", (0.8, 0.2)), ("tangent", (0.2, 0.8)), ("curvature", (0.7, 0.7)))]


def nonlinear(s):
    s.set_stiffness_law("cubic", 50.0)
    s.set_damping_law("saturating", 10.0)


VARIANTS = {
    "plain": lambda s: None,
    "painted maps": paint,
    "maps painted then uniform again": lambda s: (paint(s), [m.set_uniform(m.values.mean()) for m in
                                                            (s.mass_map, s.damping_map, s.stiffness_map)]),
    "point, normal, tangent constraints": lambda s: [s.add_constraint(k, uv=uv) for k, uv in
                                                     (("point", (0.1, 0.1)), ("normal", (0.8, 0.2)), ("tangent", (0.2, 0.8)))],
    "4 constraints (curvature: energy guard on)": constrain,
    "constraints added then removed": lambda s: [s.remove_constraint(c) for c in constrain(s)],
    "non-linear laws": nonlinear,
    "laws set back to linear": lambda s: (nonlinear(s), s.set_stiffness_law("linear"), s.set_damping_law("linear")),
    "curvature display at 60 Hz": "curvature",
}


def prepared(setup):
    s = scene()
    if setup != "curvature":
        setup(s)
    s.step(DT, 5)  # refactor outside the timing
    return s


def block(s, curvature):
    """Microseconds per step over one block, and whether the last step was local/global's Verlet."""
    t0 = time.perf_counter()
    if curvature:  # one curvature grid per 1/60 s of simulated time
        for k in range(STEPS):
            r = s.step(DT)
            if k % 17 == 0:
                s.curvature_grid()
    else:
        r = s.step(DT, STEPS)
    return (time.perf_counter() - t0) / STEPS * 1e6, r.verlet


def per_step_all():
    """Round-robin over the variants so machine noise hits them alike; min and median per variant."""
    scenes = {name: prepared(setup) for name, setup in VARIANTS.items()}
    times = {name: [] for name in VARIANTS}
    verlet = {}
    for _ in range(BLOCKS):
        for name, s in scenes.items():
            us, verlet[name] = block(s, VARIANTS[name] == "curvature")
            times[name].append(us)
    return [{"variant": n, "us_per_step": float(np.median(t)), "us_per_step_min": float(np.min(t)),
             "step": "verlet" if verlet[n] else "implicit"} for n, t in times.items()]


def cpu_seconds():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def resting_cpu(seconds=5.0):
    """CPU use of a session whose surface is at rest and whose device does not move (threads on)."""
    s = core.patch(CONTROLS, (3, 3), MESH)
    mouse = _core.ExternalDevice("idle")
    mouse.push([0.0, 0.0, 50.0])
    rt = _core.HapticRuntime(s, mouse)
    rt.start()
    time.sleep(1.0)  # falls asleep
    c0, w0 = cpu_seconds(), time.perf_counter()
    time.sleep(seconds)
    cpu = (cpu_seconds() - c0) / (time.perf_counter() - w0) * 100
    rt.stop()
    sync = core.patch(CONTROLS, (3, 3), MESH)
    sync.step(DT, 200)
    t0 = time.perf_counter()
    report = sync.step(DT, 20000)
    asleep_us = (time.perf_counter() - t0) / 20000 * 1e6
    return cpu, asleep_us, report.slept


def main():
    os.makedirs(os.path.join(ROOT, "bench", "results"), exist_ok=True)
    rows = per_step_all()
    base = rows[0]["us_per_step_min"]
    for r in rows:
        r["ratio_to_plain"] = r["us_per_step_min"] / base
    cpu, asleep_us, slept = resting_cpu()
    print(f"{'scene (12x12 controls, 40x40 mesh, local/global)':<44}{'min us':>9}{'median':>9}{'x plain':>9}"
          f"{'step':>10}")
    for r in rows:
        print(f"{r['variant']:<44}{r['us_per_step_min']:>9.1f}{r['us_per_step']:>9.1f}{r['ratio_to_plain']:>9.2f}"
              f"{r['step']:>10}")
    print(f"resting scene, synchronous step: {asleep_us:.3f} us (slept: {slept})")
    print(f"resting scene, threaded session (1 kHz haptics on): {cpu:.2f} % of one core")
    out = {"controls": CONTROLS, "mesh": MESH, "rows": rows, "resting_step_us": asleep_us,
           "resting_session_cpu_percent": cpu}
    with open(os.path.join(ROOT, "bench", "results", "skip.json"), "w") as f:
        json.dump(out, f, indent=2)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 4))
    ax.barh([r["variant"] for r in rows][::-1], [r["us_per_step_min"] for r in rows][::-1], color="tab:blue")
    ax.set_xlabel("us per step (min of 15 interleaved blocks)")
    ax.set_title(f"Pay for what the scene has (resting session: {cpu:.2f} % CPU)")
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, "bench", "results", "skip.png"), dpi=100)
    print("wrote bench/results/skip.json, bench/results/skip.png")


if __name__ == "__main__":
    main()
