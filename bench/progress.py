"""A text progress bar for long benchmark and campaign runs (stderr, so tables on stdout stay clean).

Used as an iterator wrapper: `for item in progress(items, "label"):`. It redraws at most ten times a
second and shows done/total, rate and time left; on a terminal it redraws in place, elsewhere (CI
logs) it prints a line every tenth of the run.
"""
from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")


def progress(items: Iterable[T], label: str, total: int | None = None, width: int = 30) -> Iterator[T]:
    """Yield from `items`, drawing a progress bar on stderr."""
    seq = list(items) if total is None else items
    n = len(seq) if total is None else total  # type: ignore[arg-type]
    tty = sys.stderr.isatty()
    start = last = time.monotonic()
    last_tenth = -1

    def draw(done: int) -> None:
        elapsed = time.monotonic() - start
        rate = done / elapsed if elapsed > 0 else 0.0
        left = (n - done) / rate if rate > 0 else float("nan")
        filled = int(width * done / n) if n else width
        line = (f"{label} [{'#' * filled}{'.' * (width - filled)}] {done}/{n} "
                f"{rate:.1f}/s, {elapsed:.0f} s, ~{left:.0f} s left")
        sys.stderr.write(("\r" + line) if tty else (line + "\n"))
        sys.stderr.flush()

    done = 0
    for item in seq:
        yield item
        done += 1
        now = time.monotonic()
        tenth = 10 * done // max(n, 1)
        if (tty and now - last > 0.1) or (not tty and tenth != last_tenth) or done == n:
            draw(done)
            last, last_tenth = now, tenth
    if tty:
        sys.stderr.write("\n")
