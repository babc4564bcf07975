#!/usr/bin/env python3
"""Run time against error: every integrator over a range of time steps and iteration counts on three
reference scenes, error against a converged reference, and the Pareto front of each solver.

Scenes (8x8 controls, 24x24 mesh, a 100 mm dome-shaped patch relaxed as its rest shape, stiffness
1e4, mass 1 per unit area; the same for every solver):
- rope: the rope grabs the centre, the cursor rises 15 mm in 0.15 s (updated every 1 ms of
  simulated time), lets go, and the patch swings free until 0.3 s; damping 2.
- equilibrium: four pinned corners, a point constraint raised 5 mm and a normal tilted 10 degrees
  settle for 1.5 s; damping 40. Reference: the static minimum of the same discrete energy, by scipy
  (Newton-CG on the core's potential energy and its gradient, exact for springs, point and normal
  constraints: tests/test_core_dynamics.py). The curvature constraint is left out: its arc targets keep the
  current half-chord, so its force is not the gradient of a fixed energy and there is no energy
  to minimise (its accuracy at equilibrium is tested in tests/test_core_dynamics.py).
- oscillation: a pole pushed 3 mm and let go, undamped, 0.2 s.
- two_faces: the rope scene on two faces sculpted as one (as hs.sculpt_solid joins them): the same
  dome as two patches joined along u = 0.5 by a knot of full multiplicity, the seam's poles linked
  to their neighbours across it so it stays tangent (G1; the core's linked poles), grabbed beside
  the seam. The coupling must not cost the default its lead.
- two_faces_g2: the same with the seam curvature-continuous (G2: two linked poles per column, the
  seam's and the one two rows past it, from seam_continuity).
- curve: the rope scene on the dome following a curve G0 (a line of it across it at v = 0.35:
  linked poles with offsets from curve_constraint), grabbed at the centre beside it.
Rope and oscillation references: the explicit scheme at 1 ms / 1024 and 1 ms / 2048, Richardson-
extrapolated (first order); their difference says how good the reference is (printed).

Error: largest mesh-point distance to the reference at the end, over the patch size (also at the
release for the rope). Time: wall seconds per simulated second, median of repeats for short runs.

Solvers: explicit (the paper's eq. 8-9 with adaptive halving), implicit (the paper's linearised
backward Euler, 5 or 20 CG iterations), local_global (the default: an explicit velocity Verlet step
where it is provably stable for the step, else BDF2 by 1-8 local/global iterations), and for
comparison its parts: local_global_bdf2 (the implicit step alone) and local_global_be (backward
Euler alone).

Writes bench/results/time_vs_error.json (records: scene, solver, dt, iterations,
seconds_per_sim_second, error) and time_vs_error.png, prints each solver's fastest run at each error
level 1e-2 .. 1e-6 and the default's speed-up over the paper's schemes. Finished runs are kept if
interrupted (Ctrl-C writes what is done). ``--scenes rope,two_faces`` runs only those scenes and
replaces their records in the JSON (every scene's solvers are compared within one run).

The references and the runs are tasks on Dask distributed (campaign.py: a local cluster over all
cores by default, ``--workers N``, ``--scheduler tcp://HOST:PORT``; ``--workers 0`` runs them here in
order). The errors do not depend on where a run ran; the times do: runs side by side share the
machine's memory bandwidth, so compare times within one run (``--workers 1`` for the quietest).

``--fairness`` runs only the fair-stroke measure (issue 26): curvature sign changes and total
variation along sections of a rope stroke (exact derivatives), free and pinned, clay and elastic,
today's springs alone beside the default bending, and the per-step time of each integrator on each
scene, today's and new, with the default's lead in both (bench/results/fairness.json; see
fairness_table).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np
from scipy import optimize

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.dirname(os.path.abspath(__file__)), os.path.join(ROOT, "tests")]
from HapticSculpt import core  # noqa: E402
import campaign  # noqa: E402

MS = 1e-3
DTS = [MS * 2.0 ** -k for k in range(0, 11)] + [2 * MS, 4 * MS, 8 * MS]  # 8 ms .. 0.98 us
LEVELS = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
SIZE = 100.0 * math.sqrt(2)  # errors are over the patch's diagonal
# (solver, integrator, settings): solver names the integrator family the Pareto fronts compare;
# iteration counts are one of the parameters each family is swept over, as the time step is.
SOLVERS = [
    ("explicit", "explicit", {}),
    ("implicit", "implicit", {"cg_iterations": 5}),
    ("implicit", "implicit", {"cg_iterations": 20}),
    ("local_global", "local_global", {"iterations": 1}),
    ("local_global", "local_global", {"iterations": 2}),
    ("local_global", "local_global", {"iterations": 4}),
    ("local_global", "local_global", {"iterations": 8}),
    ("local_global_bdf2", "local_global", {"explicit_when_stable": False, "iterations": 1}),
    ("local_global_bdf2", "local_global", {"explicit_when_stable": False, "iterations": 2}),
    ("local_global_be", "local_global", {"explicit_when_stable": False, "time_order": 1, "iterations": 1}),
    ("local_global_be", "local_global", {"explicit_when_stable": False, "time_order": 1, "iterations": 4}),
]
FAMILIES = ["explicit", "implicit", "local_global_be", "local_global_bdf2", "local_global"]
DEFAULT = "local_global"  # the default integrator: Verlet where stable, else BDF2


def dome(damping: float, mesh: int = 24) -> core.DynamicSurface:
    """The 100 mm dome (8x8 cubic poles, relaxed as the rest shape) on a mesh x mesh grid."""
    s = core.patch((8, 8), (3, 3), (mesh, mesh))
    p = np.array(s.poles)
    x, y = p[..., 0] / 50, p[..., 1] / 50
    p[..., 2] = 15 * (1 - 0.5 * (x ** 2 + y ** 2))
    s.set_poles(p)
    s.relax()
    s.stiffness_map.set_uniform(1e4)
    s.damping_map.set_uniform(damping)
    s.sleep_enabled = False
    return s


# --- scenes: build(solver settings) -> surface; play(surface, dt) -> list of mesh snapshots -----------
def rope_build() -> core.DynamicSurface:
    s = dome(2.0)
    s.tool.reel_time = 0.1
    return s


def rope_play(s: core.DynamicSurface, dt: float, at: tuple[int, int] = (12, 12)) -> list[np.ndarray]:
    """Grabs 2 mm above mesh point ``at``, rises 15 mm over 0.15 s (the cursor moved every 1 ms of
    simulated time), lets go and swings free until 0.3 s; the mesh at the release and at the end."""
    per_ms = round(MS / dt)
    top = np.array(s.mesh[at]) + [0, 0, 2.0]
    snaps = []
    for k in range(300):
        grab = k < 150
        s.set_cursor(list(top + [0, 0, 15.0 * min(k, 150) / 150]), grab=grab)
        s.step(dt, per_ms)
        if k == 149:
            snaps.append(np.array(s.mesh))
    snaps.append(np.array(s.mesh))
    return snaps


def equilibrium_build(mesh: int = 24) -> core.DynamicSurface:
    s = dome(40.0, mesh)
    n = s.mesh.shape[1]
    for idx in (0, n - 1, n * (n - 1), n * n - 1):
        s.add_constraint("point", index=idx)
    raised = np.array(s.mesh).reshape(-1, 3)[s.mesh_index_at(0.4, 0.4)] + [0, 0, 5.0]
    s.add_constraint("point", uv=(0.4, 0.4), target=list(raised))
    tilt = math.radians(10)
    s.add_constraint("normal", uv=(0.7, 0.3), target=[math.sin(tilt), 0.0, math.cos(tilt)])
    return s


def equilibrium_play(s: core.DynamicSurface, dt: float) -> list[np.ndarray]:
    s.step(dt, round(1.5 / dt))
    return [np.array(s.mesh)]


def oscillation_build() -> core.DynamicSurface:
    s = dome(0.0)
    p = np.array(s.poles)
    p[3, 4, 2] += 3.0
    s.set_poles(p)
    return s


def oscillation_play(s: core.DynamicSurface, dt: float) -> list[np.ndarray]:
    s.step(dt, round(0.2 / dt))
    return [np.array(s.mesh)]


def two_faces_build() -> core.DynamicSurface:
    """The dome as two 7 x 8 patches joined along u = 0.5, its seam row linked for G1."""
    ku = [0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1]
    kv = [0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1, 1]
    gu = [sum(ku[i + 1:i + 4]) / 3 for i in range(7)]  # Greville abscissae: an even parametrisation
    gv = [sum(kv[j + 1:j + 4]) / 3 for j in range(8)]
    x, y = np.meshgrid((np.array(gu) - 0.5) * 2, (np.array(gv) - 0.5) * 2, indexing="ij")
    poles = np.stack([50 * x, 50 * y, 15 * (1 - 0.5 * (x ** 2 + y ** 2))], axis=-1)
    s = core.DynamicSurface(core.BSplineSurface(poles, (3, 3), ku, kv), (24, 24))
    s.hold_poles([], [(3 * 8 + j, [(2 * 8 + j, 0.5), (4 * 8 + j, 0.5)]) for j in range(8)])
    s.relax()
    s.stiffness_map.set_uniform(1e4)
    s.damping_map.set_uniform(2.0)
    s.sleep_enabled = False
    s.tool.reel_time = 0.1
    return s


def two_faces_play(s: core.DynamicSurface, dt: float) -> list[np.ndarray]:
    return rope_play(s, dt, at=(9, 12))  # beside the seam (mesh column 11.5)


def two_faces_g2_build() -> core.DynamicSurface:
    """The two faces with their seam curvature-continuous (G2): per column the seam pole and the
    one two rows past it follow the others (seam_continuity), after the least move that makes it so."""
    from HapticSculpt.app import seam_continuity
    s = two_faces_build()
    s.hold_poles([], [])
    poles = np.array(s.poles)
    knots = np.array(s.surface.knots_u)
    made = seam_continuity.project(poles, None, knots, 3, 3, 0.5, set(), "seam")
    s.set_poles(made)
    s.hold_poles([], seam_continuity.links(made, None, knots, 3, 3, 0.5, set(), "seam"))
    s.relax()
    return s


def curve_build() -> core.DynamicSurface:
    """The rope dome following a curve G0: a line of the dome across it at v = 0.35 (the poles do
    not move), held through the stroke by linked poles with offsets (curve_constraint)."""
    from HapticSculpt.app import curve_constraint
    s = rope_build()
    line = [s.surface.evaluate(u, 0.35)["point"] for u in np.linspace(0.1, 0.9, 401)]  # (on the dome)
    _, moved, links = curve_constraint.make(s, line, "G0", None, curve_constraint.FIRST_ID, [], [])
    s.set_poles(moved.reshape(np.array(s.poles).shape))
    s.hold_poles([], links)
    s.relax()
    return s


# name: (build, play, simulated seconds, (shortest, longest) time step)
SCENES = {"rope": (rope_build, rope_play, 0.3, (MS / 1024, MS)),
          "equilibrium": (equilibrium_build, equilibrium_play, 1.5, (MS / 16, 8 * MS)),
          "oscillation": (oscillation_build, oscillation_play, 0.2, (MS / 1024, 8 * MS)),
          "two_faces": (two_faces_build, two_faces_play, 0.3, (MS / 1024, MS)),
          "two_faces_g2": (two_faces_g2_build, two_faces_play, 0.3, (MS / 1024, MS)),
          "curve": (curve_build, rope_play, 0.3, (MS / 1024, MS))}


def shortest_step(label: str, settings: dict) -> float:
    """The shortest step run for a solver: 3.9 us as before for all, down to 0.98 us only for the
    explicit scheme and 1-2 local/global iterations, the only ones still gaining accuracy there
    (implicit's 5-20 CG iterations and backward Euler level off; 4-8 iterations reach the same
    errors as 1-2 at 2-4x the cost), so the runs that would only cost time are left out."""
    if label == "explicit" or (label.startswith("local_global") and label != "local_global_be"
                               and settings.get("iterations", 1) <= 2):
        return 0.0
    return MS / 256


def configure(s: core.DynamicSurface, integrator: str, settings: dict) -> core.DynamicSurface:
    s.integrator = integrator
    for k, v in settings.items():
        setattr(s, k, v)
    return s


def richardson_reference(scene: str) -> tuple[list[np.ndarray], float]:
    """Explicit at 1 ms/1024 and 1 ms/2048, extrapolated; and its own error estimate."""
    build, play, _, _ = SCENES[scene]
    runs = []
    for div in (512, 1024, 2048):
        s = configure(build(), "explicit", {})
        runs.append(play(s, MS / div))
    coarse = [2 * b - a for a, b in zip(runs[0], runs[1])]
    fine = [2 * b - a for a, b in zip(runs[1], runs[2])]
    return fine, max(float(np.abs(f - c).max()) for f, c in zip(fine, coarse)) / SIZE


def static_equilibrium(s: core.DynamicSurface) -> float:
    """Moves s to the minimum of its discrete potential energy by scipy's Newton-CG (the core's exact
    gradient; Hessian-vector products by central differences of it); returns the largest
    remaining gradient entry over the largest initial one."""
    shape = s.poles.shape

    def energy(x: np.ndarray) -> float:
        s.set_poles(x.reshape(shape))
        return s.potential_energy()

    def gradient(x: np.ndarray) -> np.ndarray:
        s.set_poles(x.reshape(shape))
        return s.potential_gradient().ravel().copy()

    def hessp(x: np.ndarray, v: np.ndarray) -> np.ndarray:
        e = 1e-6 / max(1e-300, float(np.abs(v).max()))
        return (gradient(x + e * v) - gradient(x - e * v)) / (2 * e)

    x0 = np.array(s.poles).ravel()
    g0 = float(np.abs(gradient(x0)).max())
    sol = optimize.minimize(energy, x0, jac=gradient, hessp=hessp, method="Newton-CG",
                            options={"xtol": 1e-14, "maxiter": 5000})
    return float(np.abs(gradient(sol.x)).max()) / g0


def static_reference() -> tuple[list[np.ndarray], float]:
    s = equilibrium_build()
    residual = static_equilibrium(s)
    return [np.array(s.mesh)], residual


def reference(scene: str) -> tuple[list[np.ndarray], float]:
    """A scene's reference run and its quality (a campaign task)."""
    return static_reference() if scene == "equilibrium" else richardson_reference(scene)


