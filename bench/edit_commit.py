#!/usr/bin/env python3
"""What committing an edit costs (issue 28): a slider release (``set_uniform``: one material map
changed), a tool setting (``set_tool``) and a short stroke (``run``: 20 steps, then the commit of
poles, velocities, rest lengths and bending reference) on a flat 100 mm sculpt of m x m mass points (64, 128, 256;
controls m / 4), each as one undo step in a real FreeCAD document, console mode. Two ways to find
what changed, in the same run: "compare" (the live surface compares the new state with what it
last wrote: what an edit does) and "read back" (every state property read back from the document
first: what each edit did before, minus its second read). Median of REPEAT; one run on this
machine: prints a table, writes bench/results/edit_commit.json and edit_commit.png.

    PYTHONPATH=/usr/lib/freecad-python3/lib /usr/bin/python3 bench/edit_commit.py
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, "/usr/lib/freecad-python3/lib"]
import FreeCAD  # noqa: E402

import HapticSculpt as hs  # noqa: E402

REPEAT = 7
SIZES = (64, 128, 256)


def timed(obj, edit, read_back: bool) -> float:
    """Median seconds of ``edit(k)`` (each one undo step) over REPEAT runs."""
    runs = []
    for k in range(REPEAT):
        if read_back:
            obj.Proxy.live.property_written()  # (as if written from outside: the commit reads them back)
        t0 = time.perf_counter()
        edit(k)
        runs.append(time.perf_counter() - t0)
    return float(np.median(runs))


def main() -> None:
    edits = {
        "slider release": lambda obj, k: hs.set_uniform(obj, "stiffness", 100.0 + k),
        "tool setting": lambda obj, k: hs.set_tool(obj, "magnet", radius=10.0 + k),
        "short stroke": lambda obj, k: hs.run(obj, 0.02, device=hs.ReplayDevice.stroke(
            (0.0, 0.0, 0.0), (0.0, 0.0, 2.0 + k), seconds=0.02), tool="rope"),
    }
    rows = []
    print(f"committing an edit (median of {REPEAT}, ms)")
    print(f"{'mesh':>6}{'edit':>16}{'compare':>10}{'read back':>11}{'ratio':>7}")
    for m in SIZES:
        doc = FreeCAD.newDocument(f"Bench{m}")
        doc.UndoMode = 1
        obj = hs.make_sculpt(doc, controls=(m // 4, m // 4), mesh=(m, m))
        hs.set_uniform(obj, "stiffness", 99.0)  # (the first commit reads the document once)
        for name, edit in edits.items():
            fast = timed(obj, lambda k: edit(obj, k), False)
            slow = timed(obj, lambda k: edit(obj, k), True)
            rows.append({"mesh": m, "edit": name, "compare_ms": 1e3 * fast, "read_back_ms": 1e3 * slow})
            print(f"{m:>6}{name:>16}{1e3 * fast:>10.2f}{1e3 * slow:>11.2f}{slow / fast:>7.1f}")
        FreeCAD.closeDocument(doc.Name)
    out = os.path.join(ROOT, "bench", "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "edit_commit.json"), "w") as f:
        json.dump({"rows": rows, "repeat": REPEAT}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for name in edits:
        for key, style in (("compare_ms", "-o"), ("read_back_ms", "--x")):
            pts = [(r["mesh"], r[key]) for r in rows if r["edit"] == name]
            ax.plot(*zip(*pts), style, label=f"{name}, {key.removesuffix('_ms').replace('_', ' ')}")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("mass points per side")
    ax.set_ylabel("ms per edit (one undo step)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "edit_commit.png"), dpi=100)
    print("wrote bench/results/edit_commit.json and edit_commit.png")


if __name__ == "__main__":
    main()
