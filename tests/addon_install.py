"""The Addon Manager's install, tried as a user gets it (make test-addon): no compiler involved.

The repository is copied without any build output into a private FreeCAD home's Mod folder (as the
Addon Manager's clone), the hapticsculpt_core wheel is installed into that home's
AdditionalPythonPackages folder by tools/install_core.py (the README's command), and then, from the
copy: the core's origin is checked, ``freecadcmd -t TestHapticSculpt`` runs the FreeCAD-layer
tests and pytest runs the GUI tests (real FreeCAD under Xvfb, real input events).

    /usr/bin/python3 tests/addon_install.py --wheel WHEEL --pip-python PYTHON --out DIR [--suites runner|gui]

PYTHON is an interpreter with pip for FreeCAD's Python version (a virtual environment's).
"""
from __future__ import annotations

import argparse
import glob
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: What a clone of the repository has and a build adds: left out of the copy.
BUILD_OUTPUT = shutil.ignore_patterns(".git", "build", "out", "__pycache__", "*.so", "*.pyc", ".pytest_cache",
                                      ".hypothesis")


#: A sculpt, one rope stroke and its face, in console mode: the installed core at work.
#: Run by freecadcmd as a script file (its -c mode in FreeCAD 1.1.3 ends in "Application
#: unexpectedly terminated" after a stroke, before any line of output, where a file runs through).
SMOKE = """
import sys
import FreeCAD, HapticSculpt as hs
doc = FreeCAD.newDocument("smoke")
obj = hs.make_sculpt(doc)
hs.run(obj, 0.5, hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 10.0), seconds=0.3))
lift = max(p.z for row in obj.Shape.Faces[0].Surface.getPoles() for p in row)
assert lift > 1.0, lift
sys.stderr.write("HS_SMOKE lift %.2f mm\\n" % lift)
"""


def run(what: str, command: list[str], part: str | None = None, **kwargs) -> subprocess.CompletedProcess:
    """Runs ``command``, printing what it is and how long it took (a ``part`` of make test: through
    tools/timed, whose lines tools/test_times.py reads); fails the script if it fails."""
    print(f"== {what}", flush=True)
    start = time.monotonic()
    proc = subprocess.run([os.path.join(ROOT, "tools", "timed"), part, *command] if part else command, **kwargs)
    if not part:
        print(f"   ({time.monotonic() - start:.0f} s)", flush=True)
    if proc.returncode != 0:
        sys.exit(f"addon install: {what} failed (exit {proc.returncode})")
    return proc


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--wheel", required=True)
    parser.add_argument("--pip-python", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--pytest-args", default="", help="more arguments for the GUI tests' pytest")
    parser.add_argument("--gui-tests", default="", help="the GUI test files to run (default: every tests/test_gui_*.py)")
    parser.add_argument("--load-only", action="store_true",
                        help="install the wheel and check that FreeCAD loads it and sculpts with it; no test suites")
    parser.add_argument("--suites", default="runner,gui",
                        help="which suites to run from the installed addon: runner (freecadcmd -t), gui, or both")
    args = parser.parse_args(argv)
    out = os.path.abspath(args.out)
    shutil.rmtree(out, ignore_errors=True)
    home = os.path.join(out, "home")
    addon = os.path.join(home, "Mod", "HapticSculpt")
    shutil.copytree(ROOT, addon, ignore=BUILD_OUTPUT, symlinks=True)
    built = [os.path.join(d, f) for d, _, files in os.walk(addon) for f in files if f.endswith(".so")]
    assert not built, f"the copy has build output: {built}"

    run("install the wheel (tools/install_core.py)",
        [args.pip_python, os.path.join(addon, "tools", "install_core.py"), os.path.abspath(args.wheel),
         "--freecad-home", home], check=False)
    packages = os.path.join(home, "AdditionalPythonPackages")
    env = dict(os.environ, FREECAD_USER_HOME=home, HS_CORE_SITE=packages,
               HS_SCREENSHOTS=os.path.join(ROOT, "build", "screenshots-addon"))
    env.pop("PYTHONPATH", None)

    origin = run("the core FreeCAD loads", ["freecadcmd", "-c", "import HapticSculpt.core as c; "
                                            "print('HS_ORIGIN=' + c.NATIVE_ORIGIN)"],
                 env=env, cwd=out, capture_output=True, text=True)
    line = next((x for x in origin.stdout.splitlines() if x.startswith("HS_ORIGIN=")), "")
    print("   " + line)
    if not (line.startswith("HS_ORIGIN=installed package") and f"({packages}" in line):
        sys.exit(f"addon install: FreeCAD did not load the installed core:\n{origin.stdout[-2000:]}{origin.stderr[-2000:]}")

    if args.load_only:
        script = os.path.join(out, "smoke.py")
        with open(script, "w", encoding="utf-8") as f:
            f.write(SMOKE)
        smoke = run("a stroke in freecadcmd with the installed core", ["freecadcmd", script], env=env, cwd=out,
                    capture_output=True, text=True)
        line = next((x for x in smoke.stderr.splitlines() if x.startswith("HS_SMOKE")), "")
        print("   " + line)
        if not line:  # (an exception in a script file is printed, not an exit status)
            sys.exit(f"addon install: the stroke did not run:\n{smoke.stdout[-2000:]}{smoke.stderr[-2000:]}")
        return 0
    suites = set(args.suites.split(","))
    if not suites <= {"runner", "gui"}:
        sys.exit(f"addon install: unknown suites {sorted(suites - {'runner', 'gui'})} (runner, gui)")
    if "runner" in suites:
        run("freecadcmd -t TestHapticSculpt (from the installed addon)", ["freecadcmd", "-t", "TestHapticSculpt"],
            part="freecad-runner", env=env, cwd=out)
    if "gui" not in suites:
        return 0
    gui_tests = args.gui_tests.split() or sorted(
        os.path.relpath(p, addon) for p in glob.glob(os.path.join(addon, "tests", "test_gui_*.py")))
    run("GUI tests (from the installed addon)",
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rfE", "--durations=10",
         *args.pytest_args.split(), *gui_tests], part="gui", env=env, cwd=addon)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
