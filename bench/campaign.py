"""Campaigns on Dask distributed: the stress campaign, the time-vs-error sweep and the batch replay
run their scenes as tasks of one function on a Dask cluster, never on a home-made pool.

By default a LocalCluster of one single-threaded worker process per core runs on this machine;
``--workers N`` sets the count, and ``--scheduler tcp://HOST:PORT`` sends the tasks to a running
scheduler instead, whose workers may be other machines (each started from a checkout of the same
commit with its core built, e.g. ``PYTHONPATH=$PWD:$PWD/bench:$PWD/tests dask worker
tcp://HOST:PORT --nthreads 1``). ``--workers 0`` runs the tasks here, one after the other, without
Dask (the serial run the distributed one must equal).

A task is a plain function of one argument, importable by name from a module of bench/ or tests/
(the workers import it; the scenes are seeded, so a task's result does not depend on the worker
that ran it or the order). Results come back as they finish, each with its argument, so a
campaign can record each at once and resume after Ctrl-C.
"""
from __future__ import annotations

import argparse
import os
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

from progress import progress

A = TypeVar("A")
R = TypeVar("R")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: What a worker needs on its path to import the tasks: the checkout (the package and its core),
#: bench/ and tests/ (the scenes).
PATHS = [ROOT, os.path.join(ROOT, "bench"), os.path.join(ROOT, "tests")]


def add_arguments(ap: argparse.ArgumentParser) -> None:
    """The options every campaign takes: --workers and --scheduler."""
    ap.add_argument("--workers", type=int, default=None,
                    help="worker processes of the local cluster (default: one per core; 0: no Dask, here, in order)")
    ap.add_argument("--scheduler", default=None,
                    help="address of a running Dask scheduler (tcp://HOST:PORT) to run the tasks on instead")


def _check(workers: int | None, scheduler: str | None) -> None:
    if workers is not None and (not isinstance(workers, int) or workers < 0):
        raise ValueError(f"workers: a count >= 0, got {workers!r}")
    if scheduler is not None and workers is not None:
        raise ValueError("workers: give either a worker count (a local cluster) or a scheduler, not both")
    if scheduler is not None and not str(scheduler).startswith(("tcp://", "tls://", "inproc://", "ws://", "wss://")):
        raise ValueError(f"scheduler: an address such as tcp://HOST:8786, got {scheduler!r}")


def run(task: Callable[[A], R], args: Iterable[A], label: str, workers: int | None = None,
        scheduler: str | None = None) -> Iterator[tuple[A, R]]:
    """Runs ``task`` on each of ``args`` and yields ``(arg, result)`` as each finishes (in order of
    completion), drawing a progress bar labelled ``label``. A task that raises re-raises here. On
    Ctrl-C (or when the caller stops iterating) the cluster is shut down and unfinished tasks are
    dropped."""
    _check(workers, scheduler)
    todo = list(args)
    if workers == 0:
        for a in progress(todo, label, total=len(todo)):
            yield a, task(a)
        return
    if not todo:
        return
    from distributed import Client, LocalCluster, as_completed  # (only campaigns need Dask)
    # Worker processes inherit the environment: the same paths, and one thread per library.
    os.environ["PYTHONPATH"] = os.pathsep.join(PATHS + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    if scheduler is not None:
        cluster = None
        client = Client(scheduler)
    else:
        n = workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=40)
        client = Client(cluster)
    try:
        futures = {client.submit(task, a, pure=False): a for a in todo}
        for future in progress(as_completed(futures), label, total=len(futures)):
            yield futures[future], future.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def describe(workers: int | None, scheduler: str | None) -> str:
    """Where the tasks run, for a campaign's report."""
    if workers == 0:
        return "serial (no Dask)"
    if scheduler is not None:
        return f"Dask scheduler {scheduler}"
    return f"Dask LocalCluster, {workers or os.cpu_count() or 1} workers"
