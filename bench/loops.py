#!/usr/bin/env python3
"""The threaded loops (paper section 5): a replay device drives a rope stroke on a scene for a set
time while the haptic loop renders the force from the simulation's local estimate.

Each scene runs twice: alone ("load": "none") and as a user has it ("cpu_hog"): a process
spinning on the other core while this one does an overlay's frame work (30 times a second: the
newest poles from the session, the surface evaluated on a 96 x 96 grid with its normals, as the
zebra display does), all in the same run, so the two compare.

Prints a table and writes bench/results/loops.json: for the 12x12/40x40 scene without load at the
top level (haptic_hz, haptic_period_p50/p99/max_ms, sim_hz, force_error_rel = 99th percentile of
the estimated force's error against the force from the exact surface, relative to the force,
cpu_percent of one core, latency_p50/p99_ms = from reading the device to writing its force) and
every run under "scenes", each with its "load" and "realtime_priority" (sessions ask for SCHED_FIFO
on the haptic thread, granted to root or within an rtprio limit; --no-realtime runs without); plus
bench/results/loops.png (period histogram, force error).
"""
from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import resource
import sys
import threading
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from HapticSculpt import core  # noqa: E402
from HapticSculpt.core import native as _core  # noqa: E402
from HapticSculpt.runtime.replay_device import ReplayDevice  # noqa: E402

SCENES = [((12, 12), (40, 40), 5e-4), ((32, 32), (128, 128), 1e-3), ((64, 64), (256, 256), 1e-3)]


def trajectory(seconds: float) -> ReplayDevice:
    """A long rope stroke: lift, circle and wiggle, with a release and re-grab every 2.5 s."""
    t = np.linspace(0.0, seconds, int(seconds * 50) + 1)
    xyz = np.column_stack([12 * np.sin(1.3 * t), 9 * np.sin(0.7 * t + 1), 18 + 10 * np.sin(2.1 * t) ** 2])
    xyz[t < 0.3] *= (t[t < 0.3] / 0.3)[:, None]
    buttons = np.where((t % 2.5) < 2.4, 1, 0)
    buttons[-1] = 0
    return ReplayDevice(t, xyz, buttons=buttons)


def cpu_seconds() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _spin() -> None:
    while True:
        pass


class Load:
    """A CPU hog in another process and an overlay's frame work in this one, while it is entered."""

    def __init__(self, runtime, controls) -> None:
        self.runtime, self.controls, self.frames, self.stop = runtime, controls, 0, threading.Event()

    def _frames(self) -> None:
        surface = None
        while not self.stop.wait(1 / 30):
            poles = self.runtime.take_poles()
            if poles is not None:
                surface = poles
            if surface is not None:
                s = core.BSplineSurface(np.asarray(surface).reshape(*self.controls, 3), (3, 3))
                s.grid(96, 96)
                self.frames += 1

    def __enter__(self) -> "Load":
        self.hog = multiprocessing.Process(target=_spin, daemon=True)
        self.hog.start()
        self.thread = threading.Thread(target=self._frames, daemon=True)
        self.thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop.set()
        self.thread.join()
        self.hog.terminate()
        self.hog.join()


def run_scene(controls, mesh, sim_dt, seconds, rate, load="none", regional=False, **settings):
    surface = core.patch(controls, (3, 3), mesh, (100.0, 100.0))
    surface.damping_map.set_uniform(5.0)
    surface.regional = regional
    native = trajectory(seconds).native
    runtime = _core.HapticRuntime(surface, native, haptic_rate=rate, sim_dt=sim_dt, log_seconds=seconds + 1,
                                  stop_when_finished=True, **settings)
    cpu0, wall0 = cpu_seconds(), time.perf_counter()
    frames = 0
    if load == "cpu_hog":
        with Load(runtime, controls) as work:
            runtime.start()
            while runtime.running:
                time.sleep(0.05)
            runtime.stop()
        frames = work.frames
    else:
        runtime.start()
        while runtime.running:
            time.sleep(0.05)
        runtime.stop()
    cpu, wall = cpu_seconds() - cpu0, time.perf_counter() - wall0
    status = runtime.status()
    errors = np.asarray(runtime.force_errors(0.05))
    ticks = runtime.ticks()
    periods = np.diff(ticks["t"]) * 1e3
    return {
        "scene": f"{controls[0]}x{controls[1]}/{mesh[0]}x{mesh[1]}" + (" reg" if regional else ""),
        "load": load,
        "overlay_frames": frames,
        "seconds": status["elapsed"],
        "haptic_hz": status["haptic_hz"],
        "haptic_period_p50_ms": status["haptic_period_p50_ms"],
        "haptic_period_p99_ms": status["haptic_period_p99_ms"],
        "haptic_period_max_ms": status["haptic_period_max_ms"],
        "realtime_priority": status["realtime_priority"],
        "realtime_how": status["realtime_how"],
        "latency_p50_ms": status["latency_p50_ms"],
        "latency_p99_ms": status["latency_p99_ms"],
        "sim_hz": status["sim_hz"],
        "sim_dt": sim_dt,
        "dropped_sim_time": status["dropped_sim_time"],
        "doubled_steps": status["doubled_steps"],
        "force_error_rel": float(np.percentile(errors, 99)) if errors.size else None,
        "force_error_rel_median": float(np.median(errors)) if errors.size else None,
        "force_rms": float(np.sqrt(np.mean(np.sum(ticks["rendered_force"] ** 2, axis=1)))),
        "cpu_percent": 100.0 * cpu / wall,
        "strokes": status["strokes"],
        "error": status["error"],
    }, periods, errors


