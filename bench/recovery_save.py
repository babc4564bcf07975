#!/usr/bin/env python3
"""What a release costs for crash recovery (issue 47): after each commit a session makes, the GUI
writes the document's recovery file (HapticSculpt/gui/recovery_file.py) on FreeCAD's GUI thread.
Here the same write in console mode (FreeCAD's document without its GUI part: the GUI test prints
the whole write, 30-50 ms measured under make test's load) on a flat 100 mm sculpt of m x m mass
points (40: the GUI's New patch; 64, 128, 256; controls m / 4) after three strokes, alone and with
a process spinning on the other core. Median of REPEAT; prints a table, writes
bench/results/recovery_save.json and recovery_save.png.

    PYTHONPATH=/usr/lib/freecad-python3/lib /usr/bin/python3 bench/recovery_save.py
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, "/usr/lib/freecad-python3/lib"]
import FreeCAD  # noqa: E402

import HapticSculpt as hs  # noqa: E402
from HapticSculpt.gui import recovery_file  # noqa: E402

REPEAT = 7
SIZES = (40, 64, 128, 256)


def median_ms(doc) -> float:
    """Median milliseconds of one recovery write of ``doc`` over REPEAT writes."""
    runs = []
    for _ in range(REPEAT):
        start = time.perf_counter()
        recovery_file.write(doc)
        runs.append(time.perf_counter() - start)
    return 1e3 * float(np.median(runs))


def main() -> None:
    rows = []
    print(f"writing the recovery file after a release (median of {REPEAT}, console mode)")
    print(f"{'mesh':>6}{'controls':>10}{'KiB':>8}{'alone ms':>10}{'hog ms':>8}{'ratio':>7}")
    for m in SIZES:
        doc = FreeCAD.newDocument(f"Bench{m}")
        obj = hs.make_sculpt(doc, controls=(m // 4, m // 4), mesh=(m, m))
        for k in range(3):
            hs.run(obj, 0.05, device=hs.ReplayDevice.stroke((10.0 * (k - 1), 0.0, 0.0), (10.0 * (k - 1), 0.0, 5.0),
                                                            seconds=0.05), tool="rope")
        alone = median_ms(doc)
        hog = subprocess.Popen([sys.executable, "-c", "while True: pass"])
        try:
            loaded = median_ms(doc)
        finally:
            hog.kill()
            hog.wait()
        size = os.path.getsize(os.path.join(doc.TransientDir, "fc_recovery_file.fcstd")) / 1024
        rows.append({"mesh": m, "controls": m // 4, "kib": size, "alone_ms": alone, "cpu_hog_ms": loaded})
        print(f"{m:>6}{m // 4:>10}{size:>8.0f}{alone:>10.1f}{loaded:>8.1f}{loaded / alone:>7.2f}")
        FreeCAD.closeDocument(doc.Name)
    out = os.path.join(ROOT, "bench", "results")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "recovery_save.json"), "w") as f:
        json.dump({"rows": rows, "repeat": REPEAT, "mode": "console"}, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for key, label in (("alone_ms", "alone"), ("cpu_hog_ms", "a process spinning on the other core")):
        ax.plot([r["mesh"] for r in rows], [r[key] for r in rows], "-o", label=label)
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("mass points per side")
    ax.set_ylabel("ms per recovery write (one release)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "recovery_save.png"), dpi=100)
    print("wrote bench/results/recovery_save.json and recovery_save.png")


if __name__ == "__main__":
    main()
