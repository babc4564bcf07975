"""Real-time priority without root: a user who is not root and has no rtprio limit gets SCHED_FIFO
for the haptic thread from RealtimeKit, over the D-Bus system bus (the core's own client: no libdbus).
Against a stand-in for rtkit-daemon on a bus of the test's own (tools/realtime_kit_standin.py: it
checks what rtkit checks, then grants for real), the session status says which way the thread got
its priority, or why it got none: no bus, no RealtimeKit on it, or a RealtimeKit that refuses."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from realtime_kit_standin import MAX_PRIORITY, RTTIME_USEC_MAX, private_system_bus  # noqa: E402

NOBODY = 65534
pytestmark = pytest.mark.skipif(
    os.geteuid() != 0 or shutil.which("setpriv") is None or shutil.which("dbus-daemon") is None,
    reason="runs a stand-in rtkit (it sets SCHED_FIFO, as root) and a session as another user (setpriv): "
           "needs root, setpriv and dbus-daemon (make deps installs it)")

#: A session's haptic thread starts, and says how it got its priority; then the threads that are
#: SCHED_FIFO and this process's RLIMIT_RTTIME.
CLIENT = """
import json, os, resource, sys, time
sys.path[:0] = [ROOT, os.path.join(ROOT, "bench")]
from HapticSculpt import core
from HapticSculpt.core import native as _core
import loops
runtime = _core.HapticRuntime(core.patch((8, 8), (3, 3), (24, 24), (100.0, 100.0)), loops.trajectory(2.0).native,
                              haptic_rate=1000, sim_dt=1e-3, stop_when_finished=True)
runtime.start()
t = time.monotonic()
while not runtime.status()["realtime_how"] and time.monotonic() - t < 20:
    time.sleep(0.01)
status = runtime.status()
fifo = [int(t) for t in os.listdir("/proc/self/task")
        if os.sched_getscheduler(int(t)) & ~os.SCHED_RESET_ON_FORK == os.SCHED_FIFO]
runtime.stop()
print(json.dumps({"uid": os.getuid(), "how": status["realtime_how"], "ok": status["realtime_priority"],
                  "fifo_threads": fifo, "rttime": resource.getrlimit(resource.RLIMIT_RTTIME)[0]}))
"""


def session_as_nobody(address: str | None) -> dict:
    """CLIENT run as user nobody (no rtprio limit, no capabilities) with the system bus at ``address``."""
    folder = tempfile.mkdtemp(prefix="hs-rt-")
    try:
        os.chmod(folder, 0o755)  # (nobody reads the script)
        script = os.path.join(folder, "client.py")
        with open(script, "w", encoding="utf-8") as f:
            f.write(f"ROOT = {ROOT!r}\n" + CLIENT)
        env = {k: v for k, v in os.environ.items() if k != "DBUS_SYSTEM_BUS_ADDRESS"}
        env["DBUS_SYSTEM_BUS_ADDRESS"] = address or f"unix:path={folder}/no_bus_here"
        env["HOME"] = folder
        proc = subprocess.run(["setpriv", f"--reuid={NOBODY}", f"--regid={NOBODY}", "--clear-groups", "--inh-caps=-all",
                               sys.executable, script], env=env, capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, proc.stderr[-3000:]
        return json.loads(proc.stdout.strip().splitlines()[-1])
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def test_a_user_who_is_not_root_gets_sched_fifo_from_realtime_kit():
    log: list[str] = []
    with private_system_bus(log=log) as address:
        got = session_as_nobody(address)
    assert got["uid"] == NOBODY
    assert got["ok"] and got["how"] == f"SCHED_FIFO {MAX_PRIORITY} from RealtimeKit", got
    assert len(got["fifo_threads"]) == 1, got  # the haptic thread alone
    assert 0 < got["rttime"] <= RTTIME_USEC_MAX, got  # (set before asking: rtkit refuses a process without it)
    assert log == [f"granted: pid {log[0].split()[2]} thread {got['fifo_threads'][0]} priority {MAX_PRIORITY}"], log


def test_without_realtime_kit_the_status_says_why():
    got = session_as_nobody(None)
    assert not got["ok"] and got["fifo_threads"] == [], got
    assert got["how"].startswith("none: the rtprio limit is 0; RealtimeKit: no D-Bus system bus at unix:path="), got
    with private_system_bus(standin=False) as address:
        got = session_as_nobody(address)
    assert not got["ok"] and got["fifo_threads"] == [], got
    assert "RealtimeKit: org.freedesktop.DBus.Error.ServiceUnknown" in got["how"], got


def test_a_realtime_kit_that_refuses_is_reported_and_the_session_runs_on():
    log: list[str] = []
    with private_system_bus(log=log, refuse_all=True) as address:
        got = session_as_nobody(address)
    assert not got["ok"] and got["fifo_threads"] == [], got
    assert got["how"].endswith("RealtimeKit: org.freedesktop.DBus.Error.AccessDenied: this RealtimeKit grants nothing"), got
    assert log == ["refused: this RealtimeKit grants nothing"], log


def _said(runtime) -> str:
    """The runtime's realtime_how once its haptic thread has said it (within 20 s)."""
    end = time.monotonic() + 20
    while not runtime.status()["realtime_how"] and time.monotonic() < end:
        time.sleep(0.005)
    return runtime.status()["realtime_how"]


def test_root_takes_it_directly():
    from HapticSculpt import core
    from HapticSculpt.core import native as _core
    sys.path.insert(0, os.path.join(ROOT, "bench"))
    import loops
    runtime = _core.HapticRuntime(core.patch((8, 8), (3, 3), (24, 24), (100.0, 100.0)), loops.trajectory(0.5).native,
                                  stop_when_finished=True)
    runtime.start()
    try:
        assert _said(runtime).endswith("(root)"), runtime.status()["realtime_how"]
    finally:
        runtime.stop()
    off = _core.HapticRuntime(core.patch((8, 8), (3, 3), (24, 24), (100.0, 100.0)), loops.trajectory(0.5).native,
                              stop_when_finished=True, realtime=False)
    off.start()
    try:
        assert _said(off) == "off" and not off.status()["realtime_priority"]
    finally:
        off.stop()