def run_job(job: tuple[str, str, str, dict, float]) -> tuple[float, list[np.ndarray]]:
    """One run of the sweep (a campaign task): (scene, label, integrator, settings, dt)."""
    scene, _, integrator, settings, dt = job
    return timed_run(scene, integrator, settings, dt)


def timed_run(scene: str, integrator: str, settings: dict, dt: float) -> tuple[float, list[np.ndarray]]:
    """Wall seconds per simulated second (median of 3 for short runs) and the run's snapshots."""
    build, play, seconds, _ = SCENES[scene]
    times, snaps = [], []
    for _ in range(3):
        s = configure(build(), integrator, settings)
        t0 = time.perf_counter()
        snaps = play(s, dt)
        times.append(time.perf_counter() - t0)
        if times[-1] > 0.5:  # long runs once: noise is small next to them
            break
    return float(np.median(times)) / seconds, snaps


def pareto_table(records: list[dict]) -> list[dict]:
    rows = []
    for scene in SCENES:
        for label in FAMILIES:
            row = {"scene": scene, "solver": label}
            for level in LEVELS:
                ok = [r["seconds_per_sim_second"] for r in records
                      if r["scene"] == scene and r["solver"] == label and r["error"] <= level]
                row[f"{level:g}"] = min(ok) if ok else None
            rows.append(row)
    return rows


