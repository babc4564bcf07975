#!/usr/bin/env python3
"""Discretisation error (paper section 4.1, error control): how the mass-spring mesh resolution g x h
changes the sculpted shape, and which resolution to pick for a tolerance.

The scene is time_vs_error.py's equilibrium scene (a 100 mm dome, 8x8 controls, four pinned
corners, a raised point, a tilted normal), solved statically (scipy's minimum of the discrete
energy) at each mesh resolution, so no time-step error enters. For each
resolution:
- shape error: largest distance between the resulting continuous B-spline surface and the one from
  the finest mesh, both evaluated on a 201x201 (u, v) grid, over the patch size;
- chord error: largest distance between the surface and its mesh (cell centres against the
  bilinear cell), what a display or a haptic proxy built on the mesh is off by;
- cost: the default solver's time per step at that resolution (median of blocks).

Writes bench/results/discretisation.json and discretisation.png and prints the smallest mesh that
meets each tolerance.
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.dirname(os.path.abspath(__file__))]
from HapticSculpt import core  # noqa: E402
from progress import progress  # noqa: E402
from time_vs_error import equilibrium_build as scene, static_equilibrium  # noqa: E402

# g - 1 a multiple of 10, so the constraints at u, v = 0.3, 0.4, 0.7 sit on mesh points at every
# resolution (elsewhere they snap to the nearest point, an error of its own: up to half a spacing).
MESHES = [11, 21, 31, 41, 51, 61, 81, 101, 121]
TOLERANCES = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]
EVAL = 201


def equilibrium(s: core.DynamicSurface) -> np.ndarray:
    residual = static_equilibrium(s)
    if residual > 1e-8:
        raise RuntimeError(f"static solve did not converge (gradient left {residual:.1e})")
    return np.array(s.poles)


def dense(s: core.DynamicSurface, poles: np.ndarray, n: int) -> np.ndarray:
    """The continuous surface with these poles sampled on an n x n (u, v) grid."""
    surf = core.BSplineSurface(poles, s.surface.degree, knots_u=s.surface.knots_u, knots_v=s.surface.knots_v)
    return np.array(core.DynamicSurface(surf, (n, n)).mesh)


def chord_error(s: core.DynamicSurface) -> float:
    g = s.mesh.shape[0]
    fine = dense(s, np.array(s.poles), 2 * g - 1)  # cell centres at the odd samples (uniform parameters)
    corners = np.array(s.mesh)
    centres = 0.25 * (corners[:-1, :-1] + corners[1:, :-1] + corners[:-1, 1:] + corners[1:, 1:])
    return float(np.linalg.norm(fine[1::2, 1::2] - centres, axis=-1).max())


def us_per_step(s: core.DynamicSurface) -> float:
    s.sleep_enabled = False
    s.set_cursor(list(np.array(s.mesh[s.mesh.shape[0] // 2, s.mesh.shape[1] // 2]) + [0, 0, 2.0]), grab=True)
    s.step(1e-3, 20)
    n = max(10, int(20000 / s.mesh.shape[0] ** 2))
    times = []
    for _ in range(7):
        t0 = time.perf_counter()
        s.step(1e-3, n)
        times.append((time.perf_counter() - t0) / n * 1e6)
    return float(np.median(times))


def main() -> None:
    out_dir = os.path.join(ROOT, "bench", "results")
    shapes, records = {}, []
    try:
        for m in progress(MESHES, "meshes"):
            s = scene(m)
            poles = equilibrium(s)
            shapes[m] = dense(s, poles, EVAL)
            records.append({"mesh": f"{m}x{m}", "points": m * m, "chord_error": chord_error(s) / s.size,
                            "us_per_step": us_per_step(scene(m)), "size": s.size})
    except KeyboardInterrupt:
        print(f"\ninterrupted after {len(records)} meshes", file=sys.stderr)
    finest = max(shapes)
    for r in records:
        m = int(r["mesh"].split("x")[0])
        r["shape_error"] = float(np.linalg.norm(shapes[m] - shapes[finest], axis=-1).max()) / r["size"]
    # Shape error against the finest mesh is trusted only up to half its spacing (closer meshes
    # share most of its own error); the chord error needs no reference.
    trusted = [r for r in records if 2 * (int(r["mesh"].split("x")[0]) - 1) <= finest - 1]
    recommend = {}
    for tol in TOLERANCES:
        shape_ok = [r["mesh"] for r in trusted if r["shape_error"] <= tol]
        chord_ok = [r["mesh"] for r in records if r["chord_error"] <= tol]
        recommend[f"{tol:g}"] = {"shape": shape_ok[0] if shape_ok else None, "display": chord_ok[0] if chord_ok else None}
    with open(os.path.join(out_dir, "discretisation.json"), "w") as f:
        json.dump({"reference_mesh": f"{finest}x{finest}", "records": records, "recommended_mesh": recommend}, f, indent=1)
    print(f"{'mesh':>8}{'us/step':>10}{'shape err':>12}{'chord err':>12}   (errors / patch size; shape against {finest}x{finest})")
    for r in records:
        print(f"{r['mesh']:>8}{r['us_per_step']:>10.1f}{r['shape_error']:>12.2e}{r['chord_error']:>12.2e}")
    print("smallest mesh for a tolerance (error / size): shape (sculpted result) | display (chord)")
    coarsest_untested = "finer than " + trusted[-1]["mesh"]
    for k, v in recommend.items():
        print(f"  {k:>6}: {v['shape'] or coarsest_untested:>20} | {v['display'] or 'finer than tested'}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    pts = [r["points"] for r in records]
    ax.loglog(pts[:-1], [r["shape_error"] for r in records[:-1]], "o-", label="shape error (vs finest)")
    ax.loglog(pts, [r["chord_error"] for r in records], "s-", label="chord error (mesh vs surface)")
    ax2 = ax.twinx()
    ax2.loglog(pts, [r["us_per_step"] for r in records], "k:", label="us per step")
    ax2.set_ylabel("default solver, us per step")
    ax.set_xlabel("mass points g x h (8x8 controls)")
    ax.set_ylabel("error / patch size")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "discretisation.png"), dpi=110)


if __name__ == "__main__":
    main()
