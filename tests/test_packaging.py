"""How the addon finds its native core, and what the Addon Manager reads from package.xml.

The wheel itself is built, installed and used by the addon-install test (tests/addon_install.py,
make test-addon); here: the import order, its messages, and the install folder's rule."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap

import pytest
from freecad_support import ROOT, run_freecadcmd

sys.path.insert(0, os.path.join(ROOT, "tools"))
import install_core  # noqa: E402

PYTHON = "/usr/bin/python3"  # FreeCAD's interpreter, which the in-tree core is built for


def origin_of(tmp_path, package_root: str, env: dict[str, str], fake_installed: str | None = None) -> str:
    """NATIVE_ORIGIN (or the ImportError's text) of ``import HapticSculpt.core`` in a new Python whose
    path has ``package_root`` and, with ``fake_installed``, a module hapticsculpt_core of that text."""
    paths = [package_root]
    if fake_installed is not None:
        site = tmp_path / "site"
        site.mkdir(exist_ok=True)
        (site / "hapticsculpt_core.py").write_text(textwrap.dedent(fake_installed))
        paths.insert(0, str(site))
    script = ("import sys; sys.path[:0] = %r\n"
              "try:\n    import HapticSculpt.core as c; print(c.NATIVE_ORIGIN)\n"
              "except ImportError as e:\n    print('IMPORT ERROR:', e)\n" % paths)
    clean = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "HAPTICSCULPT_CORE")}
    proc = subprocess.run([PYTHON, "-c", script], env=dict(clean, **env), capture_output=True, text=True,
                          timeout=60, cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.strip()


#: A stand-in for an installed hapticsculpt_core: the in-tree module under the package's name.
FAKE_INSTALLED = """
    from HapticSculpt import _core
    globals().update({{k: v for k, v in vars(_core).items() if not k.startswith("__")}})
    __version__ = {version!r}
"""


def test_in_tree_build_is_used_when_nothing_is_installed(tmp_path):
    assert origin_of(tmp_path, ROOT, {}).startswith("in-tree build HapticSculpt._core 0.2.0 (")


def test_an_installed_core_comes_first_and_the_variable_turns_the_order(tmp_path):
    fake = FAKE_INSTALLED.format(version="0.2.0")
    assert origin_of(tmp_path, ROOT, {}, fake).startswith("installed package hapticsculpt_core 0.2.0 (")
    assert origin_of(tmp_path, ROOT, {"HAPTICSCULPT_CORE": "in-tree"}, fake).startswith("in-tree build")
    assert "HAPTICSCULPT_CORE='newest'" in origin_of(tmp_path, ROOT, {"HAPTICSCULPT_CORE": "newest"}, fake)


def test_an_installed_core_of_another_version_is_passed_over_and_said(tmp_path):
    said = origin_of(tmp_path, ROOT, {}, FAKE_INSTALLED.format(version="0.1.0"))
    assert said.startswith("in-tree build"), said
    assert "is version 0.1.0, this addon is 0.2.0" in said


def test_without_a_core_the_error_says_both_ways_to_get_one(tmp_path):
    copy = tmp_path / "addon"
    shutil.copytree(os.path.join(ROOT, "HapticSculpt"), copy / "HapticSculpt",
                    ignore=shutil.ignore_patterns("*.so", "__pycache__"))
    said = origin_of(tmp_path, str(copy), {})
    assert said.startswith("IMPORT ERROR: HapticSculpt 0.2.0 finds no native core"), said
    assert "No module named 'hapticsculpt_core'" in said
    assert "tools/install_core.py WHEEL" in said and "make build" in said


def test_install_folder_is_the_one_each_freecad_reads():
    assert install_core.packages_folder({"user": "/h/", "version": [0, 20], "python": [3, 11]}) == \
        "/h/AdditionalPythonPackages"
    assert install_core.packages_folder({"user": "/h/", "version": [1, 0], "python": [3, 13]}) == \
        "/h/AdditionalPythonPackages/py313"


def test_install_refuses_a_wheel_for_another_python(tmp_path, capsys):
    wheel = tmp_path / "hapticsculpt_core-0.2.0-cp39-cp39-manylinux_2_34_x86_64.whl"
    wheel.write_bytes(b"")
    with pytest.raises(SystemExit):
        install_core.main([str(wheel), "--freecad-home", str(tmp_path / "home")])
    assert "take the wheel whose name has -cp3" in capsys.readouterr().err


def test_a_windows_freecad_takes_the_windows_wheel_and_linux_the_others():
    windows = {"user": "C:/u/", "version": [1, 0], "python": [3, 11], "windows": True}
    linux = {"user": "/h/", "version": [0, 20], "python": [3, 11], "windows": False}
    win_wheel, linux_wheel = ("hapticsculpt_core-0.2.0-cp311-cp311-win_amd64.whl",
                              "hapticsculpt_core-0.2.0-cp311-cp311-manylinux_2_34_x86_64.whl")
    assert install_core.wrong_wheel(win_wheel, windows) is None
    assert install_core.wrong_wheel(linux_wheel, linux) is None
    assert "-win_amd64.whl" in install_core.wrong_wheel(linux_wheel, windows)
    assert "not a Windows one" in install_core.wrong_wheel(win_wheel, linux)
    assert "-cp313-" in install_core.wrong_wheel(win_wheel, dict(windows, python=[3, 13]))


def test_addon_manager_reads_the_core_as_a_python_dependency(tmp_path):
    """FreeCAD's own Addon Manager code (0.20's and 1.0's) lists the wheel's package among the
    Python packages it would pip-install with the addon."""
    got = run_freecadcmd(f"""
        import os, sys
        import FreeCAD
        sys.path.insert(0, os.path.join(FreeCAD.getResourceDir(), "Mod", "AddonManager"))
        from Addon import Addon
        addon = Addon("HapticSculpt", "https://github.com/hapticsculpt/HapticSculpt", Addon.Status.NOT_INSTALLED,
                      "main")
        addon.load_metadata_file({os.path.join(ROOT, "package.xml")!r})
        deps = Addon.Dependencies()
        addon.walk_dependency_tree({{}}, deps)
        found = getattr(deps, "python_requires", None) or getattr(deps, "python_required")
        answer({{"python": sorted(found)}})
    """, str(tmp_path))
    assert got["python"] == ["hapticsculpt-core", "numpy"]


def test_install_realtime_grants_the_user_an_rtprio_limit(tmp_path):
    out = subprocess.run(["make", "-s", "install-realtime", f"LIMITS_DIR={tmp_path}", "RT_USER=alice", "SUDO="],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "90-hapticsculpt.conf").read_text() == "alice - rtprio 50\n"
    assert "next login" in out.stdout
