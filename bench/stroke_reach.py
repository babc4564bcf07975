#!/usr/bin/env python3
"""How far a local stroke moves a plate (issue 29): the reach that a regional step has to cover to
stay within the default solver's own error, and what a region that holds the far field at rest
costs and misses.

The stroke is scale.py's local one (a rope pulled up 50 mm/s for 0.2 s, held to 0.3 s, let go to
0.4 s) on a flat 400 mm patch sampled m x m (m/4 x m/4 controls), clay (the GUI's material) or
elastic, bending 10, on scenes a designer meets:

- free corner: scale.py's scene (free edges, the rope 15 % in from a corner);
- clamped corner, clamped centre: the two outer rings of poles held (as New clamped patch does).

For each scene, from the whole solve:
- reach: the largest displacement of the mesh points farther than r from the rope's point, at
  0.3 s and 0.4 s, against the solver's own error (the same stroke at dt / 8);
- the radius beyond which nothing moves by more than that own error, and the share of the net's
  poles a square region of that half-side takes (what an exact-at-rest far field needs);
- frozen far field: regional runs that never grow (region_wake 1) with a wider and wider margin:
  their error against the whole solve, their share of the net and their cost per step, in the same
  run as the whole one.

Then the same stroke on coarser nets (64^2, 128^2) against the 256^2 one, on a common 41 x 41
grid of the surfaces: what a coarse stand-in for the far field would be off by (the mass-spring
material is per mesh point, so a coarser net is a different plate; see discretisation.py).

Prints the tables and writes bench/results/stroke_reach.json and stroke_reach.png.

    /usr/bin/python3 bench/stroke_reach.py [--mesh 256] [--materials clay elastic]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from HapticSculpt import core  # noqa: E402
from HapticSculpt.app.api import CLAY, CLAY_DAMPING, FAIR_BENDING  # noqa: E402

DT, PULL, HOLD, END = 1e-3, 0.2, 0.3, 0.4
SIZE = 400.0
RADII = (25.0, 50.0, 100.0, 150.0, 200.0)
MARGINS = (4, 8, 16)
SCENES = {"free corner": (0, (-140.0, -140.0)), "clamped corner": (2, (-140.0, -140.0)),
          "clamped centre": (2, (0.0, 0.0))}


def run(mesh: int, held_rings: int, at: tuple[float, float], material: str, sub: int = 1,
        margin: int | None = None) -> dict:
    """One stroke, whole (margin None) or regional with a region that never grows; its mesh at
    HOLD and END, the start's mesh, the surface on a 41 x 41 grid at HOLD and the median step."""
    n = mesh // 4
    s = core.patch((n, n), mesh=(mesh, mesh), size=(SIZE, SIZE))
    if material == "clay":
        s.set_plasticity(*CLAY)
        s.damping_map.set_uniform(CLAY_DAMPING)
    s.bending_map.set_uniform(FAIR_BENDING)
    if held_rings:
        s.hold_poles([i * n + j for i in range(n) for j in range(n) if min(i, j, n - 1 - i, n - 1 - j) < held_rings])
    if margin is not None:
        s.regional = True
        s.region_wake = 1.0
        s.region_margin = margin
    start = np.array([at[0], at[1], 0.0])
    first = np.asarray(s.mesh).reshape(-1, 3).copy()
    dt = DT / sub
    times, snaps, grid = [], {}, None
    for k in range(int(round(END / dt))):
        t = k * dt
        s.set_cursor(list(start + [0.0, 0.0, 50.0 * min(t, PULL)]), grab=t < HOLD - 1e-12)
        t0 = time.perf_counter()
        s.step(dt)
        times.append(time.perf_counter() - t0)
        for mark in (HOLD, END):
            if abs((k + 1) * dt - mark) < dt / 2:
                snaps[mark] = np.asarray(s.mesh).reshape(-1, 3).copy()
                if mark == HOLD:
                    grid = np.asarray(s.surface.grid(41, 41)[0])
    pull = np.asarray(times[int(0.02 / dt):int(PULL / dt)]) * sub
    region = s.active_region
    share = 1.0 if region["whole"] else ((region["poles"][1] - region["poles"][0]) *
                                         (region["poles"][3] - region["poles"][2]) / (n * n))
    return {"first": first, "snaps": snaps, "grid": grid, "step_us": float(np.median(pull) * 1e6),
            "region": region, "share": share}


def reach(whole: dict, at: tuple[float, float]) -> dict:
    """Largest displacement beyond each radius from the rope's point, at HOLD and END."""
    r = np.linalg.norm(whole["first"][:, :2] - np.asarray(at), axis=1)
    out = {}
    for mark in (HOLD, END):
        moved = np.linalg.norm(whole["snaps"][mark] - whole["first"], axis=1)
        out[str(mark)] = [float(moved[r > radius].max()) if (r > radius).any() else 0.0 for radius in RADII]
    return out


def needed_radius(whole: dict, at: tuple[float, float], tolerance: float) -> float:
    """The smallest radius beyond which no mesh point moved by more than tolerance (at HOLD or END)."""
    r = np.linalg.norm(whole["first"][:, :2] - np.asarray(at), axis=1)
    moved = np.maximum(*(np.linalg.norm(whole["snaps"][m] - whole["first"], axis=1) for m in (HOLD, END)))
    over = r[moved > tolerance]
    return float(over.max()) if over.size else 0.0


