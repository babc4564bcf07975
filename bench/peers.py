#!/usr/bin/env python3
"""Peers side by side, in one run on this machine: the same mass-spring grid stepped by
PositionBasedDynamics (pypbd, XPBD distance constraints), NVIDIA Newton on warp's CPU backend
(XPBD, semi-implicit and VBD), and our core.

The grid: N x N points over 100 mm, springs to the four neighbours and along both diagonals,
stiffness 100 per spring, the lumped masses of our core (density 1), no damping, no gravity, rest
lengths from the flat grid. It starts with a smooth 10 mm bump and swings for 0.1 s at a 1 ms step
(at stiffness 1e4 every solver, ours included, is 5 % off at this step and nothing is compared).
Error: largest point distance at 0.1 s to a converged reference of the same discrete ODE (our
explicit scheme at 1 ms / 256 and / 512, Richardson-extrapolated), over the grid size. A run that
blows up is unstable at this step.

Ours runs the very same grid: a degree-1 B-spline with one control point per mass point, so d = A p
with A the identity (that is Liu et al. 2013's prefactored local/global on a plain grid, with BDF2,
and Verlet steps where those are stable);
and, as the paper's dual representation, with 12..64 cubic poles per side driving the same mass
points (same springs, masses and error measure; fewer degrees of freedom).
Each peer runs at its iteration/substep settings; ours is then matched to it: the cheapest of our
settings whose error is no larger than the peer's (matched_error). pbatoolkit, named by the issue,
was installed and has only tetrahedral FEM (VBD, XPBD with Stable Neo-Hookean), no springs, so it
cannot step this grid; the prefactored local/global peer is ours on the full grid.

Needs the benchmark venv (make bench-peers): pypbd, warp-lang, newton. Writes
bench/results/peers.json (records: grid, peer, peer_us_per_step, ours_us_per_step, matched_error;
plus ours_full_grid_us_per_step: the same match among our plain-grid settings only) and prints
ratios (peer time / ours: above 1, ours is faster). Interrupting keeps the finished records.
"""
from __future__ import annotations

import json
import math
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.dirname(os.path.abspath(__file__))]
from HapticSculpt import core  # noqa: E402
from progress import progress  # noqa: E402

SIZE, K, DT, STEPS = 100.0, 100.0, 1e-3, 100
GRIDS = [int(g) for g in os.environ.get("HS_PEER_GRIDS", "40,128").split(",")]


def grid_surface(n: int, controls: int | None = None, degree: int = 1) -> core.DynamicSurface:
    """The n x n grid; by default one degree-1 control per mass point (A = identity), else the
    paper's dual representation with `controls` x `controls` poles of `degree` over the same grid."""
    c = controls or n
    s = core.patch((c, c), (degree, degree), (n, n), (SIZE, SIZE))
    s.stiffness_map.set_uniform(K)
    s.damping_map.set_uniform(0.0)
    s.sleep_enabled = False
    s.energy_guard = False  # the peers have none (ours would run it on Verlet steps)
    return s


def bump(points: np.ndarray) -> np.ndarray:
    """The start: a smooth 10 mm bump over the flat grid (rest lengths stay the flat ones)."""
    out = points.copy()
    r2 = (points[:, 0] ** 2 + points[:, 1] ** 2) / (0.3 * SIZE) ** 2
    out[:, 2] += 10.0 * np.exp(-r2)
    return out


def springs(n: int) -> list[tuple[int, int]]:
    out = []
    for i in range(n):
        for j in range(n):
            a = i * n + j
            if j + 1 < n:
                out.append((a, a + 1))
            if i + 1 < n:
                out.append((a, a + n))
            if i + 1 < n and j + 1 < n:
                out.append((a, a + n + 1))
            if i + 1 < n and j > 0:
                out.append((a, a + n - 1))
    return out


