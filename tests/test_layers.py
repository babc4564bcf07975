"""The layers (tools/architecture.py): the C++ core's includes and the package's imports run downward
only, without cycles; only core.py picks the native module, the live surface's private core surface stays private, no Qt binding, importing the package loads no
GUI, and docs/architecture.dot and docs/architecture_core.dot are generated from the code as it is."""
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


def test_the_core_includes_run_downward_without_cycles():
    assert architecture.core_violations() == []
    assert not [f for f in architecture.core_files() if "/" not in f], "files loose in native_core/src"


def test_the_core_rules_catch_upward_sideways_and_loose_includes(tmp_path, monkeypatch):
    """The check above fails on a core that breaks the rules: an include planted upward (geometry
    includes the runtime), one across device families, a file outside the layers, an include not
    by its layer path, and a cycle."""
    src = tmp_path / "native_core" / "src"
    plant = {
        "geometry/knot_vector.hpp": '#include "runtime/haptic_runtime.hpp"\n',
        "runtime/haptic_runtime.hpp": '#include "geometry/knot_vector.hpp"\n',
        "devices/hid/spacemouse.hpp": '#include "devices/device.hpp"\n#include "devices/falcon/falcon_usb.hpp"\n',
        "devices/device.hpp": "",
        "devices/falcon/falcon_usb.hpp": '#include "falcon_frames.hpp"\n',
        "loose.hpp": "",
    }
    for name, text in plant.items():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        (src / name).write_text(text)
    monkeypatch.setattr(architecture, "ROOT", tmp_path)
    assert architecture.core_violations() == [
        'include not by its layer path: devices/falcon/falcon_usb.hpp includes "falcon_frames.hpp"',
        "sideways include: devices/hid/spacemouse.hpp (devices/hid) includes devices/falcon/falcon_usb.hpp (devices/falcon)",
        "upward include: geometry/knot_vector.hpp (geometry) includes runtime/haptic_runtime.hpp (runtime)",
        "outside the layers: loose.hpp",
        "include cycle: geometry/knot_vector.hpp -> runtime/haptic_runtime.hpp -> geometry/knot_vector.hpp"]


def test_the_bindings_mirror_the_core_layers():
    """One binding file per layer of the core (devices in two: HID and force devices), each
    including its own layer and those below."""
    bindings = ROOT / "native_core" / "bindings"
    files = {p.stem for p in bindings.glob("*.cpp")}
    for layer in architecture.CORE_LAYERS[1:]:
        assert layer in files, f"no bindings/{layer}.cpp"
    rank = {name: i for i, name in enumerate(architecture.CORE_LAYERS)}
    for path in bindings.glob("*.cpp"):
        own = {"hid_devices": "devices", "force_devices": "devices"}.get(path.stem, path.stem)
        if own not in rank:
            continue  # module.cpp, convert.cpp: the module itself
        for inc in architecture.core_includes(path):
            layer = inc.split("/")[0]
            assert layer not in rank or rank[layer] <= rank[own], f"{path.name} includes {inc}"


def test_the_core_picture_is_generated_from_the_code():
    committed = architecture.CORE_DOT.read_text()
    assert committed == architecture.core_dot(architecture.core_graph()), \
        "docs/architecture_core.dot is out of date: run `python3 tools/architecture.py` and commit it"
    assert architecture.CORE_DOT.with_suffix(".svg").is_file()
