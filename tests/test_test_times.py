"""tools/test_times.py: a make test log's table ends with what failed, so a CI log's tail says it."""
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "tools", "test_times.py")

LOG = """\
[bookworm gui] == [part] bookworm gui: start 100.0
[trixie python] == [part] trixie python: start 101.0
[bookworm gui] tests/test_gui_undo.py ....F
[trixie python] 120 passed
[bookworm gui] FAILED tests/test_gui_undo.py::test_undo - TimeoutError: no dialog in 30 s
[trixie python] == [part] trixie python: 50 s, CPU 40 s, exit 0 (151.0)
[bookworm gui] == [part] bookworm gui: 300 s, CPU 90 s, exit 1 (400.0)
[forky cpp] == [part] forky cpp: start 402.0
"""


def test_the_table_ends_with_the_failed_parts_and_their_failure_lines(tmp_path):
    log = tmp_path / "make-test.log"
    log.write_text(LOG)
    run = subprocess.run([sys.executable, SCRIPT, str(log)], capture_output=True, text=True)
    assert run.returncode == 1
    tail = run.stdout.split("\n\nFAILED: ", 1)[1]
    assert tail.startswith("bookworm gui (exit 1)\n  FAILED tests/test_gui_undo.py::test_undo - TimeoutError")
    assert "FAILED: forky cpp (did not end)" in run.stdout
    assert "trixie python (" not in tail
