"""The package's layers (tools/architecture.py): imports run downward only, no import cycles, only
core.py picks the native module, the live surface's private core surface stays private, no Qt binding, importing the package loads no
GUI, and docs/architecture.dot is generated from the code as it is."""
from __future__ import annotations

import ast
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import architecture  # noqa: E402

GRAPH = architecture.graph()


def test_every_module_belongs_to_a_layer_folder():
    loose = [m for m in GRAPH if architecture.layer(m) == "core"
             and m not in ("HapticSculpt.core", "HapticSculpt.version", architecture.NATIVE)]
    assert not loose, f"modules outside the layer folders: {loose}"


def test_only_core_py_picks_the_native_module():
    """HapticSculpt.core chooses between an installed hapticsculpt_core and the in-tree build; every
    other module (and the benchmarks and tests) takes ``core.native``, whichever it is (bench/builds.py
    compares the two builds, so it names both)."""
    assert [m for m in GRAPH if architecture.NATIVE in GRAPH[m]] == ["HapticSculpt.core"]
    for folder in ("bench", "tests", "tools"):
        for path in (ROOT / folder).rglob("*.py"):
            text = path.read_text()
            assert "from HapticSculpt import _core" not in text and "HapticSculpt._core" not in text \
                or path.name in ("test_packaging.py", "test_layers.py", "architecture.py", "builds.py"), path


def test_imports_run_downward_without_cycles():
    assert architecture.violations(GRAPH) == []


def test_the_rules_catch_an_upward_import_and_a_cycle(tmp_path, monkeypatch):
    """The check above fails on a package that breaks the rules (so it can fail)."""
    pkg = tmp_path / "HapticSculpt"
    for folder in ("app", "runtime", "gui"):
        (pkg / folder).mkdir(parents=True)
        (pkg / folder / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "app" / "a.py").write_text("from ..gui import b\n")
    (pkg / "gui" / "b.py").write_text("def f():\n    from ..app import a\n")
    (pkg / "runtime" / "c.py").write_text("import HapticSculpt\n")
    monkeypatch.setattr(architecture, "ROOT", tmp_path)
    monkeypatch.setattr(architecture, "PACKAGE", pkg)
    assert architecture.violations(architecture.graph()) == [
        "upward import: HapticSculpt.app.a (app) imports HapticSculpt.gui.b (gui)",
        "upward import: HapticSculpt.runtime.c (runtime) imports HapticSculpt (facade)",
        "import cycle: HapticSculpt.app.a -> HapticSculpt.gui.b -> HapticSculpt.app.a"]


def test_only_the_owner_reaches_the_core_surface():
    owner = ROOT / "HapticSculpt" / "app" / "live_surface.py"
    reached = []
    for path in list((ROOT / "HapticSculpt").rglob("*.py")) + list((ROOT / "tests").rglob("*.py")):
        if path == owner or path == pathlib.Path(__file__).resolve():
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and node.attr in ("_surface", "_commit"):
                reached.append(f"{path.relative_to(ROOT)}:{node.lineno} .{node.attr}")
    assert not reached, reached


def test_nothing_imports_a_qt_binding():
    qt = ("PySide", "PySide2", "PySide6", "PyQt4", "PyQt5", "PyQt6", "shiboken2", "shiboken6", "qtpy")
    found = []
    for path in ROOT.rglob("*.py"):
        if any(part.startswith(".") or part == "build" for part in path.relative_to(ROOT).parts):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            found += [f"{path.relative_to(ROOT)}:{node.lineno} {n}" for n in names if n.split(".")[0] in qt]
    assert not found, found


def test_importing_the_package_loads_no_gui_and_no_freecad():
    code = ("import sys, HapticSculpt\n"
            "print(sorted(m for m in sys.modules if m.startswith('HapticSculpt.gui') or "
            "m.split('.')[0] in ('FreeCAD', 'FreeCADGui', 'pivy')))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True,
                         env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.stdout.strip() == "[]", out.stdout


def test_the_architecture_picture_is_generated_from_the_code():
    committed = architecture.DOT.read_text()
    assert committed == architecture.dot(GRAPH), \
        "docs/architecture.dot is out of date: run `python3 tools/architecture.py` and commit both files"
    assert architecture.DOT.with_suffix(".svg").is_file()
