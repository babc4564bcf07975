"""A sculpting session: the C++ simulation and haptic threads over one Sculpt object and a device.

The workbench owns sessions: closing the document, deleting the object, leaving the workbench, an
error in a loop or a lost device stops them (the force goes to zero first, then the threads join).
Each stroke (a grab released) becomes one undo transaction when the session is polled: by the GUI's
timer while FreeCAD's GUI runs, by :meth:`Session.poll` / :meth:`Session.wait` in console mode, and
always at :meth:`Session.stop`.
"""
from __future__ import annotations

import time
import weakref
from typing import Any

import numpy as np

from . import _core, core, sculpt_state
from .replay_device import ReplayDevice
from .sculpt_feature import is_sculpt, read_state
from .undo import transaction

#: Sessions that may still run, so a document close or a workbench change can stop them all.
_ACTIVE: "weakref.WeakSet[Session]" = weakref.WeakSet()


def native_device(device: Any) -> Any:
    """The C++ device for a Python-side device description."""
    if isinstance(device, _core.Device):
        return device
    native = getattr(device, "native", None)
    if isinstance(native, _core.Device):
        return native
    raise TypeError(f"device: expected a ReplayDevice or a HapticSculpt device, got {type(device).__name__}")


class Session:
    """Runs the threaded loops over a Sculpt object; see the module docstring for its life cycle."""

    def __init__(self) -> None:
        self._runtime: Any = None
        self._obj: Any = None
        self._device: Any = None
        self._error = ""
        self._timer: Any = None
        self._frame_base: Any = None  # knots, weights, degrees for GUI frames (they do not change)
        self._start_args: dict[str, Any] = {}
        self._airbrush: dict[str, Any] = {"map": None}
        #: the newest pole snapshot the GUI received ((nu*nv, 3)), for overlays; None before one
        self.latest_poles: np.ndarray | None = None
        #: the newest snapshot of each map the airbrush sprayed this run ((rows, cols)), for overlays
        self.latest_maps: dict[str, np.ndarray] = {}

    # --- life cycle -------------------------------------------------------------------------------
    def start(self, obj: Any, device: Any, tool: str = "rope", haptic_rate: float = 1000.0,
              sim_dt: float = 5e-4, max_force: float = 0.0, max_stiffness: float = 0.0,
              stale_limit: float = 0.02, record_seconds: float = 0.0, stop_when_finished: bool = False,
              realtime: bool = False) -> "Session":
        """Starts the loops. ``max_force``/``max_stiffness`` of 0 take the device's limits;
        ``record_seconds`` > 0 logs every haptic tick (for :meth:`recording` and benchmarks)."""
        if self._runtime is not None:
            raise RuntimeError("session: already started; stop it first")
        if not is_sculpt(obj):
            raise TypeError(f"obj: expected a HapticSculpt Sculpt object, got {getattr(obj, 'TypeId', type(obj).__name__)}")
        if tool not in core.TOOLS:
            raise ValueError(f"tool: unknown tool {tool!r} (one of {', '.join(core.TOOLS)})")
        proxy = obj.Proxy
        if getattr(proxy, "session", None) is not None and proxy.session.running:
            raise RuntimeError(f"obj: {obj.Label} is already being sculpted by another session")
        native = native_device(device)
        surface = proxy.surface
        if surface.tool.name != tool:
            surface.set_tool(tool)
        runtime = _core.HapticRuntime(surface, native, haptic_rate=haptic_rate, sim_dt=sim_dt, max_force=max_force,
                                      max_stiffness=max_stiffness, stale_limit=stale_limit, log_seconds=record_seconds,
                                      stop_when_finished=stop_when_finished, realtime=realtime)
        self._runtime, self._obj, self._device, self._error = runtime, obj, native, ""
        self._start_args = dict(device=device, tool=tool, haptic_rate=haptic_rate, sim_dt=sim_dt, max_force=max_force,
                                max_stiffness=max_stiffness, stale_limit=stale_limit, record_seconds=record_seconds,
                                stop_when_finished=stop_when_finished, realtime=realtime)
        proxy.session = self
        self.latest_maps = {}
        runtime.set_airbrush(**self._airbrush)
        runtime.start()
        _ACTIVE.add(self)
        _Observer.ensure()
        if _gui_up():
            self._frame_base = read_state(obj)
            self._start_timer()
        return self

    def stop(self, commit: bool = True) -> dict[str, Any]:
        """Zeroes the force, joins the threads, commits the remaining strokes (unless ``commit`` is
        False, e.g. when the document is going away) and returns the final status."""
        runtime = self._runtime
        if runtime is None:
            return {}
        self._stop_timer()
        runtime.stop()
        status = runtime.status()
        self._error = status["error"]
        obj, self._obj = self._obj, None
        self._runtime = None
        _ACTIVE.discard(self)
        if obj is not None:
            obj.Proxy.session = None
            if commit and _alive(obj):
                self._commit_strokes(runtime, obj)
                self._commit_final(obj)
        self._last_runtime = runtime  # logs stay readable (recording, force errors)
        return status

    def edit(self, change: Any, title: str) -> Any:
        """Applies ``change(surface)`` to the sculpted surface as one undo transaction. The
        simulation owns the surface while the loops run, so they are stopped (strokes committed,
        force to zero) for the edit and started again with the same device and settings."""
        obj = self._obj
        if obj is None:
            raise RuntimeError("session: not running")
        args = dict(self._start_args)
        self.stop()
        try:
            result = change(obj.Proxy.surface)
            from .api import _commit
            _commit(obj, title)
        finally:
            args["tool"] = obj.Proxy.surface.tool.name
            self.start(obj, **args)
        return result

    def set_airbrush(self, map: str | None, radius: float = 0.08, factor: float = 3.0, strength: float = 0.25,
                     rate: float = 30.0) -> None:
        """Switches the airbrush: while ``map`` ("mass", "damping", "stiffness") is set, the device's
        button sprays that map instead of grabbing (the tool lets go, no force), a dab every
        1/``rate`` s at the mass point nearest the cursor moving it toward ``factor`` times its mean
        at the spray's start (``radius`` in map coordinates, the unit square). Each spray becomes one
        undo transaction like a stroke. ``None`` switches it off. Kept across edits and restarts."""
        if map is not None and map not in core.MAPS:
            raise ValueError(f"map: one of {', '.join(core.MAPS)}, or None (off)")
        settings = dict(map=map, radius=float(radius), factor=float(factor), strength=float(strength), rate=float(rate))
        if self._runtime is not None:
            self._runtime.set_airbrush(**settings)  # validates the numbers, naming the bad one
        else:
            _core.HapticRuntime.validate_airbrush(**settings)
        self._airbrush = settings

    @property
    def airbrush(self) -> str | None:
        """The map the airbrush sprays, None when it is off."""
        return self._airbrush["map"]

    @property
    def running(self) -> bool:
        """True while both loops run."""
        return self._runtime is not None and self._runtime.running

    def status(self) -> dict[str, Any]:
        """Loop rates, haptic period jitter (p50/p99/max, ms), simulation steps per second, current
        force, strokes, and the error that stopped it (empty if none)."""
        runtime = self._runtime or getattr(self, "_last_runtime", None)
        if runtime is None:
            return {"running": False, "error": self._error}
        return runtime.status()

    def poll(self) -> int:
        """Commits finished strokes (one undo transaction each); stops the session if a loop stopped
        by itself. Returns the number of strokes committed."""
        runtime, obj = self._runtime, self._obj
        if runtime is None:
            return 0
        if obj is None or not _alive(obj):
            self.stop(commit=False)
            return 0
        n = self._commit_strokes(runtime, obj)
        if not runtime.running:
            self.stop()
        return n

    def wait(self, timeout: float | None = None, interval: float = 0.05) -> bool:
        """Polls until the session stops by itself (a finished replay, an error); True if it did."""
        end = None if timeout is None else time.monotonic() + timeout
        while self._runtime is not None and self._runtime.running:
            if end is not None and time.monotonic() >= end:
                return False
            self.poll()
            time.sleep(interval)
        if self._runtime is not None:
            self.stop()
        return True

    def recording(self) -> ReplayDevice:
        """The cursor as the haptic loop read it, tick by tick (needs ``record_seconds``), as a
        ReplayDevice: save it, and replaying it reproduces every sample exactly."""
        runtime = self._runtime or getattr(self, "_last_runtime", None)
        if runtime is None or runtime.running:
            raise RuntimeError("session: stop it before taking its recording")
        ticks = runtime.ticks()
        if len(ticks["t"]) == 0:
            raise RuntimeError("session: nothing recorded (start it with record_seconds > 0)")
        return ReplayDevice(ticks["t"], ticks["position"], ticks["orientation"], ticks["buttons"].astype(np.int64))

    def force_errors(self, floor: float = 0.05) -> np.ndarray:
        """Relative error of each logged haptic force against the exact surface (see the core)."""
        runtime = self._runtime or getattr(self, "_last_runtime", None)
        if runtime is None or runtime.running:
            raise RuntimeError("session: stop it before analysing it")
        return np.asarray(runtime.force_errors(floor))

    def __del__(self) -> None:
        try:
            if self._runtime is not None:
                self._runtime.stop()
        except Exception:  # noqa: BLE001 - never raise from a finaliser
            pass

    # --- strokes -> undo transactions -------------------------------------------------------------
    def _commit_strokes(self, runtime: Any, obj: Any) -> int:
        n = 0
        while (stroke := runtime.take_stroke()) is not None:
            painted = stroke["painted"]
            with transaction(obj.Document, f"Paint {painted}" if painted else "Sculpt stroke"):
                obj.Proxy.write_arrays(stroke["poles"], stroke["velocities"], stroke["rest_lengths"],
                                       (painted, stroke["map_shape"], stroke["map_values"]) if painted else None)
                obj.Strokes = obj.Strokes + 1
                obj.purgeTouched()
            n += 1
        return n

    def _commit_final(self, obj: Any) -> None:
        """The state after the last stroke (the surface kept moving) as its own transaction."""
        current = sculpt_state.capture(obj.Proxy.surface)
        stored = read_state(obj)
        if all(np.array_equal(current.arrays[k], stored.arrays[k]) for k in current.arrays) and \
                current.settings_json() == obj.SculptSettings:
            return
        from .api import _commit
        _commit(obj, "Sculpt session end")

    # --- GUI: shape at graphics rate, strokes as they end ----------------------------------------
    def _start_timer(self) -> None:
        from pivy import coin
        self._timer = coin.SoTimerSensor(lambda *_: self._on_frame(), None)
        self._timer.setInterval(coin.SbTime(1.0 / 30.0))
        self._timer.schedule()

    def _stop_timer(self) -> None:
        if self._timer is not None:
            self._timer.unschedule()
            self._timer = None

    def _on_frame(self) -> None:
        runtime, obj = self._runtime, self._obj
        if runtime is None or obj is None:
            return
        poles = runtime.take_poles()
        if poles is not None and _alive(obj):
            self.latest_poles = poles
            obj.Proxy.show_poles(poles, self._frame_base)
        painted = runtime.take_painted_map()
        if painted is not None:
            self.latest_maps[painted["map"]] = painted["values"]
        self.poll()


