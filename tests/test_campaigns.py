"""Campaigns on Dask distributed (bench/campaign.py) give exactly what the serial run gives: the
stress campaign's records on a local cluster of two workers and on a running scheduler, its script's
resume and summary, and clear errors for bad options."""
import dataclasses
import json
import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(ROOT, "bench")
sys.path.insert(0, BENCH)
import campaign  # noqa: E402
from stress_scenes import run_scene  # noqa: E402

distributed = pytest.importorskip("distributed", reason="python3-distributed (make deps installs it)")

#: A few seeds of every integrator (make test's stress test runs 10,000 of them serially).
SEEDS = list(range(700, 708))


def records(pairs):
    return {seed: dataclasses.asdict(r) for seed, r in pairs}


@pytest.fixture(scope="module")
def serial():
    return records((seed, run_scene(seed)) for seed in SEEDS)


def test_a_local_cluster_gives_the_serial_records(serial):
    got = records(campaign.run(run_scene, SEEDS, "stress", workers=2))
    assert got == serial
    assert {r["integrator"] for r in got.values()} == {"explicit", "implicit", "local_global"}


def test_a_running_scheduler_gives_the_serial_records(serial, monkeypatch):
    # Workers started by someone else (here: a cluster of this test) need the checkout on their path.
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(campaign.PATHS))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster:
        got = records(campaign.run(run_scene, SEEDS, "stress", scheduler=cluster.scheduler_address))
    assert got == serial


def test_the_campaign_resumes_and_its_summary_does_not_depend_on_the_workers(tmp_path):
    script = os.path.join(BENCH, "stress_campaign.py")

    def campaign_run(log, out, *extra):
        subprocess.run([sys.executable, script, "--scenes", str(len(SEEDS)), "--first", str(SEEDS[0]), "--log", log,
                        "--out", out, *extra], check=True, capture_output=True, text=True, timeout=600)
        with open(out, encoding="utf-8") as f:
            summary = json.load(f)
        with open(log, encoding="utf-8") as f:
            lines = [json.loads(line) for line in f]
        return summary, lines

    log = str(tmp_path / "dask.jsonl")
    # Half the scenes serially, "interrupted" there; the rest on two workers resumes from the log.
    half, _ = campaign_run(log, str(tmp_path / "half.json"), "--workers", "0", "--scenes", str(len(SEEDS) // 2))
    assert half["complete"] and half["scenes"] == len(SEEDS) // 2
    dask, lines = campaign_run(log, str(tmp_path / "dask.json"), "--workers", "2")
    assert sorted(r["seed"] for r in lines) == SEEDS  # each scene once: the finished half was not rerun
    serial, _ = campaign_run(str(tmp_path / "serial.jsonl"), str(tmp_path / "serial.json"), "--workers", "0")
    assert dask["complete"] and serial["complete"]
    assert dask["ran_on"].startswith("Dask LocalCluster, 2 workers") and serial["ran_on"] == "serial (no Dask)"
    for key in ("per_integrator", "failures", "scenes", "first_seed"):
        assert dask[key] == serial[key]


@pytest.mark.parametrize("kwargs, match", [
    ({"workers": -1}, "workers"),
    ({"workers": 2, "scheduler": "tcp://127.0.0.1:8786"}, "workers"),
    ({"scheduler": "127.0.0.1:8786"}, "scheduler"),
])
def test_bad_options_are_refused_by_name(kwargs, match):
    with pytest.raises(ValueError, match=match):
        list(campaign.run(run_scene, SEEDS, "stress", **kwargs))


def test_a_batch_replay_on_dask_equals_the_serial_one(tmp_path):
    """The default stroke replayed in FreeCAD console mode onto two parts: the records (all but the
    wall time) and the STEP files are the same on two workers as in order here."""
    parts = tmp_path / "parts.json"
    parts.write_text(json.dumps([{"name": "clay_free", "controls": [6, 6], "mesh": [16, 16]},
                                 {"name": "elastic_held", "controls": [6, 6], "mesh": [16, 16], "material": "elastic",
                                  "edges": "held", "bending": 0}]))
    runs = {}
    for workers in ("2", "0"):
        out = tmp_path / f"workers{workers}"
        subprocess.run([sys.executable, os.path.join(BENCH, "batch_replay.py"), "--parts", str(parts), "--out", str(out),
                        "--seconds", "0.8", "--workers", workers], check=True, capture_output=True, text=True, timeout=600)
        with open(out / "batch_replay.json", encoding="utf-8") as f:
            runs[workers] = [{k: v for k, v in r.items() if k != "wall_seconds"} for r in json.load(f)["parts"]]
        for name in ("clay_free", "elastic_held"):
            for ext in ("step", "FCStd", "png"):
                assert (out / f"{name}.{ext}").stat().st_size > 0
    assert runs["2"] == runs["0"]
    free, held = runs["0"]
    assert free["steps"] == held["steps"] == 800 and free["refused"] == held["refused"] == 0
    assert free["step_faces"] == held["step_faces"] == 1
    assert held["lift_mm"] > 0.1  # the stroke moved the part (an elastic held sheet springs most of it back)
    assert (tmp_path / "workers0" / "clay_free.step").read_bytes().count(b"B_SPLINE_SURFACE") >= 1


def test_a_batch_replay_refuses_bad_parts():
    import batch_replay
    for parts, match in (([], "parts"), ([{"controls": [6, 6]}], "name"), ([{"name": "a", "colour": 1}], "unknown"),
                         ([{"name": "a"}, {"name": "a"}], "unique"), ([{"name": "a/b"}], "letters")):
        with pytest.raises(ValueError, match=match):
            batch_replay.checked_parts(parts)