def plot(records: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(SCENES), figsize=(6 * len(SCENES), 5))
    for ax, scene in zip(axes, SCENES):
        for label in FAMILIES:
            pts = sorted((r["error"], r["seconds_per_sim_second"]) for r in records
                         if r["scene"] == scene and r["solver"] == label and r["error"] > 0)
            if not pts:
                continue
            front, best = [], math.inf  # Pareto front: fastest run reaching each error
            for e, t in pts:
                if t < best:
                    front.append((e, t))
                    best = t
            ax.loglog(*zip(*pts), ".", alpha=0.35)
            ax.loglog(*zip(*front), "-o", ms=4, label=label, color=ax.lines[-1].get_color(),
                      lw=2.5 if label == DEFAULT else 1.2)
        ax.set_title(scene)
        ax.set_xlabel("error / patch size")
        ax.set_ylabel("wall s per simulated s")
        ax.axvspan(1e-6, 1e-2, color="0.93", zorder=0)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


FAIRNESS_SOLVERS = [("explicit", "explicit", {}), ("implicit (5 CG)", "implicit", {"cg_iterations": 5}),
                    ("local_global (default)", "local_global", {})]


def fairness_table(out_dir: str, repeats: int = 3) -> None:
    """Issue 26's fair strokes: the rope scene of tests/fairness_scene.py (a flat 100 mm patch
    whose centre the rope pulls up 20 mm and holds for 4 s), free and corners pinned, elastic and
    clay, today's material (springs alone, bending 0) beside the new default (api.FAIR_BENDING):
    the exact normal curvature of the core's B-spline along the central sections (and the
    diagonals when pinned; HapticSculpt/app/fairness.py): sign changes, total variation over the
    largest |curvature| (the issue's measure) and total variation itself (1/m; the shapes have the
    same lift), the lift; then the wall time per step of each integrator on each scene at a
    session's 1 ms, today's and new, median of ``repeats`` pulls, and the default's lead (the
    paper's schemes' time over the default's)."""
    import fairness_scene as fs
    from HapticSculpt.app import fairness
    from HapticSculpt.app.api import FAIR_BENDING as default
    rows, profiles = [], {}
    print(f"\nfairness: today (bending 0) against the default bending {default:g}; exact normal curvature "
          "along the sections; 'worst' = most sign changes on one section; variation = sum over the sections "
          "of total variation / largest |curvature|; TV 1/m = sum of total variation")
    print(f"{'scene':<16}{'bending':>8}{'lift mm':>9}{'signs':>7}{'worst':>7}{'variation':>11}{'TV 1/m':>9}")
    scenes = [(material, pinned) for material in ("elastic", "clay") for pinned in (False, True)]
    for material, pinned in scenes:
        for bending in (0.0, default):
            s = fs.build(material, pinned, bending)
            report = fs.pull(s)
            m = fs.measure(s, pinned)
            sections = fs.sections(s, pinned)
            profiles[material, pinned, bending] = [fairness.section_curvature(fairness.core_derivatives(s.surface),
                                                                             sections[k]) for k in (2, 6 if pinned else 3)]
            rows.append({"material": material, "pinned": pinned, "bending": bending, "lift": report["lift"],
                         "sign_changes": m.sign_changes, "worst_section": max(c for c, _ in m.per_section),
                         "variation": m.variation, "absolute_variation_per_m": 1000 * m.absolute_variation})
            r = rows[-1]
            print(f"{material + (' pinned' if pinned else ' free'):<16}{bending:>8g}{r['lift']:>9.2f}"
                  f"{r['sign_changes']:>7}{r['worst_section']:>7}{r['variation']:>11.1f}"
                  f"{r['absolute_variation_per_m']:>9.1f}")
    for key, name in (("variation", "variation (over the largest |curvature|)"),
                      ("absolute_variation_per_m", "total variation (1/m)")):
        print(f"{name}, new against today:")
        for material, pinned in scenes:
            before, after = (next(r[key] for r in rows if (r["material"], r["pinned"], r["bending"]) ==
                                  (material, pinned, b)) for b in (0.0, default))
            print(f"  {material + (' pinned' if pinned else ' free'):<16}{before:9.1f} -> {after:9.1f}"
                  + (f"  ({100 * (after / before - 1):+.0f} %)" if before else ""))
        before = sum(r[key] for r in rows if r["bending"] == 0)
        after = sum(r[key] for r in rows if r["bending"] != 0)
        print(f"  {'all four':<16}{before:9.1f} -> {after:9.1f}  ({100 * (after / before - 1):+.0f} %)")
    reach = reach_table(fs)
    timing = []
    print(f"\nper-step wall time (us), dt 1 ms, median of {repeats} pulls (held 1 s), today -> new; "
          "lead = the scheme's time / the default's")
    print(f"{'scene':<16}{'solver':<24}{'today':>8}{'new':>8}{'new/today':>10}{'lead today':>11}{'lead new':>9}")
    for material, pinned in scenes:
        cells: dict = {}
        for label, integ, settings in FAIRNESS_SOLVERS:
            for bending in (0.0, default):
                runs = [fs.pull(configure(fs.build(material, pinned, bending), integ, settings), hold=1.0)["step_seconds"]
                        for _ in range(repeats)]
                cells[label, bending] = float(np.median(runs))
        ours = FAIRNESS_SOLVERS[-1][0]
        for label, _, _ in FAIRNESS_SOLVERS:
            t0, t1 = cells[label, 0.0], cells[label, default]
            lead0, lead1 = t0 / cells[ours, 0.0], t1 / cells[ours, default]
            timing.append({"material": material, "pinned": pinned, "solver": label, "today": t0, "new": t1,
                           "lead_today": lead0, "lead_new": lead1})
            print(f"{material + (' pinned' if pinned else ' free'):<16}{label:<24}{1e6 * t0:>8.0f}{1e6 * t1:>8.0f}"
                  f"{t1 / t0:>10.2f}{lead0:>11.2f}{lead1:>9.2f}")
    for label, _, _ in FAIRNESS_SOLVERS[:-1]:
        leads = [(t["lead_today"], t["lead_new"]) for t in timing if t["solver"] == label]
        print(f"default's lead over {label}: median {np.median([a for a, _ in leads]):.2f}x today, "
              f"{np.median([b for _, b in leads]):.2f}x new")
    with open(os.path.join(out_dir, "fairness.json"), "w") as f:
        json.dump({"default_bending": default, "measure": "exact normal curvature (core B-spline derivatives)",
                   "scenes": rows, "reach": reach, "step_seconds": timing}, f, indent=1)
    plot_fairness(profiles, default, os.path.join(out_dir, "fairness.png"))


