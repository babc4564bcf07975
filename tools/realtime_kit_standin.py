"""A stand-in for rtkit-daemon on a system bus of its own, for tests and benchmarks of real-time
priority without root (rtkit-daemon itself needs the machine's system bus and polkit).

It serves org.freedesktop.RealtimeKit1 at /org/freedesktop/RealtimeKit1 with what HapticSculpt
uses of it, and checks what rtkit checks before it grants: the thread belongs to the calling
process, the priority is at most MaxRealtimePriority, and the caller's RLIMIT_RTTIME is set and at
most RTTimeUSecMax. It then makes the thread SCHED_FIFO (with SCHED_RESET_ON_FORK, as rtkit does),
so it must run as root; each grant or refusal is a line on stdout.

    with private_system_bus(standin=True) as address:   # a dbus-daemon and the stand-in
        ... DBUS_SYSTEM_BUS_ADDRESS=address ...

As a script: ``realtime_kit_standin.py ADDRESS [--refuse-all]`` serves on the bus at ADDRESS until killed.
"""
from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import tempfile
from typing import Iterator

SERVICE = "org.freedesktop.RealtimeKit1"
PATH = "/org/freedesktop/RealtimeKit1"
#: rtkit's defaults.
MAX_PRIORITY = 20
RTTIME_USEC_MAX = 200000
MIN_NICE = -15

BUS_CONFIG = """<!DOCTYPE busconfig PUBLIC "-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN"
 "http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd">
<busconfig>
  <type>system</type>
  <listen>unix:path={socket}</listen>
  <auth>EXTERNAL</auth>
  <policy context="default">
    <allow user="*"/>
    <allow own="*"/>
    <allow send_destination="*"/>
    <allow receive_sender="*"/>
  </policy>
</busconfig>
"""


def _rttime_limit(pid: int) -> int | None:
    """The process's soft RLIMIT_RTTIME in microseconds (None: unlimited)."""
    with open(f"/proc/{pid}/limits", encoding="utf-8") as f:
        for line in f:
            if line.startswith("Max realtime timeout"):
                soft = line.split()[3]
                return None if soft == "unlimited" else int(soft)
    return None


def serve(address: str, refuse_all: bool = False) -> None:
    """Serves the stand-in on the bus at ``address`` until killed (``refuse_all``: an rtkit whose
    policy grants nothing, as a locked-down machine's may)."""
    import dbus
    import dbus.mainloop.glib
    import dbus.service
    from gi.repository import GLib

    dbus.mainloop.glib.DBusGMainLoop(set_as_default=True)
    bus = dbus.bus.BusConnection(address)
    daemon = dbus.Interface(bus.get_object("org.freedesktop.DBus", "/org/freedesktop/DBus"), "org.freedesktop.DBus")

    def refuse(why: str) -> None:
        print(f"refused: {why}", flush=True)
        raise dbus.DBusException(why, name="org.freedesktop.DBus.Error.AccessDenied")

    class RealtimeKit(dbus.service.Object):
        @dbus.service.method(SERVICE, in_signature="tu", sender_keyword="sender")
        def MakeThreadRealtime(self, thread: int, priority: int, sender: str | None = None) -> None:
            self.grant(int(daemon.GetConnectionUnixProcessID(sender)), int(thread), int(priority))

        @dbus.service.method(SERVICE, in_signature="ttu")
        def MakeThreadRealtimeWithPID(self, process: int, thread: int, priority: int) -> None:
            self.grant(int(process), int(thread), int(priority))

        @dbus.service.method(SERVICE, in_signature="ti", sender_keyword="sender")
        def MakeThreadHighPriority(self, thread: int, nice: int, sender: str | None = None) -> None:
            if nice < MIN_NICE:
                refuse(f"nice {nice} is below {MIN_NICE}")
            os.setpriority(os.PRIO_PROCESS, int(thread), int(nice))

        @dbus.service.method("org.freedesktop.DBus.Properties", in_signature="ss", out_signature="v")
        def Get(self, interface: str, name: str):  # noqa: N802 - D-Bus's name
            values = {"MaxRealtimePriority": dbus.Int32(MAX_PRIORITY), "RTTimeUSecMax": dbus.Int64(RTTIME_USEC_MAX),
                      "MinNiceLevel": dbus.Int32(MIN_NICE)}
            if interface != SERVICE or name not in values:
                raise dbus.DBusException(f"no property {interface}.{name}", name="org.freedesktop.DBus.Error.InvalidArgs")
            return values[name]

        def grant(self, pid: int, thread: int, priority: int) -> None:
            if refuse_all:
                refuse("this RealtimeKit grants nothing")
            if not 1 <= priority <= MAX_PRIORITY:
                refuse(f"priority {priority} is not in 1..{MAX_PRIORITY}")
            if not os.path.isdir(f"/proc/{pid}/task/{thread}"):
                refuse(f"thread {thread} is not one of process {pid}'s")
            limit = _rttime_limit(pid)
            if limit is None or limit > RTTIME_USEC_MAX:
                refuse(f"process {pid} has RLIMIT_RTTIME {limit}, not at most {RTTIME_USEC_MAX}")
            os.sched_setscheduler(thread, os.SCHED_FIFO | os.SCHED_RESET_ON_FORK, os.sched_param(priority))
            print(f"granted: pid {pid} thread {thread} priority {priority}", flush=True)

    RealtimeKit(bus, PATH)
    bus.request_name(SERVICE)
    print("ready", flush=True)
    GLib.MainLoop().run()


@contextlib.contextmanager
def private_system_bus(standin: bool = True, log: list[str] | None = None, refuse_all: bool = False) -> Iterator[str]:
    """A dbus-daemon on a socket anyone may use, with the stand-in on it (``standin``; granting
    nothing with ``refuse_all``); yields its address. The stand-in's lines go to ``log`` when the
    bus closes."""
    if shutil.which("dbus-daemon") is None:
        raise RuntimeError("dbus-daemon is not installed (Debian: dbus-daemon)")
    folder = tempfile.mkdtemp(prefix="hs-bus-")
    os.chmod(folder, 0o755)  # (a user who is not root connects to the socket in it)
    config = os.path.join(folder, "bus.conf")
    socket = os.path.join(folder, "system_bus_socket")
    with open(config, "w", encoding="utf-8") as f:
        f.write(BUS_CONFIG.format(socket=socket))
    bus = subprocess.Popen(["dbus-daemon", f"--config-file={config}", "--nofork", "--print-address"],
                           stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    server = None
    try:
        address = bus.stdout.readline().strip()
        if not address:
            raise RuntimeError("dbus-daemon did not start")
        if standin:
            server = subprocess.Popen([sys.executable, os.path.abspath(__file__), address]
                                      + (["--refuse-all"] if refuse_all else []), stdout=subprocess.PIPE, text=True)
            if server.stdout.readline().strip() != "ready":
                raise RuntimeError("the RealtimeKit stand-in did not start")
        yield address
    finally:
        if server is not None:
            server.terminate()
            out, _ = server.communicate(timeout=10)
            if log is not None:
                log.extend(out.splitlines())
        bus.terminate()
        bus.wait(timeout=10)
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    serve(sys.argv[1], "--refuse-all" in sys.argv[2:])
