#!/usr/bin/env python3
"""The device libraries the Windows core links, from the same Debian sources the Linux build uses
as packages (make build-windows): hidapi (the SpaceMouse's HID; its Windows backend loads hid.dll
and cfgmgr32.dll itself), simdjson (Haply's messages) and libwebsockets without TLS (Haply's
Inverse Service is a plain WebSocket on this computer), each the version Debian 12 ships.

    python3 tools/windows_deps.py OUT --toolchain native_core/cmake/mingw-w64.cmake [--cache DIR]

OUT then holds hidapi/ and simdjson/ as sources (CMake compiles them with the core:
HS_WINDOWS_DEPS) and libwebsockets/ built and installed by its own CMake with the same cross
toolchain (lib/libwebsockets_static.a, include/), each with its licence (the Windows wheel carries
them: tools/windows_wheel.py). Tarballs are fetched once into --cache and
checked against their SHA-256; the built libwebsockets is kept there too.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import subprocess
import sys

from debian_source import extract, fetch

# (pool path, SHA-256 from the .dsc, the tarball's top folder, what of it is needed)
HIDAPI = ("h/hidapi/hidapi_0.13.1.orig.tar.gz", "476a2c9a4dc7d1fc97dd223b84338dbea3809a84caea2dcd887d9778725490e3",
          "hidapi-hidapi-0.13.1/", ["hidapi/hidapi.h", "windows/hid.c", "windows/hidapi_", "LICENSE"])
SIMDJSON = ("s/simdjson/simdjson_3.0.1.orig.tar.gz", "156b1bc5eb0561b2bd166b46d191fd3d95a3e709cc63761477d3b7aec2b6e9ed",
            "simdjson-3.0.1/", ["singleheader/simdjson.h", "singleheader/simdjson.cpp", "LICENSE"])
WEBSOCKETS = ("libw/libwebsockets/libwebsockets_4.1.6.orig.tar.gz",
              "402e9a8df553c9cd2aff5d7a9758e9e5285bf3070c82539082864633db3deb83", "libwebsockets-4.1.6/", [""])
# A client and a server (the tests' mock Inverse Service) over plain TCP: no TLS, no compression,
# none of its examples or test programs.
WEBSOCKETS_OPTIONS = ["-DLWS_WITH_SSL=OFF", "-DLWS_WITH_SHARED=OFF", "-DLWS_WITH_STATIC=ON", "-DLWS_WITHOUT_TESTAPPS=ON",
                      "-DLWS_WITH_MINIMAL_EXAMPLES=OFF", "-DLWS_WITHOUT_EXTENSIONS=ON", "-DLWS_WITH_ZLIB=OFF",
                      "-DLWS_WITH_ZIP_FOPS=OFF", "-DCMAKE_BUILD_TYPE=Release"]


def run(command: list[str]) -> None:
    """A build step, its output shown only when it fails."""
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.stderr.write(done.stdout + done.stderr)
        raise SystemExit(f"{' '.join(command[:3])}...: exit {done.returncode}")


def build_websockets(tarball: str, out: str, toolchain: str, cache: str) -> None:
    """libwebsockets' static library and headers in out/libwebsockets, built by its own CMake once
    per source, options, toolchain and compiler, and kept in cache (its compile commands hold this
    checkout's paths, which the compiler cache would miss in the next one)."""
    compiler = subprocess.run(["x86_64-w64-mingw32-gcc-posix", "--version"], capture_output=True, text=True,
                              check=True).stdout.splitlines()[0]
    with open(toolchain, "rb") as f:
        key = hashlib.sha256("\n".join([WEBSOCKETS[1], *WEBSOCKETS_OPTIONS, compiler]).encode() + f.read()).hexdigest()
    kept = os.path.join(cache, "windows-libwebsockets-" + key[:16])
    if not os.path.isfile(os.path.join(kept, "lib", "libwebsockets_static.a")):
        work = os.path.join(out, "work")
        source, build, staged = (os.path.join(work, d) for d in ("src", "build", "install"))
        extract(tarball, WEBSOCKETS[2], WEBSOCKETS[3], source)
        run(["cmake", "-S", source, "-B", build, "-G", "Ninja", f"-DCMAKE_TOOLCHAIN_FILE={toolchain}",
             f"-DCMAKE_INSTALL_PREFIX={staged}", *WEBSOCKETS_OPTIONS])
        run(["cmake", "--build", build, "-j", str(os.cpu_count() or 2)])
        run(["cmake", "--install", build])
        shutil.rmtree(kept, ignore_errors=True)
        shutil.move(staged, kept)
        shutil.rmtree(work)
    shutil.copytree(kept, os.path.join(out, "libwebsockets"))
    extract(tarball, WEBSOCKETS[2], ["LICENSE"], os.path.join(out, "libwebsockets"))


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", help="the folder to make (CMake's HS_WINDOWS_DEPS)")
    parser.add_argument("--toolchain", required=True, help="the MinGW-w64 CMake toolchain file")
    parser.add_argument("--cache", default=os.path.join(os.path.expanduser("~"), ".cache", "hapticsculpt"),
                        help="where the source tarballs are kept")
    args = parser.parse_args(argv)
    out = os.path.abspath(args.out)
    shutil.rmtree(out, ignore_errors=True)
    for name, (pool, sha256, top, wanted) in {"hidapi": HIDAPI, "simdjson": SIMDJSON}.items():
        extract(fetch(args.cache, pool, sha256), top, wanted, os.path.join(out, name))
    build_websockets(fetch(args.cache, WEBSOCKETS[0], WEBSOCKETS[1]), out, os.path.abspath(args.toolchain), args.cache)
    print(f"{out}: hidapi 0.13.1 and simdjson 3.0.1 (sources), libwebsockets 4.1.6 (built without TLS)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