def reach_table(fs) -> list[dict]:
    """How far a drag takes the sheet (fairness_scene.reach: the cursor 20 mm up over 0.5 s, held
    1 s, let go, 1 s): springs alone, the plate with the rope as it pulled before its plate gain,
    and the plate now (the rope 1 + ROPE_PLATE_GAIN x bending harder where it is tied); clamped
    (New clamped patch, G1), G0 edges and held corners. The default's sign changes (worst
    section) after the drag."""
    from HapticSculpt.app import fairness
    print("\nreach: a 20 mm drag over 0.5 s, held 1 s (lift held / lift kept 1 s after letting go, mm)")
    print(f"{'scene':<18}{'springs':>14}{'plate, rope before':>20}{'plate now':>14}{'now/springs':>13}{'worst signs':>13}")
    rows = []
    for material in ("clay", "elastic"):
        for edges in ("G1", "G0", "corners"):
            springs = fs.reach(fs.build_held(material, edges, bending=0.0))
            before = fs.reach(fs.build_held(material, edges, rope_as_before=True))
            s = fs.build_held(material, edges)
            now = fs.reach(s)
            worst = max(c for c, _ in fs.measure(s, edges == "corners").per_section)
            rows.append({"material": material, "edges": edges, "springs": springs, "rope_before": before,
                         "now": now, "worst_section_sign_changes": worst})
            print(f"{material + ' ' + edges:<18}{springs['held']:>7.1f}/{springs['kept']:<6.1f}"
                  f"{before['held']:>12.1f}/{before['kept']:<7.1f}{now['held']:>7.1f}/{now['kept']:<6.1f}"
                  f"{now['held'] / springs['held']:>13.2f}{worst:>13}")
    return rows


