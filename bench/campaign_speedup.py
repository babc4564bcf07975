#!/usr/bin/env python3
"""The campaigns' speed-up on Dask distributed: wall time of the stress campaign (SCENES seeded
scenes) and of the batch replay (the eight default parts in FreeCAD console mode) with the tasks run
in order here (``--workers 0``, no Dask) and on a local cluster of 1 and 2 workers, median of
REPEATS runs each, interleaved so that the machine's load falls on all alike. Checks on the way
that every run's records equal the serial run's. Prints a table and writes
bench/results/campaign_speedup.json and campaign_speedup.png.

    python3 bench/campaign_speedup.py [--scenes 600] [--repeats 3]
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(ROOT, "bench")
WORKERS = (0, 1, 2)


def stress(scenes: int, workers: int, tmp: str) -> tuple[float, object]:
    log, out = os.path.join(tmp, f"stress{workers}.jsonl"), os.path.join(tmp, f"stress{workers}.json")
    if os.path.exists(log):
        os.remove(log)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, os.path.join(BENCH, "stress_campaign.py"), "--scenes", str(scenes), "--first", "20000",
                    "--log", log, "--out", out, "--workers", str(workers)], check=True, capture_output=True)
    wall = time.perf_counter() - t0
    with open(out, encoding="utf-8") as f:
        summary = json.load(f)
    return wall, (summary["per_integrator"], summary["failures"])


def replay(workers: int, tmp: str) -> tuple[float, object]:
    out = os.path.join(tmp, f"replay{workers}")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, os.path.join(BENCH, "batch_replay.py"), "--out", out, "--workers", str(workers)],
                   check=True, capture_output=True)
    wall = time.perf_counter() - t0
    with open(os.path.join(out, "batch_replay.json"), encoding="utf-8") as f:
        parts = json.load(f)["parts"]
    return wall, [{k: v for k, v in p.items() if k != "wall_seconds"} for p in parts]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=600)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    times: dict[str, dict[int, list[float]]] = {"stress": {w: [] for w in WORKERS}, "batch replay": {w: [] for w in WORKERS}}
    with tempfile.TemporaryDirectory() as tmp:
        reference: dict[str, object] = {}
        for _ in range(a.repeats):
            for w in WORKERS:
                for name, run in (("stress", lambda: stress(a.scenes, w, tmp)), ("batch replay", lambda: replay(w, tmp))):
                    wall, result = run()
                    reference.setdefault(name, result)
                    if result != reference[name]:
                        sys.exit(f"{name} with {w} workers gave other records than the serial run")
                    times[name][w].append(wall)
    rows = []
    print(f"wall time (s), median of {a.repeats}, on {os.cpu_count()} cores; records equal to the serial run's in every run")
    print(f"{'campaign':<16}{'serial':>9}{'1 worker':>10}{'2 workers':>11}{'2 vs 1':>9}{'2 vs serial':>13}")
    for name, per in times.items():
        med = {w: statistics.median(v) for w, v in per.items()}
        rows.append({"campaign": name, "tasks": a.scenes if name == "stress" else 8, "median_seconds": med,
                     "speedup_2_vs_1": med[1] / med[2], "speedup_2_vs_serial": med[0] / med[2], "runs": per})
        print(f"{name:<16}{med[0]:>9.1f}{med[1]:>10.1f}{med[2]:>11.1f}{med[1] / med[2]:>8.2f}x{med[0] / med[2]:>12.2f}x")
    out = os.path.join(ROOT, "bench", "results", "campaign_speedup.json")
    with open(out, "w", encoding="utf-8") as f:
        json.dump({"cores": os.cpu_count(), "repeats": a.repeats, "rows": rows}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 3.2))
    labels = ["serial", "1 worker", "2 workers"]
    for i, r in enumerate(rows):
        ax.bar([x + 0.38 * i for x in range(3)], [r["median_seconds"][w] for w in WORKERS], width=0.36,
               label=f"{r['campaign']} ({r['tasks']} tasks)")
    ax.set_xticks([x + 0.19 for x in range(3)], labels)
    ax.set_ylabel("wall time (s)")
    ax.legend()
    ax.set_title("campaigns on Dask distributed")
    fig.tight_layout()
    fig.savefig(out.replace(".json", ".png"), dpi=90)
    print(f"wrote {os.path.relpath(out, ROOT)} and campaign_speedup.png")


if __name__ == "__main__":
    main()
