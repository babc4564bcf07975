"""Helpers shared by the FreeCAD-layer tests (plain unittest: they run under pytest and under
``freecadcmd -t TestHapticSculpt``)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for path in (ROOT, "/usr/lib/freecad-python3/lib"):
    if os.path.isdir(path) and path not in sys.path:
        sys.path.append(path)

import FreeCAD  # noqa: E402  (before Part, or Part segfaults on import)
import Part  # noqa: E402,F401

FREECADCMD = shutil.which("freecadcmd") or shutil.which("FreeCADCmd")
FREECAD_VERSION = tuple(int(x) for x in FreeCAD.Version()[:2])
#: Where the GUI tests put their pictures, one folder per FreeCAD version (0.20's has the plain name;
#: HS_SCREENSHOTS puts them elsewhere: the addon-install test's go to the checkout's build folder).
SCREENSHOTS = os.path.join(os.environ.get("HS_SCREENSHOTS", os.path.join(ROOT, "build", "screenshots")),
                           "" if FREECAD_VERSION < (1, 0) else "freecad-%d.%d" % FREECAD_VERSION)
#: cadquery/OCP in its own virtual environment (its numpy must not shadow FreeCAD's): `make ocp-venv`.
OCP_PYTHON = os.environ.get("HS_OCP_PYTHON", os.path.join(ROOT, "build", "ocp-venv", "bin", "python"))


class DocumentTestCase(unittest.TestCase):
    """A fresh document per test, closed afterwards."""

    def setUp(self) -> None:
        self.doc = FreeCAD.newDocument("HSTest")
        self.tmp = tempfile.mkdtemp(prefix="hs-test-")

    def tearDown(self) -> None:
        FreeCAD.closeDocument(self.doc.Name)
        shutil.rmtree(self.tmp, ignore_errors=True)


#: The addon-install test (tests/addon_install.py) runs the tests from a copy of the repository
#: without build output, with the core from a wheel installed into this AdditionalPythonPackages
#: folder of a FreeCAD home; every FreeCAD home the tests make then links it, as the Addon Manager's
#: install would have it.
CORE_SITE = os.environ.get("HS_CORE_SITE")


#: FreeCAD's preferences for every FreeCAD a test starts: no splash screen. Under Xvfb, with no window
#: manager, the splash repaints itself for each start-up message and then waits its full second for
#: the main window to be shown: 3 s of a 4.3 s start (strace). Nothing of the workbench depends on it.
NO_SPLASH = '<FCBool Name="ShowSplasher" Value="0"/>'
USER_CFG_WITHOUT_SPLASH = ('<?xml version="1.0" encoding="UTF-8" standalone="no" ?>\n<FCParameters><FCParamGroup Name="Root">'
                           '<FCParamGroup Name="BaseApp"><FCParamGroup Name="Preferences"><FCParamGroup Name="General">'
                           f'{NO_SPLASH}</FCParamGroup></FCParamGroup></FCParamGroup></FCParamGroup></FCParameters>\n')


def make_addon_home(home: str) -> str:
    """Makes ``home`` a FREECAD_USER_HOME with this checkout as the addon Mod/HapticSculpt (and the
    installed core, with HS_CORE_SITE) and FreeCAD's preferences without the splash screen (a test
    may write a user.cfg of its own, with ``NO_SPLASH``); returns it."""
    os.makedirs(os.path.join(home, "Mod"), exist_ok=True)
    link = os.path.join(home, "Mod", "HapticSculpt")
    if not os.path.lexists(link):
        os.symlink(ROOT, link)
    packages = os.path.join(home, "AdditionalPythonPackages")
    if CORE_SITE and not os.path.lexists(packages):
        os.symlink(CORE_SITE, packages)
    cfg = os.path.join(home, "user.cfg")
    if not os.path.exists(cfg):
        with open(cfg, "w", encoding="utf-8") as f:
            f.write(USER_CFG_WITHOUT_SPLASH)
    return home


def _addon_home(tmp: str, name: str) -> str:
    """A private FREECAD_USER_HOME under ``tmp`` whose Mod/HapticSculpt links this checkout."""
    return make_addon_home(os.path.join(tmp, name))


def run_freecadcmd(script: str, tmp: str, timeout: float = 300) -> dict:
    """Runs ``script`` in a new ``freecadcmd`` process with this checkout installed as an addon (a
    private FREECAD_USER_HOME whose Mod/HapticSculpt links here); the script stores its answer with
    ``answer(dict)``, which this returns."""
    if FREECADCMD is None:
        raise unittest.SkipTest("freecadcmd is not installed")
    home = _addon_home(tmp, "fchome")
    out = os.path.join(tmp, "answer.json")
    path = os.path.join(tmp, "script.py")
    with open(path, "w") as f:
        f.write("import json\n"
                f"def answer(d):\n    json.dump(d, open({out!r}, 'w'))\n"
                + textwrap.dedent(script))
    env = dict(os.environ, FREECAD_USER_HOME=home)
    proc = subprocess.run([FREECADCMD, path], env=env, capture_output=True, text=True, timeout=timeout)
    if not os.path.exists(out):
        raise AssertionError(f"freecadcmd gave no answer (rc {proc.returncode}):\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    with open(out, encoding="utf-8") as f:
        return json.load(f)


#: The FreeCAD GUI can run here (under Xvfb); GUI tests skip otherwise (make deps installs both).
GUI_AVAILABLE = shutil.which("Xvfb") is not None and shutil.which("freecad") is not None


class VirtualDisplay:
    """An Xvfb server on a display number it picks itself (``-displayfd``): free of the race
    ``xvfb-run -a`` has when several test processes, or a Debian root beside the host (which share
    the abstract X sockets), start displays at once. Close it, or use it as a context manager."""

    def __init__(self, screen: str = "1280x1024") -> None:
        self.process = subprocess.Popen(["Xvfb", "-displayfd", "1", "-screen", "0", screen + "x24", "-nolisten", "tcp"],
                                        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        number = self.process.stdout.readline().decode().strip()
        if not number:
            self.process.kill()
            raise AssertionError(f"Xvfb did not start (exit {self.process.wait()})")
        self.name = ":" + number

    def close(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        self.process.stdout.close()

    def __enter__(self) -> "VirtualDisplay":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def run_freecad_gui(script: str, tmp: str, timeout: float = 300) -> dict:
    """Runs ``script`` in the real FreeCAD GUI under Xvfb with this checkout installed as an addon;
    the script's text may use ``{answer}`` (formatted in here with the path, as a repr) to dump its
    result dict as JSON before ``os._exit(0)``, which this returns."""
    home = _addon_home(tmp, "guihome")
    out = os.path.join(tmp, "answer.json")
    path = os.path.join(tmp, "gui.py")
    with open(path, "w") as f:
        f.write(textwrap.dedent(script).replace("{answer}", repr(out)))
    with VirtualDisplay() as display:
        env = dict(os.environ, DISPLAY=display.name, QTWEBENGINE_DISABLE_SANDBOX="1", FREECAD_USER_HOME=home)
        proc = subprocess.run(["freecad", path], env=env, capture_output=True, text=True, timeout=timeout)
    if not os.path.exists(out):
        raise AssertionError(f"the FreeCAD GUI gave no answer (rc {proc.returncode}):\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    with open(out, encoding="utf-8") as f:
        result = json.load(f)
    assert "error" not in result, result["error"]
    return result


def run_ocp(script: str, tmp: str, timeout: float = 300) -> dict:
    """Runs ``script`` with the cadquery/OCP virtual environment's Python; it prints one JSON line."""
    if not os.path.exists(OCP_PYTHON):
        if os.environ.get("HS_REQUIRE_OCP"):
            raise AssertionError(f"{OCP_PYTHON} is missing: run `make ocp-venv`")
        raise unittest.SkipTest(f"{OCP_PYTHON} is missing: run `make ocp-venv`")
    path = os.path.join(tmp, "ocp_script.py")
    with open(path, "w") as f:
        f.write(textwrap.dedent(script))
    proc = subprocess.run([OCP_PYTHON, path], capture_output=True, text=True, timeout=timeout,
                          env=dict(os.environ, PYTHONPATH=""))
    if proc.returncode != 0:
        raise AssertionError(f"OCP script failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])
