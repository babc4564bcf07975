"""Where a `make test` run's time went, read from its log: each part's seconds, by Debian (FreeCAD).

    make test 2>&1 | tee test.log
    python3 tools/test_times.py test.log [--json]

Each part of make test runs under tools/timed, which frames it with a start line and an end line
carrying the clock; parts that ran side by side (the lanes of make test) overlap in the table's
"from" and "to" columns, seconds since the run's first part started. The total is the wall time
from the first start to the last end, not the sum of the parts. The table ends with the parts that
failed and the lines of theirs that say what failed (a CI log often keeps only its tail).
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from dataclasses import asdict, dataclass, field

PREFIX = re.compile(r"\[(\S+) (\S+)\] ")  # tools/timed's in make test's lanes
START = re.compile(r"== \[part\] (\S+) (\S+): start ([0-9.]+)")
#: A line of a part that says what failed: pytest's summary, FreeCAD's runner, make, a compiler.
FAILURE = re.compile(r"^(FAILED |ERROR |FAIL:|ERROR:|make(\[\d+\])?: \*\*\*|.*: error: |.*Timeout|.*Error: )")
#: How many of a failed part's lines to show.
FAILURE_LINES = 12
END = re.compile(r"== \[part\] (\S+) (\S+): (\d+) s,(?: CPU (\d+) s,)? exit (\d+) \(([0-9.]+)\)")
#: The FreeCAD each Debian has (the roots' and the hosts').
FREECAD = {"bookworm": "0.20.2", "trixie": "1.0.0", "forky": "1.1.3"}


@dataclass
class Part:
    suite: str
    name: str
    start: float
    end: float | None = None
    exit: int | None = None
    cpu: float | None = None  # user + system seconds, on any core
    failures: list[str] = field(default_factory=list)  # its lines that say what failed

    @property
    def seconds(self) -> float | None:
        return None if self.end is None else self.end - self.start


def parts_of(lines) -> list[Part]:
    """The parts in a log, in the order they started; a part with no end line (the run stopped in
    it) has ``end`` None."""
    parts: list[Part] = []
    open_parts: dict[tuple[str, str], Part] = {}
    for line in lines:
        if m := PREFIX.match(line):
            said = line[m.end():].rstrip("\n")
            part = open_parts.get((m[1], m[2]))
            if part is not None and FAILURE.match(said) and len(part.failures) < FAILURE_LINES:
                part.failures.append(said)
        if m := START.search(line):
            part = Part(m[1], m[2], float(m[3]))
            parts.append(part)
            open_parts[(part.suite, part.name)] = part
        elif m := END.search(line):
            part = open_parts.pop((m[1], m[2]), None)
            if part is not None:
                part.end, part.exit = float(m[6]), int(m[5])
                part.cpu = None if m[4] is None else float(m[4])
    return parts


def table(parts: list[Part]) -> str:
    """The parts as a text table, then the run's wall time and each suite's busy time."""
    if not parts:
        return "no timed parts in this log (make test prints them through tools/timed)"
    t0 = min(p.start for p in parts)
    rows = [("Debian (FreeCAD)", "part", "seconds", "CPU s", "from", "to", "exit")]
    for p in parts:
        rows.append((f"{p.suite} ({FREECAD.get(p.suite, '?')})", p.name,
                     "-" if p.seconds is None else f"{p.seconds:.0f}", "-" if p.cpu is None else f"{p.cpu:.0f}",
                     f"{p.start - t0:.0f}",
                     "running" if p.end is None else f"{p.end - t0:.0f}", "" if p.exit is None else str(p.exit)))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    out = ["  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths))) for r in rows]
    out.insert(1, "  ".join("-" * w for w in widths))
    ends = [p.end for p in parts if p.end is not None]
    if ends:
        out.append(f"\nwall time: {max(ends) - t0:.0f} s from the first part's start to the last part's end")
        outer = [p for p in parts if p.cpu is not None and not any(q is not p and q.suite == p.suite and q.end is not None
                                                                    and q.start <= p.start and p.end <= q.end
                                                                    for q in parts)]
        if outer:
            out.append(f"CPU time: {sum(p.cpu for p in outer):.0f} s in all (the parts not inside another)")
    for suite in dict.fromkeys(p.suite for p in parts):
        done = [p for p in parts if p.suite == suite and p.seconds is not None]
        out.append(f"  {suite}: busy {busy(done):.0f} s ({len(done)} parts; a part inside another counts once)")
    for p in parts:
        if p.exit not in (0, None) or p.end is None:
            out.append(f"\nFAILED: {p.suite} {p.name} ({'did not end' if p.end is None else f'exit {p.exit}'})")
            out += [f"  {line}" for line in p.failures] or ["  (no line of it says what failed: read its lines in the log)"]
    return "\n".join(out)


def busy(parts: list[Part]) -> float:
    """Seconds in which at least one of ``parts`` ran (the union of their spans)."""
    total, reach = 0.0, float("-inf")
    for p in sorted(parts, key=lambda p: p.start):
        if p.end > reach:
            total += p.end - max(p.start, reach)
            reach = p.end
    return total


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("log", nargs="?", default="-", help="a make test log (default: standard input)")
    parser.add_argument("--json", action="store_true", help="the parts as JSON instead of a table")
    args = parser.parse_args(argv)
    lines = sys.stdin if args.log == "-" else open(args.log, encoding="utf-8", errors="replace")
    with lines:
        parts = parts_of(lines)
    if args.json:
        print(json.dumps([asdict(p) | {"seconds": p.seconds} for p in parts], indent=1))
    else:
        print(table(parts))
    return 0 if all(p.exit in (0, None) for p in parts) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