# --- ours ------------------------------------------------------------------------------------------
def start_poles(s: core.DynamicSurface) -> np.ndarray:
    """Poles whose mesh is the bumped grid (exactly for A = identity, least squares otherwise)."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.linalg import lsqr
    flat = np.array(s.mesh).reshape(-1, 3)
    target = bump(flat)
    indptr, indices, data, shape = s.sampling_matrix()
    a = csr_matrix((data, indices, indptr), shape=shape)
    poles = np.array(s.poles).reshape(-1, 3).copy()
    if shape[0] == shape[1]:
        return target.reshape(s.poles.shape)
    for k in range(3):
        poles[:, k] = lsqr(a, target[:, k], atol=1e-14, btol=1e-14, iter_lim=10000)[0]
    return poles.reshape(s.poles.shape)


def ours(n: int, integrator: str, dt: float, steps: int, substeps: int = 1, controls: int | None = None,
         degree: int = 1, **settings) -> tuple[np.ndarray, float]:
    """Final points and microseconds per step of dt (made of `substeps` steps of dt / substeps)."""
    dt, steps = dt / substeps, steps * substeps
    s = grid_surface(n, controls, degree)
    s.integrator = integrator
    for k, v in settings.items():
        setattr(s, k, v)
    start = start_poles(s)
    s.set_poles(start)
    s.step(dt)  # factorisation outside the timing
    s.set_poles(start)
    t0 = time.perf_counter()
    s.step(dt, steps)
    us = (time.perf_counter() - t0) / steps * substeps * 1e6
    return np.array(s.mesh).reshape(-1, 3), us


def reference(n: int) -> np.ndarray:
    a, _ = ours(n, "explicit", DT / 256, STEPS * 256)
    b, _ = ours(n, "explicit", DT / 512, STEPS * 512)
    return 2 * b - a


# --- PositionBasedDynamics (pypbd) -------------------------------------------------------------------
def pbd_run(n: int, masses: np.ndarray, substeps: int, iterations: int) -> tuple[np.ndarray, float]:
    import pypbd as pbd
    sim = pbd.Simulation.getCurrent()
    sim.initDefault()
    sim.setValueFloat(sim.GRAVITATION, [0.0, 0.0, 0.0]) if hasattr(sim, "GRAVITATION") else None
    model = sim.getModel()
    model.cleanup()
    flat = np.array(grid_surface(n).mesh).reshape(-1, 3)
    tris = []
    for i in range(n - 1):
        for j in range(n - 1):
            a = i * n + j
            tris += [a, a + 1, a + n, a + 1, a + n + 1, a + n]
    model.addTriangleModel([p for p in flat], tris)
    pd = model.getParticles()
    for i, m in enumerate(masses):
        pd.setMass(i, float(m))
    for a, b in springs(n):
        model.addDistanceConstraint_XPBD(a, b, K)
    start = bump(flat)
    for i, p in enumerate(start):
        pd.setPosition(i, p)
        pd.setPosition0(i, p)
    ts = sim.getTimeStep()
    ts.setValueUInt(ts.NUM_SUB_STEPS, substeps)
    ts.setValueUInt(ts.MAX_ITERATIONS, iterations)
    pbd.TimeManager.getCurrent().setTimeStepSize(DT)
    t0 = time.perf_counter()
    for _ in range(STEPS):
        ts.step(model)
    us = (time.perf_counter() - t0) / STEPS * 1e6
    out = np.array([pd.getPosition(i) for i in range(n * n)])
    return out, us


# --- Newton (warp, CPU) -----------------------------------------------------------------------------
def newton_run(n: int, masses: np.ndarray, solver: str, substeps: int, iterations: int) -> tuple[np.ndarray, float]:
    import newton
    import warp as wp
    wp.config.quiet = True
    wp.set_device("cpu")
    b = newton.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    flat = np.array(grid_surface(n).mesh).reshape(-1, 3)
    for p, m in zip(flat, masses):
        b.add_particle(tuple(p), (0.0, 0.0, 0.0), float(m), radius=0.0)
    for a, c in springs(n):
        b.add_spring(a, c, K, 0.0, 0.0)
    if solver == "vbd":
        b.color()  # VBD's parallel Gauss-Seidel needs a graph colouring
    model = b.finalize(device="cpu")
    if solver == "xpbd":
        sol = newton.solvers.SolverXPBD(model, iterations=iterations)
    elif solver == "vbd":
        sol = newton.solvers.SolverVBD(model, iterations=iterations)
    else:
        sol = newton.solvers.SolverSemiImplicit(model)
    s0, s1 = model.state(), model.state()
    start = bump(flat)
    s0.particle_q.assign(start.astype(np.float32))
    h = DT / substeps
    sol.step(s0, s1, None, None, h)  # kernel compilation outside the timing
    s0, s1 = model.state(), model.state()
    s0.particle_q.assign(start.astype(np.float32))
    wp.synchronize()
    t0 = time.perf_counter()
    for _ in range(STEPS * substeps):
        s0.clear_forces()
        sol.step(s0, s1, None, None, h)
        s0, s1 = s1, s0
    wp.synchronize()
    us = (time.perf_counter() - t0) / STEPS * 1e6
    return s0.particle_q.numpy().astype(float), us


PEERS = [
    ("PositionBasedDynamics XPBD (pypbd), 1 substep x 5 it", lambda n, m: pbd_run(n, m, 1, 5)),
    ("PositionBasedDynamics XPBD (pypbd), 5 substeps x 1 it", lambda n, m: pbd_run(n, m, 5, 1)),
    ("Newton XPBD (warp CPU), 1 substep x 10 it", lambda n, m: newton_run(n, m, "xpbd", 1, 10)),
    ("Newton XPBD (warp CPU), 10 substeps x 2 it", lambda n, m: newton_run(n, m, "xpbd", 10, 2)),
    ("Newton semi-implicit (warp CPU), 32 substeps", lambda n, m: newton_run(n, m, "semi", 32, 1)),
    ("Newton VBD (warp CPU), 1 substep x 10 it", lambda n, m: newton_run(n, m, "vbd", 1, 10)),
]
# ours on the same grid; the last rows use the paper's dual representation (fewer, cubic poles
# driving the same mass points), our product's configuration
OURS = ([("local_global", {"iterations": it}) for it in (1, 2, 4)] +
        [("local_global", {"iterations": it, "substeps": sub}) for it in (1, 2) for sub in (2, 4, 8)] +
        [("implicit", {"cg_iterations": 20})] +
        [("local_global", {"iterations": it, "controls": c, "degree": 3}) for it in (1, 2) for c in (12, 24, 32, 64)])


def error(x: np.ndarray, ref: np.ndarray) -> float:
    e = float(np.abs(x - ref).max()) / (SIZE * math.sqrt(2))
    return e if math.isfinite(e) else math.inf


def main() -> None:
    out = os.path.join(ROOT, "bench", "results", "peers.json")
    records: list[dict] = []
    try:
        for n in GRIDS:
            ref = reference(n)
            masses = grid_surface(n).point_masses()
            mine = []
            for integ, st in OURS:
                if st.get("controls", 0) >= n:
                    continue
                x, us = ours(n, integ, DT, STEPS, **st)
                mine.append((error(x, ref), us, f"{integ} {st}", "controls" not in st))
            print(f"\n{n}x{n} grid, ours: " + ", ".join(f"{lbl}: {us:.0f} us, err {e:.1e}" for e, us, lbl, _ in mine))
            for name, run in progress(PEERS, f"peers {n}x{n}"):
                try:
                    x, us = run(n, masses)
                except Exception as exc:  # noqa: BLE001 - a peer that cannot run is reported, not fatal
                    print(f"  {name}: could not run ({type(exc).__name__}: {exc})", file=sys.stderr)
                    continue
                e = error(x, ref)
                ok = [m for m in mine if m[0] <= e]
                best = min(ok, key=lambda m: m[1]) if ok else None  # any of ours, dual representation included
                full = min((m for m in ok if m[3]), key=lambda m: m[1], default=None)  # ours on the plain grid
                records.append({"grid": f"{n}x{n}", "peer": name, "peer_us_per_step": us, "peer_error": e,
                                "ours_us_per_step": best[1] if best else None, "ours_setting": best[2] if best else None,
                                "ours_full_grid_us_per_step": full[1] if full else None,
                                "ours_full_grid_setting": full[2] if full else None, "matched_error": e})

                def cell(m: tuple | None) -> str:
                    return f"{m[1]:>7.0f} us = {us / m[1]:.1f}x ({m[2]})" if m else "   none this inaccurate"
                print(f"  {name:<56} {us:>7.0f} us err {e:.1e} | ours: {cell(best)} | plain grid: {cell(full)}")
    except KeyboardInterrupt:
        print("\ninterrupted; writing finished records", file=sys.stderr)
    with open(out, "w") as f:
        json.dump(records, f, indent=1)


if __name__ == "__main__":
    main()
