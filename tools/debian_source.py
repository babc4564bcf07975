"""Source tarballs from Debian's archive, fetched once into a cache and checked against the SHA-256
their .dsc gives (what the Windows build compiles that no Windows machine here can provide:
tools/windows_python.py, tools/windows_deps.py)."""
from __future__ import annotations

import hashlib
import os
import shutil
import tarfile
import urllib.request

POOL = "https://deb.debian.org/debian/pool/main/"


def fetch(cache: str, pool_path: str, sha256: str) -> str:
    """The tarball at POOL + pool_path, downloaded into cache once; its SHA-256 must be sha256."""
    os.makedirs(cache, exist_ok=True)
    name = os.path.basename(pool_path)
    path = os.path.join(cache, name)
    if not os.path.exists(path):
        partial = path + ".part"
        with urllib.request.urlopen(POOL + pool_path, timeout=120) as response, open(partial, "wb") as out:
            shutil.copyfileobj(response, out)
        os.replace(partial, path)
    with open(path, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    if digest != sha256:
        os.remove(path)
        raise SystemExit(f"{name}: SHA-256 {digest}, expected {sha256} (removed; run again)")
    return path


def extract(tarball: str, top: str, wanted: list[str], out: str) -> int:
    """Copies the files under top/ whose path there starts with one of wanted into out (same
    relative paths); returns how many."""
    count = 0
    with tarfile.open(tarball) as tar:
        for member in tar.getmembers():
            if not member.isfile() or not member.name.startswith(top):
                continue
            relative = member.name[len(top):]
            if not any(relative.startswith(w) for w in wanted):
                continue
            target = os.path.join(out, relative)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            with tar.extractfile(member) as src, open(target, "wb") as dst:
                shutil.copyfileobj(src, dst)
            count += 1
    return count
