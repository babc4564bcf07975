"""tools/debian-root where mount propagation is not allowed: inside a chroot whose / is no mount
point (as in many containers), a mount namespace cannot make its mounts private; the script then
keeps the propagation as it is and takes its mounts down when the command ends. Where no mount
namespace can be made at all it says so in one line and exits with 77, which make test reports and
goes on. The chroot is the other Debian's cached root (make test-other-debians builds it)."""
from __future__ import annotations

import os
import subprocess

import pytest
from freecad_support import ROOT

SCRIPT = os.path.join(ROOT, "tools", "debian-root")
CACHE = os.environ.get("HS_CACHE", os.path.join(os.path.expanduser("~"), ".cache", "hapticsculpt"))
SUITES = [s for s in ("trixie", "bookworm")
          if os.path.isfile(os.path.join(CACHE, f"debian-{s}-root", ".hapticsculpt-stamp"))]
ROOTED = os.geteuid() == 0


def _in_outer_chroot(root: str, script: str, scratch: str) -> subprocess.CompletedProcess:
    """Runs ``script`` in ``root`` entered with a plain chroot (its / then no mount point), with
    the checkout at /hapticsculpt and, as the inner script's cache, the same root again at
    /var/tmp/hs-cache/debian-SUITE-root (an overlay whose writes go to ``scratch``); all of it in a
    private namespace of the host's."""
    suite = os.path.basename(root)[len("debian-"):-len("-root")]
    inner = f"/var/tmp/hs-cache/debian-{suite}-root"
    setup = f"""
        set -e
        mkdir -p "{root}/hapticsculpt" "{root}{inner}"
        mount --bind /proc "{root}/proc"
        mount --bind "{ROOT}" "{root}/hapticsculpt"
        mkdir -p "{scratch}/upper" "{scratch}/work"
        mount -t overlay overlay -o lowerdir="{root}",upperdir="{scratch}/upper",workdir="{scratch}/work" "{root}{inner}"
        mount --make-shared "{root}{inner}"  # (a container's mounts often are: the hazard the clean-up is for)
        exec chroot "{root}" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HS_CACHE=/var/tmp/hs-cache \
            HS_SUITE={suite} INNER={inner} /bin/bash -c '{script}'
    """
    return subprocess.run(["unshare", "--mount", "--propagation", "private", "/bin/bash", "-c", setup],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.skipif(not ROOTED or not SUITES, reason="needs root and a cached Debian root (make test-other-debians)")
def test_a_root_is_used_inside_a_chroot_whose_root_is_no_mount_point(tmp_path):
    root = os.path.join(CACHE, f"debian-{SUITES[0]}-root")
    r = _in_outer_chroot(root, """
        unshare --mount --propagation private true 2>/dev/null && echo PRIVATE-WORKS
        /hapticsculpt/tools/debian-root "$HS_SUITE" run "echo inner-ok; test -f /etc/debian_version; pwd"
        echo "left-mounts=$(grep -c " $INNER/" /proc/self/mounts)"
    """, str(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "PRIVATE-WORKS" not in r.stdout  # the situation the fallback is for
    assert "inner-ok\n/hapticsculpt\n" in r.stdout
    assert "left-mounts=0" in r.stdout  # proc, sys, dev and the checkout taken down again


def test_without_a_mount_namespace_it_says_what_is_missing_in_one_line(tmp_path):
    bin_dir, cache = tmp_path / "bin", tmp_path / "cache"
    bin_dir.mkdir()
    (bin_dir / "unshare").write_text("#!/bin/sh\necho 'unshare: unshare failed: Operation not permitted' >&2\nexit 1\n")
    (bin_dir / "unshare").chmod(0o755)
    (cache / "debian-trixie-root").mkdir(parents=True)
    (cache / "debian-trixie-root" / ".hapticsculpt-stamp").write_text("x\n")
    env = dict(os.environ, PATH=f"{bin_dir}:{os.environ['PATH']}", HS_CACHE=str(cache))
    r = subprocess.run([SCRIPT, "trixie", "run", "true"], capture_output=True, text=True, env=env, timeout=60)
    assert r.returncode == 77, r.stdout + r.stderr
    lines = r.stderr.strip().splitlines()
    assert lines == ["Debian trixie root: skipped: this machine cannot make a mount namespace "
                     "(unshare --mount needs CAP_SYS_ADMIN)"]
