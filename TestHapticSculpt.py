"""HapticSculpt's FreeCAD-layer tests for FreeCAD's test runner: `freecadcmd -t TestHapticSculpt`
(registered in Init.py). The same tests run under pytest (`make test`)."""
import glob
import importlib.util
import os
import sys
import unittest

import HapticSculpt

_TESTS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(HapticSculpt.__file__))), "tests")
if _TESTS not in sys.path:
    sys.path.insert(0, _TESTS)  # for freecad_support


def _load(path):
    name = "hapticsculpt_tests." + os.path.splitext(os.path.basename(path))[0]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


for _path in sorted(glob.glob(os.path.join(_TESTS, "test_freecad_*.py"))):
    for _name, _value in vars(_load(_path)).items():
        if isinstance(_value, type) and issubclass(_value, unittest.TestCase) and _name.startswith("Test"):
            globals()[_name] = _value
