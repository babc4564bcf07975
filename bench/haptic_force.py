#!/usr/bin/env python3
"""The force a designer feels against the exact one (issue 49 item 1): a threaded session (haptic
loop at 1 kHz, simulation as fast as it goes) renders a rope stroke on a flat patch sampled m x m
(m/4 x m/4 controls, 100 mm, as bench/loops.py); the same stroke simulated at the haptic rate
(one 1 ms step per tick, each tick rendered from the state of that instant) gives the exact force.
Error per tick: |rendered before the safety layer - exact| / max(|exact|, 5 % of the stroke's
largest exact force); p99 over the ticks while grabbed.

Each size runs threaded idle and under load (a process spinning on the other core and an overlay's
frame work in this one, as bench/loops.py's cpu_hog), and on a virtual clock (the same loops,
deterministic: runtime/multirate_replay.hpp) where a step costs what it cost here, or --costs ms,
or where exact states reach the haptic loop --latencies ms late (what the haptic loop's estimate
alone gets wrong), all in the same run. Beside the error: what a step costs, the simulated time
dropped, the steps of twice the length taken to keep pace, the age of the state each grabbed tick
rendered from (p50/p99), and the haptic period p99.

--tools: the rope (default), the magnet, and the rope with a point constraint 15 mm beside where
it grabs (a held point the pull goes past), each against its own exact force.

Prints a table and writes bench/results/haptic_force.json and haptic_force.png.

    /usr/bin/python3 bench/haptic_force.py [--sizes 64 128 256] [--seconds 3] [--loads none,cpu_hog]
                                           [--costs MS ...] [--latencies MS ...] [--tools rope magnet rope+point]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "bench")]
from HapticSculpt import core  # noqa: E402
from HapticSculpt.core import native as _core  # noqa: E402
from HapticSculpt.runtime.replay_device import ReplayDevice  # noqa: E402
from loops import Load  # noqa: E402

HAPTIC_RATE = 1000.0
FLOOR = 0.05


def trajectory(seconds: float) -> ReplayDevice:
    """A rope stroke as a designer makes one: the cursor rests on the surface, grabs there, pulls up
    and around, and lets go 0.2 s before the end. (One grab: where a later grab ties the rope is the
    mesh point nearest the cursor on a surface the earlier stroke shaped, which a step's rounding
    can change, and a rope tied elsewhere is another stroke, not an error of the force.)"""
    t = np.arange(0.0, seconds + 1e-9, 1e-3)
    tau = np.clip(t - 0.1, 0.0, None)
    xyz = np.column_stack([12.3 + 8 * np.sin(1.3 * tau), -7.1 + 6 * np.sin(0.9 * tau),
                           14 * np.sin(1.2 * tau) ** 2 + 4 * tau])
    buttons = ((t >= 0.05) & (t < seconds - 0.2)).astype(int)
    return ReplayDevice(t, xyz, buttons=buttons)


#: What the hand pulls with: a tool, or the rope with a point constraint 15 mm beside where it grabs
#: (a held point the pull goes past, as the issue's "point constraint pulled through").
TOOLS = ("rope", "magnet", "rope+point")


def make_surface(mesh: int, tool: str = "rope"):
    """bench/loops.py's scene: a flat 100 mm patch, m/4 x m/4 controls, damping 5, with `tool`."""
    surface = core.patch((mesh // 4, mesh // 4), (3, 3), (mesh, mesh), (100.0, 100.0))
    surface.damping_map.set_uniform(5.0)
    surface.set_tool(tool.split("+")[0])
    if tool.endswith("+point"):
        surface.add_constraint("point", near=[12.3 + 15.0, -7.1, 0.0])
    return surface


def pressed(device: ReplayDevice, t: np.ndarray) -> np.ndarray:
    """Whether the grab button is down at each time (buttons hold from the sample before)."""
    times, _, _, buttons = device.arrays()
    return (buttons[np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 1)] & 1) == 1


def reference(mesh: int, device: ReplayDevice, seconds: float, tool: str) -> dict:
    """The exact force: the stroke simulated at the haptic rate, each tick rendered from the state
    of that instant (a virtual clock on which a step costs nothing); and what a step costs here."""
    start = time.perf_counter()
    r = _core.replay_multirate(make_surface(mesh, tool), device.native, seconds, HAPTIC_RATE, 1.0 / HAPTIC_RATE, 0.0)
    r["step_cost"] = (time.perf_counter() - start) / r["steps"]
    return r


def errors(device: ReplayDevice, ref: dict, t: np.ndarray, force: np.ndarray) -> np.ndarray:
    """Per grabbed tick: |force - exact| / max(|exact|, FLOOR * the stroke's largest |exact|)."""
    exact = np.column_stack([np.interp(t, ref["t"], ref["estimated_force"][:, c]) for c in range(3)])
    magnitude = np.linalg.norm(exact, axis=1)
    floor = FLOOR * max(float(np.linalg.norm(ref["estimated_force"], axis=1).max()), 1e-12)
    inside = pressed(device, t) & (t <= ref["t"][-1])
    return (np.linalg.norm(force - exact, axis=1) / np.maximum(magnitude, floor))[inside]


def virtual(mesh: int, tool: str, device: ReplayDevice, seconds: float, cost: float, latency: float = 0.0) -> dict:
    """The loops on a virtual clock where a step costs `cost` s and its state reaches the haptic
    loop `latency` s after (runtime/multirate_replay.hpp)."""
    return _core.replay_multirate(make_surface(mesh, tool), device.native, seconds, HAPTIC_RATE, 1.0 / HAPTIC_RATE,
                                  cost, latency=latency)


def threaded(mesh: int, tool: str, device: ReplayDevice, seconds: float, load: str) -> dict:
    """The session as a designer has it: its ticks (cursor, buttons, estimated force) and status."""
    runtime = _core.HapticRuntime(make_surface(mesh, tool), device.native, haptic_rate=HAPTIC_RATE, sim_dt=1.0 / HAPTIC_RATE,
                                  log_seconds=seconds + 1, stop_when_finished=True)
    if load == "cpu_hog":
        with Load(runtime, (mesh // 4, mesh // 4)):
            runtime.start()
            while runtime.running:
                time.sleep(0.05)
            runtime.stop()
    else:
        runtime.start()
        while runtime.running:
            time.sleep(0.05)
        runtime.stop()
    ticks = runtime.ticks()
    status = runtime.status()
    ticks.update(dropped_sim_time=status["dropped_sim_time"], doubled_steps=status["doubled_steps"],
                 sim_hz=status["sim_hz"])
    return ticks


def row(mesh: int, tool: str, how: str, device: ReplayDevice, ref: dict, run: dict) -> tuple[dict, np.ndarray]:
    t = run["t"]
    err = errors(device, ref, t, run["estimated_force"])
    grabbed = pressed(device, t)
    ages = (t - run["state_time"])[grabbed]
    return {
        "mesh": mesh, "controls": mesh // 4, "tool": tool, "run": how, "step_cost_ms": ref["step_cost"] * 1e3,
        "dropped_sim_s": float(run["dropped_sim_time"]), "doubled_steps": int(run["doubled_steps"]),
        "age_p50_ms": float(np.percentile(ages, 50) * 1e3), "age_p99_ms": float(np.percentile(ages, 99) * 1e3),
        "haptic_period_p99_ms": float(np.percentile(np.diff(t), 99) * 1e3),
        "force_error_p50": float(np.median(err)), "force_error_p99": float(np.percentile(err, 99)),
    }, err


def plot(rows: list[dict], data: list[np.ndarray], path: str) -> None:
    """Left: the loops as they run (threaded, and on the virtual clock at the step's own cost);
    right: exact states reaching the haptic loop late. A colour per size."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    sizes = sorted({r["mesh"] for r in rows})
    colour = {m: f"C{i}" for i, m in enumerate(sizes)}
    styles = {"threaded none": "-", "threaded cpu_hog": "--"}
    for r, err in zip(rows, data):
        late = r["run"].startswith("late")
        ax = axes[1] if late else axes[0]
        style = (":" if "2 ms" in r["run"] else "-." if "8 ms" in r["run"] else "-") if late else styles.get(r["run"], ":")
        s = np.sort(err)
        ax.plot(np.maximum(s, 1e-6), np.linspace(0, 1, s.size), color=colour[r["mesh"]], ls=style,
                label=f"{r['mesh']}², {r['tool']}, {r['run']}")
    for ax, title in zip(axes, ("as the loops run (virtual: a step costs what it did here)",
                                "exact states reaching the haptic loop late")):
        ax.set_xscale("log")
        ax.axvline(0.05, color="r", lw=0.8, ls="--")
        ax.set_xlabel("|rendered - exact| / force")
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=7)
    axes[0].set_ylabel("fraction of grabbed ticks")
    fig.suptitle("A stroke: the rendered force against the stroke simulated at 1 kHz")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[64, 128, 256])
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--loads", default="none,cpu_hog", help="threaded runs: none, cpu_hog (empty: none)")
    ap.add_argument("--costs", type=float, nargs="*", default=[],
                    help="also on the virtual clock with steps costing these ms (beside each size's own cost)")
    ap.add_argument("--latencies", type=float, nargs="*", default=[],
                    help="also on the virtual clock with exact states reaching the haptic loop these ms late")
    ap.add_argument("--tools", nargs="+", default=["rope"], choices=TOOLS, help="what the hand pulls with")
    ap.add_argument("--name", default="haptic_force", help="results file name (bench/results/NAME.json, .png)")
    args = ap.parse_args()
    device = trajectory(args.seconds)
    rows, data = [], []
    print(f"{'mesh':>5} {'tool':>10} {'run':>16} {'step ms':>8} {'dropped s':>9} {'2dt':>5} {'age p50':>8} {'age p99':>8} "
          f"{'period p99':>10} {'err p50':>8} {'err p99':>8}", flush=True)

    def show(r: dict, err: np.ndarray) -> None:
        rows.append(r)
        data.append(err)
        print(f"{r['mesh']:>4}² {r['tool']:>10} {r['run']:>16} {r['step_cost_ms']:>8.3f} {r['dropped_sim_s']:>9.2f} {r['doubled_steps']:>5} "
              f"{r['age_p50_ms']:>6.1f}ms {r['age_p99_ms']:>6.1f}ms {r['haptic_period_p99_ms']:>8.3f}ms "
              f"{r['force_error_p50']:>8.2%} {r['force_error_p99']:>8.2%}", flush=True)

    for mesh in args.sizes:
        for tool in args.tools:
            ref = reference(mesh, device, args.seconds, tool)
            for cost in [ref["step_cost"]] + [c * 1e-3 for c in args.costs]:
                show(*row(mesh, tool, f"virtual {cost * 1e3:.2f} ms", device, ref,
                          virtual(mesh, tool, device, args.seconds, cost)))
            for late in args.latencies:
                show(*row(mesh, tool, f"late {late:g} ms", device, ref,
                          virtual(mesh, tool, device, args.seconds, 0.0, late * 1e-3)))
            for load in [x for x in args.loads.split(",") if x]:
                show(*row(mesh, tool, f"threaded {load}", device, ref, threaded(mesh, tool, device, args.seconds, load)))
    out = os.path.join(ROOT, "bench", "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, args.name + ".json"), "w", encoding="utf-8") as f:
        json.dump({"rows": rows, "machine": f"{os.cpu_count()} cores"}, f, indent=1)
    plot(rows, data, os.path.join(out, args.name + ".png"))
    print(f"wrote bench/results/{args.name}.json, bench/results/{args.name}.png")


if __name__ == "__main__":
    main()
