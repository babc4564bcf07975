#!/usr/bin/env python3
"""Real-time priority without root: the haptic period of a session run by a user who is not root
and has no rtprio limit, with and without RealtimeKit, against root's, under one CPU hog.

Each run is bench/loops.py's scene (a replayed rope stroke, 12x12 poles / 40x40 mesh, 1 kHz) with
its "cpu_hog" load (a process spinning on the other core, an overlay's frame work in this one), in a
process of its own: as root (SCHED_FIFO directly), and as user nobody (setpriv: no capabilities,
no rtprio limit) on a system bus of its own with a RealtimeKit stand-in that grants for real
(tools/realtime_kit_standin.py; rtkit-daemon needs the machine's bus and polkit), and on a bus
without it. Needs root (to be the other user and to grant), dbus-daemon and setpriv.

Prints a table (medians over --repeats runs, interleaved) and writes bench/results/realtime_kit.json
and bench/results/realtime_kit.png (the haptic period's p99 and max per run).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from realtime_kit_standin import private_system_bus  # noqa: E402

NOBODY = 65534
SCENE = ((12, 12), (40, 40), 1e-3)
#: One loops.py run; prints its record as JSON.
CHILD = """
import json, sys
sys.path[:0] = [ROOT, ROOT + "/bench"]
import loops
controls, mesh, sim_dt = SCENE
r, periods, errors = loops.run_scene(tuple(controls), tuple(mesh), sim_dt, SECONDS, 1000.0, "cpu_hog")
print(json.dumps(r))
"""
MODES = ("root", "user + RealtimeKit", "user, no RealtimeKit")


def run(mode: str, seconds: float) -> dict:
    folder = tempfile.mkdtemp(prefix="hs-rtbench-")
    try:
        os.chmod(folder, 0o755)
        script = os.path.join(folder, "child.py")
        with open(script, "w", encoding="utf-8") as f:
            f.write(f"ROOT = {ROOT!r}\nSCENE = {SCENE!r}\nSECONDS = {seconds!r}\n" + CHILD)
        env = {k: v for k, v in os.environ.items() if k != "DBUS_SYSTEM_BUS_ADDRESS"}
        env["HOME"] = folder
        user = ["setpriv", f"--reuid={NOBODY}", f"--regid={NOBODY}", "--clear-groups", "--inh-caps=-all"]

        def child(command: list[str], address: str) -> dict:
            proc = subprocess.run(command + [sys.executable, script], env=dict(env, DBUS_SYSTEM_BUS_ADDRESS=address),
                                  capture_output=True, text=True, timeout=seconds * 10 + 120)
            if proc.returncode != 0:
                raise RuntimeError(f"{mode}: {proc.stderr[-2000:]}")
            return json.loads(proc.stdout.strip().splitlines()[-1])
        if mode == "root":
            return child([], f"unix:path={folder}/no_bus")
        with private_system_bus(standin=mode == "user + RealtimeKit") as address:
            return child(user, address)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    if os.geteuid() != 0:
        sys.exit("realtime_kit.py: run as root (it runs sessions as another user and grants as rtkit does)")
    runs: dict[str, list[dict]] = {m: [] for m in MODES}
    for _ in range(args.repeats):
        for mode in MODES:  # (interleaved: the machine's drift falls on all three)
            runs[mode].append(run(mode, args.seconds))
    table = []
    print(f"{'mode':<22}{'priority':<34}{'haptic Hz':>10}{'p50 ms':>8}{'p99 ms':>8}{'max ms':>8}{'err p99':>9}")
    for mode in MODES:
        rs = runs[mode]
        row = {"mode": mode, "realtime_how": rs[-1]["realtime_how"], "runs": len(rs),
               "haptic_hz": statistics.median(r["haptic_hz"] for r in rs),
               "haptic_period_p50_ms": statistics.median(r["haptic_period_p50_ms"] for r in rs),
               "haptic_period_p99_ms": statistics.median(r["haptic_period_p99_ms"] for r in rs),
               "haptic_period_max_ms": statistics.median(r["haptic_period_max_ms"] for r in rs),
               "force_error_rel": statistics.median([r["force_error_rel"] or 0.0 for r in rs])}
        table.append(row)
        print(f"{mode:<22}{row['realtime_how'][:33]:<34}{row['haptic_hz']:>10.1f}{row['haptic_period_p50_ms']:>8.3f}"
              f"{row['haptic_period_p99_ms']:>8.3f}{row['haptic_period_max_ms']:>8.2f}{row['force_error_rel']:>9.2e}")
    out = os.path.join(ROOT, "bench", "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "realtime_kit.json"), "w", encoding="utf-8") as f:
        json.dump({"scene": "12x12/40x40", "load": "cpu_hog", "machine": f"{os.cpu_count()} cores", "medians": table,
                   "runs": runs}, f, indent=2)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    for k, mode in enumerate(MODES):
        for j, key in enumerate(("haptic_period_p99_ms", "haptic_period_max_ms")):
            ax.scatter([k + 0.15 * (2 * j - 1)] * len(runs[mode]), [r[key] for r in runs[mode]],
                       marker="ox"[j], color=f"C{j}", label=key.replace("haptic_period_", "").replace("_ms", "")
                       if k == 0 else None)
    ax.axhline(1.2, color="r", lw=0.8, ls="--", label="goal: p99 1.2 ms")
    ax.set_xticks(range(len(MODES)), MODES)
    ax.set_yscale("log")
    ax.set_ylabel("haptic period (ms)")
    ax.set_title("Haptic period under one CPU hog: root, and a user with and without RealtimeKit")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "realtime_kit.png"), dpi=100)
    print("wrote bench/results/realtime_kit.json, bench/results/realtime_kit.png")


if __name__ == "__main__":
    main()
