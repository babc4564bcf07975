#!/usr/bin/env python3
"""Cost against mesh size, regional steps against whole ones (issue 29): per-step time and error
of the default solver on a flat 400 mm patch sampled m x m (m/4 x m/4 controls), for

- a local stroke: a rope grabbed 15 % in from a corner, pulled up 50 mm/s for 0.2 s, held to
  0.3 s and let go to 0.4 s;
- a global stroke: a magnet of radius 300 mm at the centre, the same motion.

"regional; end" is the share of the steps that were regional and the region at the end (pole
index ranges, or whole). Each stroke runs whole and regional (``s.regional = True``, region_wake 1e-2) in the same run. The
error of the regional run is its largest mesh distance from the whole run at 0.3 s and 0.4 s, and
its reaction force's p99 difference during the pull and hold, as a fraction of the stroke's
largest force (full scale, as haptic devices state theirs); beside it, the whole run's own error
against the same stroke at dt / 8 (the default step's error against a converged one). Times are
medians over the pull (a step after a region change included, the first 20 steps not).

A third table runs a region that never grows (region_wake 1: the far field frozen, not an
accurate setting) on nets up to 512 x 512: what the regional machinery itself costs against the
net's size, with the first step (which builds the whole system matrix) and peak memory.

Prints the tables and writes bench/results/scale.json and scale.png.

    /usr/bin/python3 bench/scale.py [--sizes 32 64 128 256] [--big]   (--big adds 512 x 512)
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from HapticSculpt import core  # noqa: E402
from HapticSculpt.app.api import CLAY, CLAY_DAMPING, FAIR_BENDING  # noqa: E402

DT, PULL, HOLD, END, WAKE = 1e-3, 0.2, 0.3, 0.4, 1e-2
SWEEP = (1e-2, 3e-2, 1e-1, 3e-1)


def stroke(mesh: int, kind: str, regional: bool, sub: int = 1, material: str = "clay", wake: float = WAKE) -> dict:
    """One stroke on an m x m patch; its per-step times, mesh at HOLD and END, and reactions."""
    setup_start = time.perf_counter()
    s = core.patch((mesh // 4, mesh // 4), mesh=(mesh, mesh), size=(400.0, 400.0))
    if material == "clay":  # the GUI's default material (HapticSculpt.app.api)
        s.set_plasticity(*CLAY)
        s.damping_map.set_uniform(CLAY_DAMPING)
    s.bending_map.set_uniform(FAIR_BENDING)
    s.regional = regional
    s.region_wake = wake
    if kind == "global":
        s.set_tool("magnet")
        s.tool.radius = 300.0
        start = np.array([0.0, 0.0, 0.0])
    else:
        start = np.array([-140.0, -140.0, 0.0])
    setup = time.perf_counter() - setup_start
    dt = DT / sub
    steps = int(round(END / dt))
    times, forces, snaps = [], [], {}
    regional_steps = 0
    for k in range(steps):
        t = k * dt
        s.set_cursor(list(start + [0.0, 0.0, 50.0 * min(t, PULL)]), grab=t < HOLD - 1e-12)
        t0 = time.perf_counter()
        report = s.step(dt)
        times.append(time.perf_counter() - t0)
        regional_steps += not s.active_region["whole"]
        if t < HOLD - 1e-12:
            forces.append(np.asarray(report.force, dtype=float))
        for mark in (HOLD, END):
            if abs((k + 1) * dt - mark) < dt / 2:
                snaps[mark] = np.asarray(s.mesh).reshape(-1, 3).copy()
    pull = np.asarray(times[int(0.02 / dt):int(PULL / dt)]) * sub
    return {"step_us": float(np.median(pull) * 1e6), "max_step_us": float(pull.max() * 1e6),
            "snaps": snaps, "forces": np.asarray(forces), "region": s.active_region,
            "regional_fraction": regional_steps / steps, "first_step_ms": times[0] * sub * 1e3, "setup_s": setup,
            "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def measure(mesh: int, kind: str, material: str, reference: bool) -> dict:
    whole = stroke(mesh, kind, False, material=material)
    regional = stroke(mesh, kind, True, material=material)
    row = {"mesh": mesh, "controls": mesh // 4, "stroke": kind, "material": material,
           "whole_us": whole["step_us"], "regional_us": regional["step_us"],
           "regional_max_us": regional["max_step_us"],
           "region_poles": list(regional["region"]["poles"]), "region_whole": regional["region"]["whole"],
           "region_changes": regional["region"]["changes"], "regional_fraction": regional["regional_fraction"],
           "rss_mb": regional["rss_mb"]}
    lift = max(float(np.abs(whole["snaps"][HOLD][:, 2]).max()), 1e-9)
    row["lift_mm"] = lift
    row["regional_error_mm"] = {str(t): float(np.abs(whole["snaps"][t] - regional["snaps"][t]).max())
                                for t in (HOLD, END)}
    fw, fr = whole["forces"], regional["forces"]
    full_scale = max(float(np.linalg.norm(fw, axis=1).max()), 1e-12)
    row["force_error_p99"] = float(np.percentile(np.linalg.norm(fw - fr, axis=1) / full_scale, 99))
    if reference:
        fine = stroke(mesh, kind, False, sub=8, material=material)
        row["own_error_mm"] = {str(t): float(np.abs(whole["snaps"][t] - fine["snaps"][t]).max()) for t in (HOLD, END)}
    return row


def sweep(mesh: int, material: str) -> list[dict]:
    """Time against error over region_wake for the local stroke on the largest mesh: the trade the
    setting makes (the whole run and its own error from measure()'s row)."""
    whole = stroke(mesh, "local", False, material=material)
    out = []
    for wake in SWEEP:
        r = stroke(mesh, "local", True, material=material, wake=wake)
        full_scale = max(float(np.linalg.norm(whole["forces"], axis=1).max()), 1e-12)
        out.append({"mesh": mesh, "material": material, "wake": wake, "whole_us": whole["step_us"],
                    "regional_us": r["step_us"], "regional_fraction": r["regional_fraction"],
                    "error_mm": {str(t): float(np.abs(whole["snaps"][t] - r["snaps"][t]).max()) for t in (HOLD, END)},
                    "force_error_p99": float(np.percentile(
                        np.linalg.norm(whole["forces"] - r["forces"], axis=1) / full_scale, 99))})
    return out


def machinery(mesh: int) -> dict:
    """The regional step's own scaling: a region that never grows (region_wake 1: the rope's reach
    and the margin only, the far field frozen), clay, on nets up to 512 x 512: per-step cost,
    the first step (it builds the whole system matrix), the net's set-up and the process's peak
    memory (each size in a process of its own, so the peak is that size's)."""
    import subprocess
    code = f"""
import json, resource, sys, time
sys.path.insert(0, {os.path.join(ROOT, "bench")!r})
import scale
t0 = time.perf_counter()
r = scale.stroke({mesh}, "local", True, wake=1.0, material="clay")
print(json.dumps({{"mesh": {mesh}, "step_us": r["step_us"], "first_step_ms": r["first_step_ms"],
                  "setup_s": r["setup_s"], "region": r["region"],
                  "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}}))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def plot(rows: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4))
    colours = {"clay": ("tab:gray", "tab:blue"), "elastic": ("tab:brown", "tab:orange")}
    for material in colours:
        for kind, style in (("local", "-"), ("global", "--")):
            sel = [r for r in rows if r["stroke"] == kind and r["material"] == material]
            if not sel:
                continue
            m = [r["mesh"] for r in sel]
            ax.loglog(m, [r["whole_us"] for r in sel], "o" + style, color=colours[material][0],
                      label=f"{material} {kind}, whole")
            ax.loglog(m, [r["regional_us"] for r in sel], "s" + style, color=colours[material][1],
                      label=f"{material} {kind}, regional")
    ax.set_xlabel("mesh side m (m x m points, m/4 x m/4 controls)")
    ax.set_ylabel("median time per 1 ms step (us)")
    ax.set_title("Cost against size: regional steps against whole ones")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[32, 64, 128, 256])
    ap.add_argument("--big", action="store_true", help="add 512 x 512 to the whole-against-regional table "
                    "(the fixed-region table always has it)")
    ap.add_argument("--materials", nargs="+", choices=("clay", "elastic"), default=["clay", "elastic"],
                    help="clay (the GUI's default: plastic, damping 10), elastic (damping 1); bending 10 both")
    ap.add_argument("--no-reference", action="store_true", help="skip the dt/8 runs (the solver's own error)")
    args = ap.parse_args()
    sizes = args.sizes + ([512] if args.big else [])
    rows = []
    print(f"{'material':>8} {'mesh':>5} {'stroke':>7} {'whole us':>9} {'regional us':>12} {'max us':>8} {'regional; end':>18} "
          f"{'err 0.3 s':>9} {'err 0.4 s':>9} {'own err 0.3/0.4 s':>18} {'force p99':>9}")
    for material in args.materials:
        for mesh in sizes:
            for kind in ("local", "global"):
                r = measure(mesh, kind, material, reference=not args.no_reference and mesh <= 256)
                rows.append(r)
                own = r.get("own_error_mm")
                own_text = f"{own[str(HOLD)]:.3g}/{own[str(END)]:.3g}" if own else "-"
                region = f"{r['regional_fraction']:.0%} " + ("whole" if r["region_whole"] else
                                                              "{}..{}x{}..{}".format(*r["region_poles"]))
                print(f"{material:>8} {mesh:>5} {kind:>7} {r['whole_us']:>9.0f} {r['regional_us']:>12.0f} "
                      f"{r['regional_max_us']:>8.0f} {region:>18} {r['regional_error_mm'][str(HOLD)]:>9.3g} "
                      f"{r['regional_error_mm'][str(END)]:>9.3g} {own_text:>18} {r['force_error_p99']:>9.2%}", flush=True)
    for material in args.materials:
        local = {r["mesh"]: r for r in rows if r["stroke"] == "local" and r["material"] == material}
        if 64 in local and 256 in local:
            print(f"{material}, local stroke: regional 256 / whole 64 {local[256]['regional_us'] / local[64]['whole_us']:.2f}x,"
                  f" whole 256 / whole 64 {local[256]['whole_us'] / local[64]['whole_us']:.1f}x")
    largest = max(args.sizes)
    print(f"\nlocal stroke on {largest} x {largest}, region_wake swept (error: against the whole run):")
    print(f"{'material':>8} {'wake':>6} {'whole us':>9} {'regional us':>12} {'regional':>9} {'err 0.3 s':>9} "
          f"{'err 0.4 s':>9} {'force p99':>9}")
    swept = []
    for material in args.materials:
        for r in sweep(largest, material):
            swept.append(r)
            print(f"{material:>8} {r['wake']:>6g} {r['whole_us']:>9.0f} {r['regional_us']:>12.0f} "
                  f"{r['regional_fraction']:>9.0%} {r['error_mm'][str(HOLD)]:>9.3g} {r['error_mm'][str(END)]:>9.3g} "
                  f"{r['force_error_p99']:>9.2%}", flush=True)
    print("\nthe regional step's own scaling: a region that never grows (region_wake 1), clay:")
    print(f"{'mesh':>5} {'region (poles)':>16} {'step us':>8} {'first step ms':>14} {'set-up s':>9} {'peak MB':>8}")
    fixed = []
    for mesh in sorted(set(args.sizes + [512])):
        if mesh < 64:
            continue
        r = machinery(mesh)
        fixed.append(r)
        print(f"{mesh:>5} {'{}..{}x{}..{}'.format(*r['region']['poles']):>16} {r['step_us']:>8.0f} "
              f"{r['first_step_ms']:>14.0f} {r['setup_s']:>9.2f} {r['rss_mb']:>8.0f}", flush=True)
    out = os.path.join(ROOT, "bench", "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "scale.json"), "w") as f:
        json.dump({"dt": DT, "wake": WAKE, "rows": rows, "sweep": swept, "fixed_region": fixed}, f, indent=1)
    plot(rows, os.path.join(out, "scale.png"))


if __name__ == "__main__":
    main()