def plot_fairness(profiles: dict, default: float, path: str) -> None:
    """The normal curvature along the central section (and a diagonal when pinned) of each scene,
    today's against the new default's."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 4, figsize=(15, 6), sharex=True)
    scenes = sorted({(m, p) for m, p, _ in profiles})
    for col, (material, pinned) in enumerate(scenes):
        for row in range(2):
            ax = axes[row, col]
            for bending, style in ((0.0, "r-"), (default, "b-")):
                k = profiles[material, pinned, bending][row]
                ax.plot(np.linspace(0, 1, len(k)), 1000 * k, style, label=f"bending {bending:g}")
            ax.axhline(0, color="0.6", lw=0.5)
            what = "central section" if row == 0 else ("diagonal" if pinned else "central section along v")
            ax.set_title(f"{material} {'pinned' if pinned else 'free'}: {what}", fontsize=9)
            if col == 0:
                ax.set_ylabel("normal curvature (1/m)")
            if row == 1:
                ax.set_xlabel("along the section")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fairness", action="store_true", help="the fairness table instead of the sweep")
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated scenes (default: all)")
    campaign.add_arguments(ap)
    a = ap.parse_args()
    out_dir = os.path.join(ROOT, "bench", "results")
    os.makedirs(out_dir, exist_ok=True)
    if a.fairness:
        fairness_table(out_dir)
        return
    chosen = [c for c in a.scenes.split(",") if c]
    unknown = [c for c in chosen if c not in SCENES]
    if unknown or not chosen:
        sys.exit(f"--scenes: no scene {', '.join(unknown)} (scenes: {', '.join(SCENES)})")
    path = os.path.join(out_dir, "time_vs_error.json")
    kept: dict = {"references": {}, "records": []}
    if chosen != list(SCENES) and os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            kept = json.load(f)
    refs, notes = {}, {k: v for k, v in kept["references"].items() if k not in chosen}
    for scene, (refs[scene], notes[scene]) in campaign.run(reference, chosen, "references", a.workers, a.scheduler):
        pass
    print("reference quality: " + ", ".join(
        f"{k}: {'relative gradient left' if k == 'equilibrium' else 'Richardson spread / size'} {v:.1e}" for k, v in notes.items()))
    jobs = [(scene, label, integ, settings, dt) for scene in chosen for label, integ, settings in SOLVERS
            for dt in DTS if max(SCENES[scene][3][0], shortest_step(label, settings)) <= dt <= SCENES[scene][3][1]]
    records: list[dict] = [r for r in kept["records"] if r["scene"] not in chosen]
    try:
        for (scene, label, integ, settings, dt), (sps, snaps) in campaign.run(run_job, jobs, "runs", a.workers,
                                                                                 a.scheduler):
            err = max(float(np.abs(a - b).max()) for a, b in zip(snaps, refs[scene])) / SIZE
            records.append({"scene": scene, "solver": label, "dt": dt,
                            "iterations": settings.get("iterations", settings.get("cg_iterations", 1)),
                            "seconds_per_sim_second": sps, "error": err if math.isfinite(err) else float("inf")})
    except KeyboardInterrupt:
        print(f"\ninterrupted after {len(records)} of {len(jobs)} runs; writing those", file=sys.stderr)
    # (in the order of the jobs, whatever order they finished in)
    order = {(j[0], j[1], j[4]): i for i, j in enumerate(jobs)}
    records.sort(key=lambda r: (r["scene"] in chosen, order.get((r["scene"], r["solver"], r["dt"]), -1)))
    with open(path, "w") as f:
        json.dump({"references": notes, "records": records}, f, indent=1)
    rows = pareto_table(records)
    print("\nfastest run (wall s per simulated s) reaching each error level; '-' = never reached")
    print(f"{'scene':<14}{'solver':<18}" + "".join(f"{level:>10g}" for level in LEVELS))
    for r in rows:
        print(f"{r['scene']:<14}{r['solver']:<18}" + "".join(
            f"{r[f'{lv:g}']:>10.3g}" if r[f"{lv:g}"] is not None else f"{'-':>10}" for lv in LEVELS))
    print("\ndefault against the paper's schemes (ratio = their fastest / ours at the same error level):")
    for scene in SCENES:
        ours = next(r for r in rows if r["scene"] == scene and r["solver"] == DEFAULT)
        for label in ("explicit", "implicit"):
            theirs = next(r for r in rows if r["scene"] == scene and r["solver"] == label)
            cells = []
            for lv in LEVELS:
                a, b = ours[f"{lv:g}"], theirs[f"{lv:g}"]
                cells.append("ours only" if a is not None and b is None else "-" if a is None else f"{b / a:.1f}x")
            print(f"  {scene:<14}{label:<10}" + "".join(f"{c:>11}" for c in cells))
    plot(records, os.path.join(out_dir, "time_vs_error.png"))


if __name__ == "__main__":
    main()