def plot(results, data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for r, (periods, errors) in zip(results, data):
        label = f"{r['scene']}, {r['load']}"
        axes[0].hist(periods, bins=np.linspace(0.5, 2.0, 151), histtype="step", label=label)
        if errors.size:
            s = np.sort(errors)
            axes[1].plot(s, np.linspace(0, 1, s.size), label=label)
    axes[0].set_yscale("log")
    axes[0].set_xlabel("haptic period (ms)")
    axes[0].set_ylabel("ticks")
    axes[0].legend()
    axes[1].set_xscale("log")
    axes[1].set_xlabel("estimated force error / force")
    axes[1].set_ylabel("fraction of ticks")
    axes[1].axvline(0.05, color="r", lw=0.8, ls="--")
    axes[1].legend()
    fig.suptitle("HapticSculpt loops: haptic period and force-estimate error (replay rope stroke)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--rate", type=float, default=1000.0, help="haptic rate (Hz)")
    ap.add_argument("--loads", default="none,cpu_hog", help="which loads to run, of none and cpu_hog")
    ap.add_argument("--spin", type=float, default=None, help="the runtime's spin (s) instead of its default")
    ap.add_argument("--sim-nice", type=int, default=None, help="the runtime's sim_nice instead of its default")
    ap.add_argument("--max-lag", type=float, default=None, help="the runtime's max_lag (s) instead of its default")
    ap.add_argument("--no-catch-up", action="store_true",
                    help="a simulation behind real time drops the backlog instead of taking double steps")
    ap.add_argument("--scenes", default="40,128,256", help="which scenes to run, by mesh side (40, 128, 256)")
    ap.add_argument("--regional", action="store_true", help="also run each scene with regional steps (s.regional)")
    ap.add_argument("--no-realtime", action="store_true",
                    help="do not ask for real-time priority for the haptic thread (sessions ask by default)")
    args = ap.parse_args()
    os.makedirs(os.path.join(ROOT, "bench", "results"), exist_ok=True)
    results, data = [], []
    wanted = {int(m) for m in args.scenes.split(",")}
    for (controls, mesh, sim_dt), regional in [(scene, r) for scene in SCENES if scene[1][0] in wanted
                                               for r in ((False, True) if args.regional else (False,))]:
        for load in args.loads.split(","):
            settings = {k: v for k, v in (("spin", args.spin), ("sim_nice", args.sim_nice), ("max_lag", args.max_lag))
                        if v is not None}
            settings["realtime"] = not args.no_realtime
            settings["catch_up"] = not args.no_catch_up
            r, periods, errors = run_scene(controls, mesh, sim_dt, args.seconds, args.rate, load, regional, **settings)
            results.append(r)
            data.append((periods, errors))
    print(f"{'scene':<14}{'load':>8}{'rt':>3}{'haptic Hz':>10}{'p50 ms':>8}{'p99 ms':>8}{'max ms':>8}{'sim Hz':>9}"
          f"{'dropped s':>10}{'2dt':>7}{'err p99':>9}{'lat p50':>9}{'lat p99':>9}{'cpu %':>7}")
    for r in results:
        err = f"{r['force_error_rel']:>9.2e}" if r["force_error_rel"] is not None else f"{'-':>9}"
        print(f"{r['scene']:<14}{r['load']:>8}{'y' if r['realtime_priority'] else 'n':>3}{r['haptic_hz']:>10.1f}{r['haptic_period_p50_ms']:>8.3f}"
              f"{r['haptic_period_p99_ms']:>8.3f}{r['haptic_period_max_ms']:>8.2f}{r['sim_hz']:>9.0f}"
              f"{r['dropped_sim_time']:>10.2f}{r['doubled_steps']:>7}{err}{r['latency_p50_ms']:>9.4f}{r['latency_p99_ms']:>9.4f}"
              f"{r['cpu_percent']:>7.1f}")
    main_scene = dict(results[0])
    main_scene["scenes"] = results
    main_scene["machine"] = f"{os.cpu_count()} cores"
    # (a run of some scenes, or with regional steps, has files of its own: loops.json's top level
    # is the 12x12/40x40 scene)
    name = "loops" if args.scenes == "40,128,256" and not args.regional else \
        "loops_" + args.scenes.replace(",", "_") + ("_regional" if args.regional else "")
    with open(os.path.join(ROOT, "bench", "results", name + ".json"), "w") as f:
        json.dump(main_scene, f, indent=2)
    plot(results, data, os.path.join(ROOT, "bench", "results", name + ".png"))
    print(f"wrote bench/results/{name}.json, bench/results/{name}.png")


if __name__ == "__main__":
    main()