def square_share(radius: float, at: tuple[float, float], mesh: int) -> float:
    """Share of the net's poles in the square of half-side radius around at, clipped to the patch."""
    half = SIZE / 2
    side = [min(half, c + radius) - max(-half, c - radius) for c in at]
    return float(min(1.0, max(0.0, side[0]) * max(0.0, side[1]) / SIZE ** 2))


def distance(a: dict, b: dict, mark: float) -> float:
    return float(np.linalg.norm(a["snaps"][mark] - b["snaps"][mark], axis=1).max())


def plot(rows: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for i, r in enumerate(rows):
        colour = f"C{i}"
        ax.semilogy(RADII, np.maximum(r["reach_mm"][str(HOLD)], 1e-4), "o-", color=colour,
                    label=f"{r['scene']}, {r['material']}")
        ax.axhline(r["own_error_mm"], color=colour, ls=":", lw=1)
    ax.set_xlabel("distance from the rope's point (mm)")
    ax.set_ylabel("largest displacement beyond it at 0.3 s (mm)")
    ax.set_title(f"How far a 10 mm rope pull moves a 400 mm plate ({rows[0]['mesh']}² mesh)\n"
                 "dotted: the default solver's own error", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", type=int, default=256)
    ap.add_argument("--materials", nargs="+", choices=("clay", "elastic"), default=["clay", "elastic"])
    args = ap.parse_args()
    mesh = args.mesh
    rows = []
    print(f"{mesh}^2 mesh, {mesh // 4}^2 poles; displacement beyond r (mm) at 0.3 s; own error at 0.3/0.4 s")
    print(f"{'scene':>15} {'material':>8} " + " ".join(f"{'r>' + str(int(x)):>7}" for x in RADII) +
          f" {'own err':>8} {'exact region':>13}")
    for material in args.materials:
        for scene, (rings, at) in SCENES.items():
            whole = run(mesh, rings, at, material)
            fine = run(mesh, rings, at, material, sub=8)
            own = max(distance(whole, fine, HOLD), distance(whole, fine, END))
            radius = needed_radius(whole, at, own)
            row = {"scene": scene, "material": material, "mesh": mesh, "held_rings": rings, "at": list(at),
                   "radii_mm": list(RADII), "reach_mm": reach(whole, at), "own_error_mm": own,
                   "needed_radius_mm": radius, "needed_share": square_share(radius, at, mesh),
                   "whole_us": whole["step_us"], "frozen": []}
            print(f"{scene:>15} {material:>8} " + " ".join(f"{x:>7.3f}" for x in row["reach_mm"][str(HOLD)]) +
                  f" {own:>8.3f} {'r ' + format(radius, '.0f') + ', ' + format(row['needed_share'], '.0%'):>13}", flush=True)
            for margin in MARGINS:
                frozen = run(mesh, rings, at, material, margin=margin)
                row["frozen"].append({"margin": margin, "share": frozen["share"], "step_us": frozen["step_us"],
                                      "error_mm": {str(m): distance(whole, frozen, m) for m in (HOLD, END)}})
            rows.append(row)
    print(f"\nfar field held at rest (a region that never grows): error against the whole solve, cost "
          f"against the whole step (same run)")
    print(f"{'scene':>15} {'material':>8} {'margin':>6} {'share':>6} {'err 0.3/0.4 s':>14} {'own err':>8} "
          f"{'step us':>8} {'whole us':>9}")
    for row in rows:
        for f in row["frozen"]:
            print(f"{row['scene']:>15} {row['material']:>8} {f['margin']:>6} {f['share']:>6.0%} "
                  f"{f['error_mm'][str(HOLD)]:>6.3f}/{f['error_mm'][str(END)]:<7.3f} {row['own_error_mm']:>8.3f} "
                  f"{f['step_us']:>8.0f} {row['whole_us']:>9.0f}")
    print(f"\na coarser net as the far field's stand-in: the same stroke (clamped centre, clay), surfaces "
          f"against the {mesh}^2 one at 0.3 s on a 41 x 41 grid")
    rings, at = SCENES["clamped centre"]
    fine = run(mesh, rings, at, "clay")
    centre = np.linalg.norm(fine["grid"][:, :, :2] - np.asarray(at), axis=2)
    coarse = []
    for m in (64, 128):
        if m >= mesh:
            continue
        other = run(m, rings, at, "clay")
        gap = np.linalg.norm(other["grid"] - fine["grid"], axis=2)
        coarse.append({"mesh": m, "max_mm": float(gap.max()), "beyond_100_mm": float(gap[centre > 100].max()),
                       "step_us": other["step_us"]})
        print(f"  {m}^2: largest gap {gap.max():.2f} mm, beyond 100 mm {gap[centre > 100].max():.2f} mm "
              f"({other['step_us']:.0f} us a step)")
    out = os.path.join(ROOT, "bench", "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "stroke_reach.json"), "w") as f:
        json.dump({"dt": DT, "mesh": mesh, "rows": rows, "coarse_stand_in": coarse}, f, indent=1)
    plot(rows, os.path.join(out, "stroke_reach.png"))


if __name__ == "__main__":
    main()
