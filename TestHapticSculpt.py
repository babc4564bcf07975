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


def _shard():
    """HS_TEST_SHARD="k/n" (make check: two runners side by side) runs every n-th test class from
    the k-th (1-based), in file order; unset, all of them."""
    text = os.environ.get("HS_TEST_SHARD", "")
    if not text:
        return 0, 1
    k, n = (int(x) for x in text.split("/"))
    if not 1 <= k <= n:
        raise ValueError(f"HS_TEST_SHARD: k/n with 1 <= k <= n, not {text!r}")
    return k - 1, n


def _register():
    """Every test class of tests/test_freecad_*.py (of this shard) as a name of this module, where
    FreeCAD's runner finds them (nothing else here is a TestCase: a loop variable left holding the
    last class ran its tests twice)."""
    first, every = _shard()
    classes = [(name, value) for path in sorted(glob.glob(os.path.join(_TESTS, "test_freecad_*.py")))
               for name, value in vars(_load(path)).items()
               if isinstance(value, type) and issubclass(value, unittest.TestCase) and name.startswith("Test")
               and value.__module__.startswith("hapticsculpt_tests.")]  # (not the ones a file imports)
    globals().update(classes[first::every])


_register()
