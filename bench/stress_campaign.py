#!/usr/bin/env python3
"""The long stability campaign behind `make stress`: many more seeded random extreme scenes than
`make test` runs (tests/stress_scenes.py says what a scene is and what it must show).

Each finished scene is appended to a JSON-lines file at once, so Ctrl-C loses nothing and a rerun
resumes where it stopped (a log written by another build of the core is moved aside instead:
`<log>.core` holds the build's SHA-256). The summary (per integrator: scenes, steps, steps the energy guard or the
NaN guard refused, failures with their seeds) is printed and written to
bench/results/stress_campaign.json. Exit status 1 if any scene failed.

The scenes run as tasks on Dask distributed (campaign.py: a local cluster over all cores by default,
--workers N, or --scheduler tcp://HOST:PORT for a cluster of machines; --workers 0 runs them here in
order). A scene is seeded, so its record is the same whichever worker runs it and in whatever order;
the log holds them in the order they finished, the summary does not depend on it.

    python3 bench/stress_campaign.py --scenes 100000 [--first 10000] [--log build/stress/campaign.jsonl]
                                     [--workers N | --scheduler tcp://HOST:PORT]
"""
from __future__ import annotations

import argparse
import collections
import dataclasses
import hashlib
import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.dirname(os.path.abspath(__file__))]
import campaign  # noqa: E402
from stress_scenes import run_scene  # noqa: E402


def core_fingerprint() -> str:
    """SHA-256 of the native core the scenes run on: a log from another build is not resumed."""
    from HapticSculpt.core import native as _core
    with open(_core.__file__, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def start_log(log: str) -> None:
    """Keeps `log` only if it was written by this build of the core; otherwise moves it aside (its
    results would not describe this core) and starts afresh."""
    stamp, current = log + ".core", core_fingerprint()
    previous = open(stamp, encoding="utf-8").read().strip() if os.path.exists(stamp) else None
    if os.path.exists(log) and previous != current:
        aside = f"{log}.{(previous or 'unknown')[:12]}"
        os.replace(log, aside)
        print(f"the log was written by another build of the core: moved to {aside}; starting afresh", file=sys.stderr)
    with open(stamp, "w", encoding="utf-8") as f:
        f.write(current + "\n")


def done_seeds(log: str) -> set[int]:
    if not os.path.exists(log):
        return set()
    with open(log, encoding="utf-8") as f:
        return {json.loads(line)["seed"] for line in f if line.strip()}


def summarise(log: str, first: int, scenes: int) -> dict:
    per: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
    failures = []
    with open(log, encoding="utf-8") as f:
        for line in f:
            r = json.loads(line)
            if not first <= r["seed"] < first + scenes:
                continue
            c = per[r["integrator"]]
            c["scenes"] += 1
            c["steps"] += r["steps"]
            c["refused_steps"] += r["refused_steps"]
            c["energy_limited_steps"] += r["energy_limited_steps"]
            c["verlet_steps"] += r.get("verlet_steps", 0)
            c["invalid_inputs_refused"] += r["invalid_inputs_refused"]
            if r["failure"]:
                c["failures"] += 1
                failures.append({"seed": r["seed"], "integrator": r["integrator"], "failure": r["failure"]})
    return {"first_seed": first, "scenes": scenes, "per_integrator": {k: dict(v) for k, v in sorted(per.items())},
            "failures": failures}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", type=int, default=100_000)
    ap.add_argument("--first", type=int, default=10_000, help="first seed (make test covers 0..3999 on the host)")
    ap.add_argument("--log", default=os.path.join(ROOT, "build", "stress", "campaign.jsonl"))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "stress_campaign.json"))
    campaign.add_arguments(ap)
    a = ap.parse_args()
    os.makedirs(os.path.dirname(a.log), exist_ok=True)
    start_log(a.log)
    todo = [s for s in range(a.first, a.first + a.scenes) if s not in done_seeds(a.log)]
    interrupted = False
    try:
        with open(a.log, "a", encoding="utf-8") as log:
            for seed, r in campaign.run(run_scene, todo, "stress", a.workers, a.scheduler):
                log.write(json.dumps(dataclasses.asdict(r)) + "\n")
                log.flush()
                if not r.ok:
                    print(f"\nFAILED seed {seed}: {r.failure}", file=sys.stderr)
    except KeyboardInterrupt:
        interrupted = True
        print("\ninterrupted: finished scenes are kept in the log; rerun to resume", file=sys.stderr)
    summary = summarise(a.log, a.first, a.scenes)
    summary["ran_on"] = campaign.describe(a.workers, a.scheduler)
    summary["complete"] = not interrupted and sum(c["scenes"] for c in summary["per_integrator"].values()) == a.scenes
    print(f"{'integrator':<14}{'scenes':>9}{'steps':>10}{'verlet':>10}{'refused':>10}{'energy guard':>14}"
          f"{'invalid refused':>17}{'failures':>10}")
    for k, c in summary["per_integrator"].items():
        print(f"{k:<14}{c['scenes']:>9}{c['steps']:>10}{c['verlet_steps']:>10}{c['refused_steps']:>10}"
              f"{c['energy_limited_steps']:>14}{c['invalid_inputs_refused']:>17}{c.get('failures', 0):>10}")
    for f in summary["failures"][:20]:
        print(f"seed {f['seed']} ({f['integrator']}): {f['failure']}")
    with open(a.out, "w", encoding="utf-8") as f:
        json.dump(summary, f, indent=1)
    return 1 if summary["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