def stop_all(commit: bool = True) -> None:
    """Stops every running session (workbench change, application exit)."""
    for session in list(_ACTIVE):
        session.stop(commit=commit)


def _gui_up() -> bool:
    try:
        import FreeCAD
    except ImportError:
        return False
    return bool(getattr(FreeCAD, "GuiUp", False))


def _alive(obj: Any) -> bool:
    try:
        return obj.Document is not None and obj.Document.getObject(obj.Name) is obj
    except Exception:  # noqa: BLE001 - a deleted object raises on any access
        return False


class _Observer:
    """FreeCAD document observer: a closing document or a deleted object stops its sessions."""

    _installed: "_Observer | None" = None

    @classmethod
    def ensure(cls) -> None:
        if cls._installed is None:
            import FreeCAD
            cls._installed = cls()
            FreeCAD.addDocumentObserver(cls._installed)

    def slotDeletedDocument(self, doc: Any) -> None:
        for session in list(_ACTIVE):
            obj = session._obj
            if obj is None or getattr(obj, "Document", None) is doc:
                session.stop(commit=False)

    def slotDeletedObject(self, obj: Any) -> None:
        for session in list(_ACTIVE):
            if session._obj is obj:
                session.stop(commit=False)


def edit_surface(obj: Any, change: Any, title: str) -> Any:
    """Applies ``change(surface)`` to a sculpt object's surface as one undo transaction, through its
    session when one runs (see :meth:`Session.edit`)."""
    if not is_sculpt(obj):
        raise TypeError(f"obj: expected a HapticSculpt Sculpt object, got {type(obj).__name__}")
    session = getattr(obj.Proxy, "session", None)
    if session is not None and session.running:
        return session.edit(change, title)
    result = change(obj.Proxy.surface)
    from .api import _commit
    _commit(obj, title)
    return result
