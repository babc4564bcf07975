#!/usr/bin/env python3
"""Runs the core's Windows build under Wine (make test-windows, issue 50): the GoogleTest suite and
the fuzz replay drivers over the recorded fixtures, as ctest runs them on Linux, and measures the
haptic loop's period there (loop_period.exe: the priority granted, p50 and p99). Then names every
test the Linux build has and the Windows one does not, each with why (NOT_ON_WINDOWS), and counts
them; a test missing on Windows with no reason here fails the run.

    python3 tools/windows_tests.py --build build/windows --linux build/release
"""
from __future__ import annotations

import argparse
import os
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
#: Test suites (GoogleTest) and ctest names the Windows build leaves out, and why.
NOT_ON_WINDOWS = {
    "RealtimeKit": "RealtimeKit over D-Bus is how Linux grants real-time priority (Windows: MMCSS)",
    "DBusWriter": "the D-Bus client RealtimeKit needs, Linux's",
    "DBusReply": "the D-Bus client RealtimeKit needs, Linux's",
}
#: The replay drivers and their inputs (as native_core/CMakeLists.txt's add_test lines give them).
FIXTURES = ROOT / "tests" / "fixtures"
REPLAYS = {
    "fuzz_report_descriptor": sorted((FIXTURES / "hid").glob("*.hid")),
    "fuzz_spacemouse_report": sorted((FIXTURES / "hid").glob("*.hid")),
    "fuzz_hid_recording": sorted((FIXTURES / "hid").glob("*.hid")),
    "fuzz_falcon_frames": [FIXTURES / "falcon" / "status_stream.bin"],
    "fuzz_haply_messages": [FIXTURES / "haply" / "inventory.json", FIXTURES / "haply" / "state.json",
                            *sorted((ROOT / "native_core" / "fuzz" / "findings" / "fuzz_haply_messages").glob("*"))],
}


def wine() -> str:
    """Debian's 64-bit Wine loader."""
    for candidate in ("wine64", "/usr/lib/wine/wine64", "wine"):
        found = shutil.which(candidate) or (candidate if os.path.isfile(candidate) else None)
        if found:
            return found
    raise SystemExit("wine64 not found: make test-windows installs it (Debian: apt install wine64)")


def gtest_names(command: list[str], env: dict[str, str] | None = None, cwd: str | None = None) -> list[str]:
    """Suite.Test names a GoogleTest binary lists."""
    out = subprocess.run(command + ["--gtest_list_tests"], capture_output=True, text=True, env=env, cwd=cwd,
                         timeout=300, check=True).stdout
    names, suite = [], ""
    for line in out.splitlines():
        if not line.strip() or line.startswith("Running main()"):
            continue
        if not line.startswith(" "):
            suite = line.strip().split("#")[0].strip()
        else:
            names.append(suite + line.strip().split("#")[0].strip())
    return names


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build/windows")
    parser.add_argument("--linux", default="build/release", help="the Linux build, to name what Windows leaves out")
    args = parser.parse_args()
    build = pathlib.Path(args.build).resolve()
    # (a private prefix; Wine maps / to Z:, so the tests' Unix paths resolve from a folder under it)
    env = dict(os.environ, WINEPREFIX=str(build / "wine"), WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    loader = wine()
    failed = []
    tests = [loader, str(build / "hscore_tests.exe")]
    run = subprocess.run(tests + ["--gtest_brief=1"], env=env, cwd=build, timeout=1800)
    if run.returncode != 0:
        failed.append("hscore_tests.exe")
    windows = set(gtest_names(tests, env, str(build)))
    for harness, inputs in REPLAYS.items():
        exe = build / f"{harness}_replay.exe"
        r = subprocess.run([loader, str(exe), "20000", *map(str, inputs)], env=env, cwd=build, timeout=900,
                           capture_output=True, text=True)
        print(f"Fuzz.{harness}: {'passed' if r.returncode == 0 else 'FAILED'} ({len(inputs)} inputs, 20000 mutations)")
        if r.returncode != 0:
            print(r.stdout[-2000:], r.stderr[-2000:], sep="\n")
            failed.append(f"Fuzz.{harness}")
        windows.add(f"Fuzz.{harness}")
    # The haptic loop's period there (a measurement, not a test: Wine is not Windows' scheduler).
    period = subprocess.run([loader, str(build / "loop_period.exe"), "3"], env=env, cwd=build, timeout=120,
                            capture_output=True, text=True)
    print("haptic loop under Wine: " + " ".join(period.stdout.split("\n")).strip())
    if period.returncode != 0:
        failed.append("loop_period.exe")
    linux_tests = pathlib.Path(args.linux).resolve() / "hscore_tests"
    if linux_tests.is_file():
        linux = set(gtest_names([str(linux_tests)]))
        linux |= {f"Fuzz.{h}" for h in REPLAYS}
        missing = sorted(linux - windows)
        unexplained = [t for t in missing if t.split(".")[0] not in NOT_ON_WINDOWS and t not in NOT_ON_WINDOWS]
        print(f"on Windows (Wine): {len(windows)} tests; not on Windows: {len(missing)} of the Linux build's "
              f"{len(linux)}:")
        for name in missing:
            why = NOT_ON_WINDOWS.get(name) or NOT_ON_WINDOWS.get(name.split(".")[0]) or "NO REASON GIVEN"
            print(f"  {name}: {why}")
        if unexplained:
            failed.append(f"{len(unexplained)} tests missing on Windows without a reason in tools/windows_tests.py")
    else:
        print(f"(no Linux build at {linux_tests}: what Windows leaves out is not counted)")
    if failed:
        print("FAILED: " + ", ".join(failed))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
