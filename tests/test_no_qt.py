"""The project imports no Qt binding anywhere (commands go through FreeCADGui, drawing through pivy)."""
import pathlib
import re

from freecad_support import ROOT

QT = re.compile(r"^\s*(from|import)\s+(PySide\d?|PyQt\d|shiboken\d?|qtpy|Qt\b|FreeCADGui\s*\.\s*PySide)", re.M)


def test_no_file_imports_a_qt_binding():
    offenders = []
    for path in pathlib.Path(ROOT).rglob("*.py"):
        if any(part in ("build", ".git") for part in path.relative_to(ROOT).parts) or path.resolve() == pathlib.Path(__file__).resolve():
            continue  # (this file names the bindings it looks for)
        text = path.read_text(errors="replace")
        if QT.search(text) or "import PySide" in text or "from PySide" in text:
            offenders.append(str(path.relative_to(ROOT)))
    assert not offenders, offenders


def test_the_check_catches_an_import():
    assert QT.search("import os\nfrom PySide2 import QtGui\n")
    assert QT.search("    import PyQt5.QtCore\n")
    assert not QT.search("# PySide is not used here\n")
