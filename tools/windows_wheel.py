#!/usr/bin/env python3
"""The Windows wheel for FreeCAD's Python 3.11 (make test-windows): packs
the cross-built hapticsculpt_core.cp311-win_amd64.pyd into hapticsculpt_core-VERSION-cp311-cp311-
win_amd64.whl and checks it as far as a machine without Windows can:

- its import table names only python311.dll, the C runtime and Windows' own DLLs (no MinGW runtime
  DLL a Windows FreeCAD would not have);
- it exports PyInit_hapticsculpt_core;
- pip takes it for a Windows CPython 3.11 (an install with --platform win_amd64 into a folder).

    python3 tools/windows_wheel.py PYD OUTDIR

Loading it in a Windows FreeCAD cannot be tried here (README: how to try it and report back).
"""
from __future__ import annotations

import argparse
import base64
import hashlib
import os
import re
import subprocess
import sys
import tempfile
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODULE = "hapticsculpt_core"
TAG = "cp311-cp311-win_amd64"
OBJDUMP = "x86_64-w64-mingw32-objdump"
# What a Windows FreeCAD has: CPython's DLL, the C runtime MinGW links against (msvcrt, or the
# universal CRT's api sets) and DLLs every Windows installs.
SYSTEM_DLLS = {"kernel32.dll", "user32.dll", "advapi32.dll", "msvcrt.dll", "ucrtbase.dll", "ws2_32.dll",
               "avrt.dll", "winmm.dll", "setupapi.dll", "hid.dll", "cfgmgr32.dll", "ole32.dll", "shell32.dll",
               "bcrypt.dll", "ntdll.dll"}


def version() -> str:
    text = open(os.path.join(ROOT, "HapticSculpt", "version.py"), encoding="utf-8").read()
    return re.search(r'^__version__ = "([^"]+)"', text, re.M).group(1)


def imports_and_exports(pyd: str) -> tuple[list[str], list[str]]:
    """The DLLs the module imports from and the names it exports (objdump's private headers)."""
    text = subprocess.run([OBJDUMP, "-p", pyd], capture_output=True, text=True, check=True).stdout
    dlls = re.findall(r"^\s*DLL Name: (\S+)", text, re.M)
    table = text.split("[Ordinal/Name Pointer] Table", 1)
    exports = re.findall(r"^\s*\[\s*\d+\]\s+(?:\+base\[\s*\d+\]\s+\w+\s+)?(\w+)\s*$", table[1], re.M) if len(table) > 1 else []
    return dlls, exports


def record_line(arcname: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{arcname},sha256={digest},{len(data)}"


#: The licences of what the module links in (tools/windows_deps.py's folders), under the wheel's
#: dist-info/licenses/.
BUNDLED_LICENCES = {"hidapi": ["LICENSE.txt", "LICENSE-bsd.txt"], "simdjson": ["LICENSE"], "libwebsockets": ["LICENSE"]}


def pack(pyd: str, outdir: str, deps: str) -> str:
    """The wheel: the module at its root, the metadata pip needs, the bundled libraries' licences."""
    ver = version()
    info = f"{MODULE}-{ver}.dist-info"
    files = {
        f"{MODULE}.cp311-win_amd64.pyd": open(pyd, "rb").read(),
        f"{info}/METADATA": (f"Metadata-Version: 2.1\nName: hapticsculpt-core\nVersion: {ver}\n"
                             "Summary: The dynamics core of the HapticSculpt FreeCAD workbench (Windows build, "
                             "cross-built with MinGW-w64)\nLicense: LGPL-2.1-or-later\nRequires-Python: >=3.11,<3.12\n"
                             "Requires-Dist: numpy\n").encode(),
        f"{info}/WHEEL": f"Wheel-Version: 1.0\nGenerator: tools/windows_wheel.py\nRoot-Is-Purelib: false\nTag: {TAG}\n".encode(),
        f"{info}/LICENSE": open(os.path.join(ROOT, "LICENSE"), "rb").read(),
    }
    for library, names in BUNDLED_LICENCES.items():
        for name in names:
            with open(os.path.join(deps, library, name), "rb") as f:
                files[f"{info}/licenses/{library}-{name}"] = f.read()
    record = "\n".join(record_line(n, d) for n, d in files.items()) + f"\n{info}/RECORD,,\n"
    os.makedirs(outdir, exist_ok=True)
    path = os.path.join(outdir, f"{MODULE}-{ver}-{TAG}.whl")
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in files.items():
            z.writestr(name, data)
        z.writestr(f"{info}/RECORD", record)
    return path


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pyd", help=f"{MODULE}.cp311-win_amd64.pyd as the cross build made it")
    parser.add_argument("outdir", help="where to write the wheel")
    parser.add_argument("--deps", required=True, help="what tools/windows_deps.py made (the bundled libraries' licences)")
    args = parser.parse_args(argv)
    dlls, exports = imports_and_exports(args.pyd)
    foreign = [d for d in dlls if d.lower() not in SYSTEM_DLLS and d.lower() != "python311.dll"
               and not d.lower().startswith("api-ms-win-")]
    problems = []
    if "python311.dll" not in [d.lower() for d in dlls]:
        problems.append("it does not import python311.dll")
    if foreign:
        problems.append("it imports DLLs a Windows FreeCAD has not: " + ", ".join(foreign))
    if f"PyInit_{MODULE}" not in exports:
        problems.append(f"it does not export PyInit_{MODULE} (exports: {', '.join(exports[:10])})")
    if problems:
        print(f"{args.pyd}: " + "; ".join(problems), file=sys.stderr)
        return 1
    wheel = pack(args.pyd, args.outdir, args.deps)
    with tempfile.TemporaryDirectory() as target:
        pip = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--disable-pip-version-check", "--no-deps",
                              "--platform", "win_amd64", "--python-version", "3.11", "--implementation", "cp",
                              "--only-binary=:all:", "--target", target, wheel], capture_output=True, text=True)
        if pip.returncode != 0:
            print(f"{wheel}: pip does not take it for a Windows CPython 3.11:\n{pip.stderr[-2000:]}", file=sys.stderr)
            return 1
        installed = sorted(os.listdir(target))
    print(f"{wheel}: imports {', '.join(dlls)}; exports PyInit_{MODULE}; pip installs it for a Windows CPython 3.11 "
          f"({', '.join(installed)})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
