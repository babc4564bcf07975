#!/usr/bin/env python3
"""What the Windows Python module is built against, with no Windows Python here (make build-windows):
CPython 3.11's own headers (Include/ and PC/pyconfig.h, from Debian's python3.11 source package,
the version FreeCAD's Windows builds bundle), an import library for python311.dll made from the
functions and data those headers export (PyAPI_FUNC, PyAPI_DATA) by MinGW's dlltool, and
pybind11's headers copied apart, so the cross compiler never sees this system's /usr/include.

    python3 tools/windows_python.py OUT [--cache DIR]

OUT then holds include/, pybind11/ and libpython311.a (CMake's HS_WINDOWS_PYTHON). The source
tarball is fetched once into --cache and checked against its SHA-256.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys

from debian_source import extract, fetch

SOURCE = "p/python3.11/python3.11_3.11.2.orig.tar.gz"
SHA256 = "2411c74bda5bbcfcddaf4531f66d1adc73f247f529aee981b029513aefdbf849"
TOP = "Python-3.11.2/"
DLL = "python311.dll"
PYBIND11 = "/usr/include/pybind11"
DLLTOOL = "x86_64-w64-mingw32-dlltool"


def exported_names(include: str) -> tuple[set[str], set[str]]:
    """The functions and the data CPython's headers declare as its DLL's exports."""
    functions, data = set(), set()
    for root, _, files in os.walk(include):
        for name in files:
            if not name.endswith(".h"):
                continue
            text = re.sub(r"/\*.*?\*/", "", open(os.path.join(root, name), encoding="utf-8", errors="replace").read(), flags=re.S)
            functions.update(re.findall(r"PyAPI_FUNC\s*\((?:[^()]|\([^()]*\))*\)\s*(\w+)\s*\(", text))
            data.update(re.findall(r"PyAPI_DATA\s*\((?:[^()]|\([^()]*\))*\)\s*(\w+)", text))
    # (CPython's names start Py or _Py; the headers also declare pthread stubs for WASI, which no
    # Windows python311.dll exports)
    ours = re.compile(r"_?Py")
    functions = {n for n in functions if ours.match(n)}
    return functions, {n for n in data - functions if ours.match(n)}


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", help="the folder to make (CMake's HS_WINDOWS_PYTHON)")
    parser.add_argument("--cache", default=os.path.join(os.path.expanduser("~"), ".cache", "hapticsculpt"),
                        help="where the source tarball is kept")
    args = parser.parse_args(argv)
    if shutil.which(DLLTOOL) is None:
        raise SystemExit(f"{DLLTOOL} not found (Debian: apt install binutils-mingw-w64-x86-64)")
    if not os.path.isdir(PYBIND11):
        raise SystemExit(f"{PYBIND11} not found (Debian: apt install pybind11-dev)")
    tarball = fetch(args.cache, SOURCE, SHA256)
    out = os.path.abspath(args.out)
    shutil.rmtree(out, ignore_errors=True)
    include = os.path.join(out, "include")
    extract(tarball, TOP + "Include/", [""], include)
    extract(tarball, TOP + "PC/", ["pyconfig.h"], include)
    shutil.copytree(PYBIND11, os.path.join(out, "pybind11", "pybind11"))
    functions, data = exported_names(include)
    definition = os.path.join(out, "python311.def")
    with open(definition, "w", encoding="utf-8") as f:
        f.write(f"LIBRARY {DLL}\nEXPORTS\n")
        f.writelines(f"    {n}\n" for n in sorted(functions))
        f.writelines(f"    {n} DATA\n" for n in sorted(data))
    subprocess.run([DLLTOOL, "-d", definition, "-D", DLL, "-l", os.path.join(out, "libpython311.a")], check=True)
    print(f"{out}: CPython 3.11.2's headers, an import library for {DLL} ({len(functions)} functions, "
          f"{len(data)} data), pybind11's headers")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
