#!/usr/bin/env python3
"""How far a step is from what this machine can do (issue 49 item 3): bytes moved and arithmetic per
step, counted from the algorithm, against this machine's memory bandwidth and arithmetic rate,
measured in the same run.

The step is the default solver's (local/global, BDF2, one iteration, the rope's implicit term) on
a flat 400 mm clay patch sampled m x m (m/4 x m/4 controls, bending on), a rope grabbed 15 % in
from a corner and pulled up, as bench/scale.py's local stroke; the time is the median step over
the pull. What a step moves, counted from native_core/src/solvers/integrator_local_global.cpp and
DynamicSurface::step (see MESH_PASSES): the passes over the mesh's per-point arrays (three doubles
a point), the springs' rest lengths, the two tensor products by the sampling matrix A, and the
solve by the factored system: its inverse (up to 600 unknowns) or its L factor read twice (a band:
values only; sparse: values and row indices), with the entries it has for this net
(``DynamicSurface.system_solve_size``). Writes are counted once
(a cache that allocates on write reads them too: up to a third more).

The machine: streaming bandwidth (numpy copies, bytes read plus written) with the data in the
per-core cache, in the shared cache and in memory, and the arithmetic rate of a dense matrix
product on one core (OpenBLAS, one thread: the FMA units' peak as a program reaches it). A step's
bound is the larger of its bytes over the bandwidth of the level its working set fits in and its
arithmetic over that rate. Hardware counters would check the counts; this machine's perf reads
none (a virtual machine: "not supported"), and the table says so.

Prints the table and writes bench/results/roofline.json and roofline.png.

    OPENBLAS_NUM_THREADS=1 /usr/bin/python3 bench/roofline.py [--sizes 64 128 256] [--big]   (--big adds 512)
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # (one core: the step runs on one)
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from HapticSculpt import core  # noqa: E402
from HapticSculpt.app.api import CLAY, CLAY_DAMPING, FAIR_BENDING  # noqa: E402

DT, PULL = 1e-3, 0.2
#: The passes of one step over the mesh's per-point arrays (x, y, z each), as (what, arrays read,
#: arrays written); a third of an array is a per-point scalar (masses, damping).
MESH_PASSES = [
    ("step start: mesh copied (DynamicSurface::step)", 1, 1),
    ("BDF2: x^ and y on the mesh from d, A v and their history", 4, 2),
    ("predicted motion over the step", 2, 1),
    ("where the tool pulls, and its forces", 2, 2),
    ("right-hand side's fixed part (damping, tool)", 3 + 1 / 3, 1),
    ("first iterate (the O(dt^3) prediction)", 3, 1),
    ("right-hand side (mass and damping on y - d)", 3 + 2 / 3, 1),
    ("springs J t - L d: four families, iterate and right-hand side", 8, 4),
    ("bending (its stencil, into the right-hand side)", 2, 1),
    ("A^T: the right-hand side to the poles (tensor product, its half-way array a quarter)", 1.25, 0.25),
    ("A: the mesh from the new poles (tensor product)", 0.25, 1.25),
    ("A v from the new mesh and x^", 2, 1),
    ("history: the mesh the step started from", 1, 1),
    ("work of the applied forces (DynamicSurface::step)", 3, 0),
    ("clay: each spring's rest length creeps toward its length (SpringMesh::applyPlasticity)", 4, 0),
]
#: Bytes per spring and step: its rest length read by the projections; clay's creep reads its
#: endpoints' indices and first rest length and reads and writes its rest length.
SPRING_BYTES = 8 + 8 + 8 + 16
#: Arithmetic per spring (difference, length, projection onto the rest length, both ends' terms),
#: counted twice with clay (its creep takes the length again).
SPRING_FLOPS = 28
#: Arithmetic per mesh point in the bending stencil (13 points, three coordinates, multiply-add).
BENDING_FLOPS = 78
DEGREE = 3


def counts(m: int, springs: int, solve: tuple[int, int, bool]) -> dict:
    """Bytes and arithmetic of one step on an m x m mesh (see MESH_PASSES)."""
    points, n = m * m, m // 4
    array = 24 * points  # (three doubles a point)
    read = sum(r for _, r, _ in MESH_PASSES)
    written = sum(w for _, _, w in MESH_PASSES)
    unknowns, entries, how = solve
    dense = how == "dense"
    # (dense: the inverse once; band: L twice, values only; sparse: L twice, values and row indices)
    solve_bytes = 8 * entries if dense else 2 * (8 if how == "band" else 12) * entries
    solve_bytes += 4 * 24 * unknowns  # (right-hand side, solution, work, its permutation)
    solve_flops = 6 * entries if dense else 12 * entries
    tensor_flops = 2 * 2 * (n + m) * m * (DEGREE + 1) * 3  # (A and A^T: (n + g) h (p + 1) per coordinate)
    mesh_bytes = (read + written) * array + SPRING_BYTES * springs
    return {"mesh_bytes": mesh_bytes, "solve_bytes": solve_bytes, "bytes": mesh_bytes + solve_bytes,
            "flops": 3 * read * points + 2 * SPRING_FLOPS * springs + BENDING_FLOPS * points + tensor_flops + solve_flops,
            "solve_flops": solve_flops, "working_set": 20 * array + 24 * springs + solve_bytes / (1 if dense else 2),
            "mesh_passes": read + written}


def step_time(m: int, steps: int) -> tuple[float, int, tuple[int, int, bool]]:
    """The median step (s) over the rope's pull, the springs and the system solved by."""
    s = core.patch((m // 4, m // 4), mesh=(m, m), size=(400.0, 400.0))
    s.set_plasticity(*CLAY)
    s.damping_map.set_uniform(CLAY_DAMPING)
    s.bending_map.set_uniform(FAIR_BENDING)
    s.set_tool("rope")
    start = np.array([-140.0, -140.0, 0.0])
    times = []
    for k in range(steps):
        s.set_cursor(list(start + [0.0, 0.0, 50.0 * min(k * DT, PULL)]), grab=True)
        t0 = time.perf_counter()
        report = s.step(DT)
        times.append(time.perf_counter() - t0)
        if report.verlet or report.iterations != 1:
            raise RuntimeError(f"{m}: the step counted is local/global with one iteration, got {report!r}")
    return float(np.median(times[20:])), int(s.spring_count), tuple(s.system_solve_size)


def bandwidth(nbytes: int, seconds: float = 0.4) -> float:
    """Streaming bandwidth (bytes read plus written per second) copying an array of ``nbytes``."""
    src = np.ones(nbytes // 8)
    dst = np.zeros_like(src)
    np.copyto(dst, src)  # (its pages mapped: a first write page-faults)
    best, end = np.inf, time.perf_counter() + seconds
    repeat, rounds = max(1, int(2e7 // nbytes)), 0
    while time.perf_counter() < end or rounds < 3:
        rounds += 1
        t0 = time.perf_counter()
        for _ in range(repeat):
            np.copyto(dst, src)
        best = min(best, (time.perf_counter() - t0) / repeat)
    return 2 * nbytes / best


def arithmetic_rate(n: int = 1024, seconds: float = 0.6) -> float:
    """Floating-point operations per second of a dense n x n product on one core."""
    a, b = np.random.default_rng(1).random((2, n, n))
    best, end = np.inf, time.perf_counter() + seconds
    while time.perf_counter() < end:
        t0 = time.perf_counter()
        a @ b
        best = min(best, time.perf_counter() - t0)
    return 2 * n ** 3 / best


def cache_sizes() -> tuple[int, int]:
    """(per-core, shared) cache bytes: the largest private level and the last level (sysfs)."""
    private, shared = 512 << 10, 8 << 20
    base = "/sys/devices/system/cpu/cpu0/cache"
    try:
        for index in sorted(os.listdir(base)):
            d = os.path.join(base, index)
            if not index.startswith("index") or open(os.path.join(d, "type")).read().strip() == "Instruction":
                continue
            size = open(os.path.join(d, "size")).read().strip()
            value = int(size[:-1]) * {"K": 1 << 10, "M": 1 << 20}[size[-1]] if size[-1] in "KM" else int(size)
            cpus = open(os.path.join(d, "shared_cpu_list")).read().strip()
            if cpus in ("0",):
                private = max(private, value)
            else:
                shared = max(shared, value)
    except (OSError, ValueError, KeyError):
        pass
    return private, shared


def counters_readable() -> bool:
    """Whether perf can read hardware counters here (a virtual machine often cannot)."""
    try:
        out = subprocess.run(["perf", "stat", "-x,", "-e", "instructions", "true"], capture_output=True, text=True,
                             timeout=20)
    except (OSError, subprocess.SubprocessError):
        return False
    return out.returncode == 0 and "not supported" not in out.stderr and "<not" not in out.stderr


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 128, 256])
    parser.add_argument("--big", action="store_true", help="add 512 x 512")
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "roofline"))
    args = parser.parse_args()
    sizes = args.sizes + ([512] if args.big and 512 not in args.sizes else [])
    private, shared = cache_sizes()
    machine = {"bandwidth_private": bandwidth(private // 4), "bandwidth_shared": bandwidth(shared // 2),
               "bandwidth_memory": bandwidth(256 << 20), "flops": arithmetic_rate(),
               "cache_private": private, "cache_shared": shared, "counters": counters_readable()}
    rows = []
    for m in sizes:
        seconds, springs, solve = step_time(m, args.steps)
        c = counts(m, springs, solve)
        level = "private" if c["working_set"] <= private else "shared" if c["working_set"] <= shared else "memory"
        bound = max(c["bytes"] / machine[f"bandwidth_{level}"], c["flops"] / machine["flops"])
        rows.append({"mesh": m, "controls": m // 4, "step_us": seconds * 1e6, "springs": springs,
                     "solve_unknowns": solve[0], "solve_entries": solve[1], "solve_by": solve[2], **c,
                     "level": level, "bound_us": bound * 1e6, "ratio": seconds / bound,
                     "memory_bound_us": c["bytes"] / machine["bandwidth_memory"] * 1e6})
    print(f"machine: bandwidth {machine['bandwidth_private'] / 1e9:.1f} GB/s in the per-core cache "
          f"({private >> 10} KiB), {machine['bandwidth_shared'] / 1e9:.1f} GB/s in the shared one "
          f"({shared >> 20} MiB), {machine['bandwidth_memory'] / 1e9:.1f} GB/s from memory; "
          f"{machine['flops'] / 1e9:.1f} GFLOP/s (dense product, one core); hardware counters: "
          f"{'read' if machine['counters'] else 'not readable here (the counts are the algorithm only)'}")
    print(f"{'mesh':>5} {'poles':>6} {'step us':>8} {'MB/step':>8} {'solve MB':>8} {'Mflop':>7} {'set MB':>7} "
          f"{'fits in':>8} {'bound us':>8} {'x bound':>7} {'x 64²':>6}")
    first = rows[0]["step_us"]
    for r in rows:
        print(f"{r['mesh']:>4}² {r['controls']:>4}² {r['step_us']:>8.0f} {r['bytes'] / 1e6:>8.2f} "
              f"{r['solve_bytes'] / 1e6:>8.2f} {r['flops'] / 1e6:>7.1f} {r['working_set'] / 1e6:>7.1f} {r['level']:>8} "
              f"{r['bound_us']:>8.0f} {r['ratio']:>7.1f} {r['step_us'] / first:>6.1f}")
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out + ".json", "w") as f:
        json.dump({"machine": machine, "rows": rows, "mesh_passes": MESH_PASSES}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    points = [r["mesh"] ** 2 for r in rows]
    ax.loglog(points, [r["step_us"] for r in rows], "o-", label="step (measured)")
    ax.loglog(points, [r["bound_us"] for r in rows], "s--", label="bound (bytes / bandwidth of where it fits)")
    ax.loglog(points, [r["memory_bound_us"] for r in rows], ":", label="bytes / memory bandwidth")
    ax.loglog(points, [first * p / points[0] for p in points], color="grey", lw=0.8, label="linear from 64²")
    ax.set_xlabel("mesh points")
    ax.set_ylabel("µs per step")
    ax.set_title("a step against this machine's bound")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out + ".png", dpi=110)
    print(f"wrote {args.out}.json and {args.out}.png")


if __name__ == "__main__":
    main()
