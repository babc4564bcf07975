"""Installs a hapticsculpt_core wheel where FreeCAD looks for add-ons' Python packages, the folder
the Addon Manager installs into: ``<UserAppDataDir>/AdditionalPythonPackages/py3XX`` for FreeCAD
0.21 and later, ``<UserAppDataDir>/AdditionalPythonPackages`` for 0.20.

    python3 tools/install_core.py WHEEL [--freecad-home DIR] [--freecadcmd PATH]

FreeCAD itself is asked for its user folder, its version and its Python (``freecadcmd``), so the
folder is the one this FreeCAD reads, also with FREECAD_USER_HOME or 1.1's versioned folders.
``--freecad-home`` installs for a FreeCAD started with FREECAD_USER_HOME=DIR (the tests do).
On Windows run it with FreeCAD's own python.exe and name its FreeCADCmd.exe with ``--freecadcmd``
(both in FreeCAD's bin folder); the wheel must be the win_amd64 one for its Python (cp311).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys

_QUERY = ("import FreeCAD, json, sys; print('HS_FREECAD=' + json.dumps({'user': FreeCAD.getUserAppDataDir(), "
          "'version': [int(x) for x in FreeCAD.Version()[:2]], 'python': list(sys.version_info[:2]), "
          "'windows': sys.platform == 'win32'}))")


def freecad_facts(home: str | None = None, freecadcmd: str | None = None) -> dict:
    """FreeCAD's user folder, version, Python version and system, as FreeCAD reports them."""
    freecadcmd = freecadcmd or shutil.which("freecadcmd") or shutil.which("FreeCADCmd")
    if freecadcmd is None or not os.path.isfile(freecadcmd):
        raise SystemExit("freecadcmd not found: install FreeCAD (Debian: apt install freecad-python3), or name "
                         "FreeCAD's console program with --freecadcmd (Windows: FreeCAD's bin\\FreeCADCmd.exe)")
    env = dict(os.environ)
    if home is not None:
        os.makedirs(home, exist_ok=True)  # (FreeCAD ignores a FREECAD_USER_HOME that does not exist)
        env["FREECAD_USER_HOME"] = os.path.abspath(home)
    out = subprocess.run([freecadcmd, "-c", _QUERY], capture_output=True, text=True, env=env, cwd="/",
                         timeout=120).stdout
    found = re.search(r"^HS_FREECAD=(.*)$", out, re.M)
    if not found:
        raise SystemExit(f"freecadcmd did not answer:\n{out[-2000:]}")
    return json.loads(found.group(1))


def packages_folder(facts: dict) -> str:
    """The folder FreeCAD adds to sys.path for add-ons' packages (FreeCADInit.py)."""
    base = os.path.join(facts["user"], "AdditionalPythonPackages")
    if tuple(facts["version"]) < (0, 21):
        return base
    major, minor = facts["python"]
    return os.path.join(base, f"py{major}{minor}")


def wrong_wheel(name: str, facts: dict) -> str | None:
    """Why the wheel named `name` cannot load in the FreeCAD `facts` describe, or None."""
    tag = "cp%d%d" % tuple(facts["python"])
    if f"-{tag}-" not in name:
        return (f"FreeCAD {'.'.join(map(str, facts['version']))} runs Python {'.'.join(map(str, facts['python']))}; "
                f"take the wheel whose name has -{tag}-")
    windows = bool(facts.get("windows"))
    if windows != name.endswith("-win_amd64.whl"):
        return ("this FreeCAD runs on " + ("Windows: take the wheel whose name ends in -win_amd64.whl" if windows else
                                            "Linux: take a manylinux wheel, not a Windows one"))
    return None


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("wheel", help="a hapticsculpt_core-*.whl file")
    parser.add_argument("--freecad-home", help="install for FreeCAD started with FREECAD_USER_HOME=DIR")
    parser.add_argument("--freecadcmd", help="FreeCAD's console program (default: freecadcmd or FreeCADCmd on PATH)")
    args = parser.parse_args(argv)
    if not os.path.isfile(args.wheel) or not args.wheel.endswith(".whl"):
        parser.error(f"wheel: {args.wheel!r} is not a .whl file")
    facts = freecad_facts(args.freecad_home, args.freecadcmd)
    wrong = wrong_wheel(os.path.basename(args.wheel), facts)
    if wrong:
        parser.error(f"wheel: {wrong}")
    if subprocess.run([sys.executable, "-m", "pip", "--version"], capture_output=True).returncode != 0:
        raise SystemExit(f"{sys.executable} has no pip (Debian: apt install python3-pip)")
    target = packages_folder(facts)
    os.makedirs(target, exist_ok=True)
    # --no-deps: FreeCAD brings numpy; --upgrade: replaces an older hapticsculpt_core in the folder.
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--disable-pip-version-check", "--no-deps",
                    "--upgrade", "--target", target, args.wheel], check=True)
    print(f"installed {os.path.basename(args.wheel)} into {target}; restart FreeCAD")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
