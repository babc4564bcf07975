"""A sculpting session: the C++ simulation and haptic threads over one Sculpt object and a device.

The workbench owns sessions: closing the document, deleting the object, leaving the workbench, an
error in a loop or a lost device stops them (the force goes to zero first, then the threads join).
Each stroke (a grab released) becomes one undo transaction when the session is polled: by the GUI's
timer while FreeCAD's GUI runs, by :meth:`Session.poll` / :meth:`Session.wait` in console mode, and
always at :meth:`Session.stop`. Edits made meanwhile (``obj.Proxy.live.edit``) reach the running
simulation through the runtime's edit queue without stopping it, and are committed the same way
when the simulation has applied them; Undo and Redo restore the session's surface in place.

Macros: every commit a session makes (a stroke, a spray, an edit with the motion it took over) is
told to the commit listener (the GUI keeps it in the sculpt's StrokeLog and echoes one
``replay_stroke`` line) with, as its state before, the state a macro replayed in console mode holds
at that line: the session follows what each echoed line does there (an edit's own scripting call
acts on the document's state, not on the session's moving poles), so a macro with strokes and
edits interleaved replays to the same surface. :meth:`Session.stop` makes no undo step of its own:
what moved after the last commit (an elastic patch springing back) joins that commit's step.
"""
from __future__ import annotations

import time
import weakref
from typing import Any, Callable

import numpy as np

from .. import core
from ..app import curve_constraint, sculpt_state
from ..app.sculpt_feature import is_sculpt
from ..app.undo import transaction
from ..core import native as _core
from .devices import native_device
from .replay_device import ReplayDevice

#: Sessions that may still run, so a document close or a workbench change can stop them all.
_ACTIVE: "weakref.WeakSet[Session]" = weakref.WeakSet()

#: Calls a function at graphics rate until the returned function is called: installed by the GUI
#: layer when it loads (see HapticSculpt.gui), so a running session shows its shape and commits
#: its strokes as they end, and this layer never imports a GUI module.
FrameClock = Callable[[Callable[[], None]], Callable[[], None]]
_frame_clocks: list[FrameClock] = []


#: Called inside the transaction of each commit a session makes (a stroke, a spray, an applied edit
#: with the motion it took over) with the object, the state a macro replayed in console mode holds
#: before it (see the module docstring), the undo step's title and the strokes it counts: the GUI
#: layer installs one that keeps the change in the sculpt and echoes HapticSculpt.replay_stroke, so
#: a macro records it (and Undo forgets it with the commit). ``echo=False`` (a keyword, only when
#: False): the last commit's record amended at the stop, already echoed under the same name.
CommitListener = Callable[..., None]
_commit_listeners: list[CommitListener] = []


def set_commit_listener(*listeners: CommitListener | None) -> None:
    """Installs the listeners told of every stroke, spray and edit a session commits, in order
    (None or none: none, as in console mode)."""
    _commit_listeners[:] = [listener for listener in listeners if listener is not None]


def set_frame_clock(clock: FrameClock) -> None:
    """Installs the clock sessions use while FreeCAD's GUI runs."""
    _frame_clocks[:] = [clock]


class Session:
    """Runs the threaded loops over a Sculpt object; see the module docstring for its life cycle."""

    def __init__(self) -> None:
        self._runtime: Any = None
        self._obj: Any = None
        self._device: Any = None
        self._error = ""
        self._priority_said = False
        self.haptic_rate = 0.0  #: Hz: the haptic loop's rate while it runs (it polls at 100 Hz while idle)
        self._timer: Any = None
        self._frame_base: Any = None  # knots, weights, degrees for GUI frames (they do not change)
        self._previewed = False  # a held stroke's frames previewed on the objects built from the sculpt
        self._airbrush: dict[str, Any] = {"map": None}
        self._latest_poles: np.ndarray | None = None  # the newest pole snapshot the GUI received
        self._latest_maps: dict[str, np.ndarray] = {}  # the newest snapshot of each map sprayed this run
        self._next_edit = 1
        self._committed = False
        self._strokes_taken = 0  # stroke and spray ends taken from the runtime this run
        #: the stroke end to drop (its ordinal among those taken), set by drop_stroke while it is held
        self._drop: int | None = None
        self._dropped_in_stop = False
        self._edits: dict[int, tuple[str, sculpt_state.SculptState | None, int]] = {}  # posted, not yet applied
        #: the state a macro replayed in console mode holds after the lines echoed so far (None: not
        #: known, an edit's own call failed on it; the document's state stands in then)
        self._console: sculpt_state.SculptState | None = None
        #: the last commit: undo steps after it, its title and strokes, the console's state before it,
        #: whether the listener was told of it, whether it was made by stop()
        self._last_commit: tuple[int, str, int, sculpt_state.SculptState, bool, bool] | None = None
        #: each edit the simulation applied this run: its title, the simulation steps taken when it
        #: was posted and when it applied (it applies between two steps, so these differ by 0 to 2),
        #: and the simulated time it applied at (s since the start)
        self.applied_edits: list[dict[str, Any]] = []
        self._grab_from: np.ndarray | None = None  # the cursor where the held grab began (GUI frames)
        self._pulled = 0.0  # mm: how far the cursor went from there, in this grab or the last
        #: the last stroke committed: how far it moved the surface (largest pole displacement, mm),
        #: how far the cursor went from where it grabbed (mm, as the GUI's frames saw it; 0 in
        #: console mode), the mean stiffness and the held poles then, so that the HUD can say why
        #: when the material barely followed; None again after an Undo or Redo
        self.last_stroke: dict[str, float] | None = None

    # --- life cycle -------------------------------------------------------------------------------
    def start(self, obj: Any, device: Any, tool: str = "rope", haptic_rate: float | None = None,
              sim_dt: float | None = None, max_force: float = 0.0, max_stiffness: float = 0.0,
              stale_limit: float = 0.02, record_seconds: float = 0.0, stop_when_finished: bool = False,
              realtime: bool | None = None) -> "Session":
        """Starts the loops. ``haptic_rate``, ``sim_dt`` and ``realtime`` of None take the core's
        defaults (``core.DEFAULTS``). ``max_force``/``max_stiffness`` of 0 take the device's limits;
        ``record_seconds`` > 0 logs every haptic tick (for :meth:`recording` and benchmarks).
        ``realtime`` asks for real-time priority (SCHED_FIFO) for the haptic thread, which holds its
        1 ms period while other programs load the machine; Linux grants it to root or within an
        rtprio limit (README), else the thread asks RealtimeKit (rtkit-daemon, on the system bus, as
        audio applications do), else it runs as before: ``status()["realtime_priority"]``, and
        ``status()["realtime_how"]`` says which way it got it, or why it got none."""
        if self._runtime is not None:
            raise RuntimeError("session: already started; stop it first")
        if not is_sculpt(obj):
            raise TypeError(f"obj: expected a HapticSculpt Sculpt object, got {getattr(obj, 'TypeId', type(obj).__name__)}")
        if tool not in core.TOOLS:
            raise ValueError(f"tool: unknown tool {tool!r} (one of {', '.join(core.TOOLS)})")
        native = native_device(device)
        live = obj.Proxy.live
        if live.session is not None:
            if live.session.running:
                raise RuntimeError(f"obj: {obj.Label} is already being sculpted by another session")
            live.session.stop()  # its loops ended by themselves (a replay played out): commit and let go
        surface = live.surface
        if surface.tool.name != tool:
            sculpt_state.choose_tool(surface, tool)
        defaults = core.DEFAULTS
        haptic_rate = defaults["haptic_rate"] if haptic_rate is None else haptic_rate
        sim_dt = defaults["sim_dt"] if sim_dt is None else sim_dt
        realtime = defaults["realtime"] if realtime is None else realtime
        runtime = _core.HapticRuntime(surface, native, haptic_rate=haptic_rate, sim_dt=sim_dt, max_force=max_force,
                                      max_stiffness=max_stiffness, stale_limit=stale_limit, log_seconds=record_seconds,
                                      stop_when_finished=stop_when_finished, realtime=realtime)
        live.attach(self)  # from here on the runtime steps the surface, starting at rest
        self._runtime, self._obj, self._device, self._error = runtime, obj, native, ""
        self._priority_said = False
        self.haptic_rate = float(haptic_rate)
        self.sim_dt = float(sim_dt)
        self._latest_poles, self._latest_maps, self._edits, self.applied_edits = None, {}, {}, []
        self._previewed = False
        self._committed = False  # a stroke, spray or edit this run (else its end commits nothing)
        self._strokes_taken, self._drop, self._dropped_in_stop = 0, None, False
        self._restores: set[int] = set()  # posted edits that restore the document's state
        self._console, self._last_commit = obj.Proxy.live.stored(), None
        runtime.set_airbrush(**self._airbrush)
        runtime.start()
        _ACTIVE.add(self)
        _Observer.ensure()
        if _gui_up():
            self._frame_base = obj.Proxy.live.stored()
            self._start_timer()
        return self

    @property
    def device_name(self) -> str:
        """The name of the device this session runs with ("" when it is not running)."""
        return self._device.name if self._device is not None and self._runtime is not None else ""

    @property
    def priority(self) -> str:
        """How the haptic thread runs, in a few words for a status line: "real-time (RealtimeKit)",
        "real-time (rtprio limit)", "real-time (root)", "no real-time priority" or "off"; "" until
        the thread has said (``status()["realtime_how"]`` has the whole of it, and why not)."""
        how = self.status().get("realtime_how", "") if self._runtime is not None else ""
        if how.startswith("SCHED_FIFO"):
            return "real-time (RealtimeKit)" if how.endswith("RealtimeKit") else f"real-time {how.split(' ', 2)[2]}"
        return "no real-time priority" if how.startswith("none") else how

    @property
    def rate_and_priority(self) -> str:
        """The status line's words for the haptic loop: "4 kHz, real-time (root)"; "" until known."""
        priority = self.priority
        return f"{self.haptic_rate / 1000:g} kHz, {priority}" if priority else ""

    def _say_priority(self, runtime: Any) -> None:
        """Once a session with a device that renders or reads at 1 kHz (not the mouse) knows its
        priority, says it in the report view; without one, why, and what grants it."""
        how = runtime.status().get("realtime_how", "")
        if self._priority_said or not how or self._device is None or self._device.name == "mouse":
            return
        self._priority_said = True
        import FreeCAD
        if how.startswith("none"):
            FreeCAD.Console.PrintWarning(f"HapticSculpt: the haptic loop has no real-time priority ({how[6:]}); "
                                         "install rtkit (Debian: rtkit) or run sudo make install-realtime\n")
        else:
            FreeCAD.Console.PrintMessage(f"HapticSculpt: haptic loop at {how}\n")

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
        if obj is not None and _alive(obj):
            obj.Proxy.live.detach(runtime.surface)
            if commit:
                self._commit_strokes(runtime, obj, final=sculpt_state.capture(obj.Proxy.live.surface))
                if self._drop is not None or self._dropped_in_stop:
                    obj.Proxy.live.document_changed()  # (a dropped stroke's motion is no change)
                else:
                    self._commit_final(obj)
            obj.Proxy.live.reset_shape()
        self._last_runtime = runtime  # logs stay readable (recording, force errors)
        return status

    def drop_stroke(self) -> None:
        """The stroke held now is dropped: call it before the device releases its grab. Its end is
        not committed, no line is echoed for it, and the surface goes back to the document's state
        (Esc, or Undo, during a drag: nothing of the stroke in hand is kept)."""
        if self._runtime is None:
            raise RuntimeError("session: not running")
        self._drop = int(self._runtime.status()["strokes"])

    # --- the live surface's link (see live_surface.SessionLink) -------------------------------------
    def post_edit(self, prepared: Any, state: sculpt_state.SculptState | None, title: str, restore: bool,
                  keep_maps: bool, keep_shape: bool, replay: Callable[[Any], None] | None = None) -> None:
        """Queues an edit for the simulation thread (called by ``obj.Proxy.live``); when it has
        applied, :meth:`poll` commits ``state`` as ``title`` with the motion it took over (not for
        None: an Undo or Redo restoring the document's own state). ``replay`` does to a surface what
        the edit's scripting call does without a session: the session follows the state a macro
        replayed in console mode holds (see the module docstring)."""
        if self._runtime is None:
            raise RuntimeError("session: not running")
        self._follow_console(title, state, replay)
        edit_id = self._next_edit
        self._next_edit += 1
        self._edits[edit_id] = (title, state, 0)
        try:
            posted = self._runtime.post_edit(edit_id, prepared, restore=restore, keep_maps=keep_maps,
                                             keep_shape=keep_shape)
        except BaseException:
            del self._edits[edit_id]
            raise
        self._edits[edit_id] = (title, state, int(posted))
        if restore:
            self._restores.add(edit_id)

    def latest_poles(self) -> np.ndarray | None:
        """The newest pole snapshot ((nu*nv, 3)) the GUI received, None before the first."""
        return self._latest_poles

    def newest_poles(self) -> np.ndarray | None:
        """The newest pole snapshot the simulation published (at most 1/60 s old), taken now as
        the GUI's frame takes it, else the newest the GUI received; None before the first. An edit
        configures its copy with it, so what the edit reads off the shape (a new constraint's
        target) is the shape now: in console mode no GUI takes snapshots, and the copy had the
        document's shape from before the stroke (a point constraint added mid-stroke on a lifted
        sheet pulled its corner back down to where it was)."""
        runtime = self._runtime
        if runtime is not None:
            poles = runtime.take_poles()
            if poles is not None:
                self._latest_poles = poles
        return self._latest_poles

    def latest_map(self, name: str) -> np.ndarray | None:
        """The newest snapshot of map ``name`` the airbrush sprayed this run, None if none."""
        return self._latest_maps.get(name)

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
    def obj(self) -> Any:
        """The Sculpt object being sculpted, None once stopped."""
        return self._obj

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

    @property
    def simulated_seconds(self) -> float:
        """The material's time simulated so far (s): behind the clock where the simulation could
        not keep pace (a loaded machine drops what it cannot catch up)."""
        s = self.status()
        return (s.get("sim_steps", 0) + s.get("doubled_steps", 0)) * self.sim_dt

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
        if _gui_up():
            self._say_priority(runtime)
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

    def rendered_forces(self, before_safety: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Each logged haptic tick's time (s since the start) and the force sent to the device
        ((n, 3)); needs ``record_seconds``. With ``before_safety``, the estimate's force before the
        safety layer, which fades the force while the simulation has fallen behind (a loaded
        machine) and clamps it to the device's limits."""
        runtime = self._runtime or getattr(self, "_last_runtime", None)
        if runtime is None or runtime.running:
            raise RuntimeError("session: stop it before analysing it")
        ticks = runtime.ticks()
        return np.asarray(ticks["t"]), np.asarray(ticks["estimated_force" if before_safety else "rendered_force"])

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
    def _follow_console(self, title: str, state: sculpt_state.SculptState | None,
                        replay: Callable[[Any], None] | None) -> None:
        """An edit's call was just echoed (it runs before its commit, in the macro too): the state a
        console replaying the macro holds after it. A restore (Undo, Redo, a replayed record: state
        None) leaves the console with what the document holds now."""
        obj = self._obj
        if state is None or replay is None:
            self._console = obj.Proxy.live.stored()
            return
        if self._console is None:
            return
        try:
            surface = sculpt_state.restore(self._console)
            replay(surface)
            self._console = sculpt_state.capture(surface)
        except Exception as exc:  # noqa: BLE001 - the call itself would fail there: said, not raised
            import FreeCAD
            FreeCAD.Console.PrintWarning(f"HapticSculpt: {title} does not replay on the macro's state "
                                         f"({exc}); a macro recorded now may not replay\n")
            self._console = None

    def _commit_strokes(self, runtime: Any, obj: Any, final: sculpt_state.SculptState | None = None) -> int:
        """Commits the runtime's events in order: strokes, sprays and applied edits, one undo
        transaction each. At the stop, ``final`` is the state the surface ended in: the last of
        them commits that (what moved after it is part of it). Returns the number of strokes and sprays."""
        n = 0
        live = obj.Proxy.live
        events = []
        while (event := runtime.take_stroke()) is not None:
            if event["edit"] is None:
                self._strokes_taken += 1
                if self._strokes_taken - 1 == self._drop:
                    self._drop = None
                    if final is not None:  # (stopping: the stop puts the document's state back)
                        self._dropped_in_stop = True
                    else:
                        live.restore_into_session()
                    continue
            events.append(event)
        if self._dropped_in_stop:
            final = None  # (the surface at the stop holds the dropped stroke)
        last = max((k for k, e in enumerate(events) if e["edit"] is None or self._edits.get(e["edit"], ("", None))[1]
                    is not None), default=-1)
        for k, event in enumerate(events):
            if event["edit"] is not None:
                title, state, posted = self._edits.pop(event["edit"], ("", None, 0))
                self.applied_edits.append({"title": title or "restore", "posted_step": posted,
                                           "applied_step": int(event["step"]), "time": float(event["time"])})
                if event["edit"] in self._restores:
                    self._restores.discard(event["edit"])
                    self._latest_maps.clear()  # (a spray shown before it is gone: the maps are the document's)
                    self.last_stroke = None  # (an Undo or Redo: the HUD spoke of a stroke no longer in hand)
                if state is None:
                    continue  # an Undo or Redo the session took up: the document holds that state already
                strokes = 0
            else:
                title = f"Paint {event['painted']}" if event["painted"] else "Sculpt stroke"
                state, strokes = obj.Proxy.live.stored(), 1
            before = self._console if self._console is not None else obj.Proxy.live.stored()
            if strokes and not event["painted"] and not (final is not None and k == last):
                moved = _largest_move(before, _with_event(state, event))
                if moved is not None and moved <= UNMOVED_MM:
                    # (a grab that moved nothing: no undo step, the document not marked modified)
                    self.last_stroke = self._stroke_facts(obj, obj.Proxy.live.stored(), moved)
                    continue
            live.reset_shape()  # (so the transaction records the stored face as what Undo goes back to)
            doc = obj.Document
            with transaction(doc, title):
                live.write(final if final is not None and k == last else _with_event(state, event))
                if strokes:
                    obj.Strokes = obj.Strokes + strokes
                    now = obj.Proxy.live.stored()
                    after, was = now.arrays["Poles"], before.arrays["Poles"]
                    if not event["painted"] and after.shape == was.shape:
                        moved = np.linalg.norm((after - was).reshape(-1, 3), axis=1)
                        self.last_stroke = self._stroke_facts(obj, now, float(moved.max(initial=0.0)))
                told = bool(strokes) or _differs(before, obj.Proxy.live.stored())  # (else the edit's own call gives it)
                if told:
                    _tell_commit(obj, before, title, strokes)
                obj.purgeTouched()
            self._console = obj.Proxy.live.stored()  # (the replay_stroke line just echoed gives it)
            self._last_commit = (len(doc.UndoNames), title, strokes, before, told, final is not None)
            self._committed = True
            n += strokes
        return n

    def _stroke_facts(self, obj: Any, now: sculpt_state.SculptState, moved: float) -> dict[str, float]:
        """Session.last_stroke: how far the stroke moved the surface (mm), how far it pulled, and
        what stood against it (the HUD's stroke line)."""
        return {"moved_mm": moved, "pulled_mm": self._pulled, "stiffness": float(np.mean(now.arrays["StiffnessMap"])),
                "held": float(len(now.settings.get("held_poles", []))),
                "curves": float(len(curve_constraint.records_of(obj))),
                "tool": obj.Proxy.live.snapshot().tool.name}

    def _commit_final(self, obj: Any) -> None:
        """What moved after the last commit (an elastic patch springing back, a swing settling)
        joins that commit's undo step: Stop is no user action of its own and adds no step. A
        session without a stroke, spray or edit changed nothing (whatever its constraints made the
        surface do meanwhile), and round-off drift of a resting patch (below a nanometre), and a
        clay patch's rest lengths relaxed at the start, are no change: the document keeps its state
        and the surface is reloaded from it. So is the motion when the document changed after the
        last commit (a step of another object's on top): the face and the surface then show the
        last commit's state, which is what the document keeps."""
        live = obj.Proxy.live
        last = self._last_commit
        if not self._committed or last is None:
            self._commit_pull(obj)
            live.document_changed()
            return
        current = sculpt_state.capture(live.surface)
        stored = obj.Proxy.live.stored()
        drift = float(np.max(np.abs(current.arrays["Poles"] - stored.arrays["Poles"]), initial=0.0))
        same = current.settings_json() == obj.SculptSettings and all(
            np.array_equal(current.arrays[k], stored.arrays[k])
            for k in current.arrays if k not in ("Poles", "Velocities", "RestLengths"))
        if same and drift <= 1e-9:
            live.document_changed()  # the stored state stays the truth
            return
        steps, title, strokes, before, told, in_stop = last
        doc = obj.Document
        if in_stop or len(doc.UndoNames) != steps or doc.UndoNames[0] != title:
            live.document_changed()  # (committed with this stop: it holds the end state already)
            return
        doc.undo()  # (that step is taken back and made again with the motion after it)
        live.reset_shape()
        with transaction(doc, title):
            live.write(current)
            if strokes:
                obj.Strokes = obj.Strokes + strokes
            _tell_commit(obj, before, title, strokes, echo=not told)  # (told: its line names it already)
            obj.purgeTouched()
        live.document_changed()

    def _commit_pull(self, obj: Any) -> None:
        """A session with no stroke, spray or edit in which the scan's pull moved the surface: that
        motion is what the designer watched happen, so it is kept, as one undo step."""
        live = obj.Proxy.live
        surface = live.surface
        if not surface.pull["active"]:
            return
        current = sculpt_state.capture(surface)
        before = live.stored()
        if float(np.max(np.abs(current.arrays["Poles"] - before.arrays["Poles"]), initial=0.0)) <= 1e-9:
            return
        live.reset_shape()
        title = "Pulled toward target"
        with transaction(obj.Document, title):
            live.write(current)
            _tell_commit(obj, before, title, 0)
            obj.purgeTouched()

    # --- GUI: shape at graphics rate, strokes as they end ----------------------------------------
    def _start_timer(self) -> None:
        if _frame_clocks:
            self._timer = _frame_clocks[0](self._on_frame)

    def _stop_timer(self) -> None:
        if self._timer is not None:
            self._timer()
            self._timer = None

    def _on_frame(self) -> None:
        runtime, obj = self._runtime, self._obj
        if runtime is None or obj is None:
            return
        # Only a held stroke previews on the objects built from the sculpt (a SculptedSolid's
        # faces as a compound): once it is let go they show the committed state, a closed solid.
        # (A spray moves no pole: nothing to preview.)
        status = runtime.status()
        held = bool(status["grab"]) and not status["spraying"]
        if held and "cursor" in status:
            cursor = np.asarray(status["cursor"], dtype=float)
            if self._grab_from is None:
                self._grab_from, self._pulled = cursor, 0.0
            self._pulled = max(self._pulled, float(np.linalg.norm(cursor - self._grab_from)))
        elif not held:
            self._grab_from = None
        poles = runtime.take_poles()
        if poles is not None and _alive(obj):
            self._latest_poles = poles
            obj.Proxy.live.show_poles(poles, self._frame_base, preview=held)
            self._previewed = self._previewed or held
        painted = runtime.take_painted_map()
        if painted is not None:
            self._latest_maps[painted["map"]] = painted["values"]
        committed = self.poll()
        if self._previewed and not held and self._obj is not None:
            self._previewed = False
            if not committed:  # (a press that grabbed nothing: no commit rebuilds them)
                obj.Proxy.live.reset_shape()


def _differs(a: sculpt_state.SculptState, b: sculpt_state.SculptState) -> bool:
    """True unless the two states are equal, bit for bit."""
    return a.settings_json() != b.settings_json() or any(
        not np.array_equal(a.arrays[k], b.arrays[k]) for k in sculpt_state.ARRAY_NAMES)


def _tell_commit(obj: Any, before: sculpt_state.SculptState, title: str, strokes: int, echo: bool = True) -> None:
    """Tells the listeners, inside the commit's transaction; one that fails is reported and the
    stroke is committed all the same (an echo must not cost the stroke)."""
    for listener in _commit_listeners:
        try:
            listener(obj, before, title, strokes) if echo else listener(obj, before, title, strokes, echo=False)
        except Exception as exc:  # noqa: BLE001 - reported, not raised: see the docstring
            import FreeCAD
            FreeCAD.Console.PrintError(f"HapticSculpt: {title} committed, but not echoed: {exc}\n")


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

    def slotUndoDocument(self, doc: Any) -> None:
        self._restore(doc)

    def slotRedoDocument(self, doc: Any) -> None:
        self._restore(doc)

    @staticmethod
    def _restore(doc: Any) -> None:
        """Undo or Redo changed a sculpt that a session steps: the session takes the restored state."""
        for session in list(_ACTIVE):
            obj = session._obj
            if obj is not None and getattr(obj, "Document", None) is doc and session.running:
                obj.Proxy.live.restore_into_session()


#: mm: a stroke that moves no pole coordinate further than this moved nothing (a tenth of a micrometre, ten
#: times under Follow curve's default tolerance: a flatten stroke over a flat sheet moved 1e-5 mm).
UNMOVED_MM = 1e-4


def _largest_move(before: sculpt_state.SculptState, after: sculpt_state.SculptState) -> float | None:
    """The largest pole coordinate's change (mm) from ``before`` to ``after``; None where the nets differ."""
    was, now = before.arrays["Poles"], after.arrays["Poles"]
    return float(np.abs(now - was).max(initial=0.0)) if was.shape == now.shape else None


def _with_event(state: sculpt_state.SculptState, event: dict[str, Any]) -> sculpt_state.SculptState:
    """``state`` with the poles, velocities, rest lengths, bending reference and maps a runtime event carries."""
    arrays = dict(state.arrays)
    settings = dict(state.settings, maps=dict(state.settings.get("maps", {})))
    arrays["Poles"] = np.asarray(event["poles"], dtype=float).ravel()
    arrays["Velocities"] = np.asarray(event["velocities"], dtype=float).ravel()
    arrays["RestLengths"] = np.asarray(event["rest_lengths"], dtype=float).ravel()
    arrays["BendingReference"] = np.asarray(event["bending_reference"], dtype=float).ravel()
    for name, values in event["maps"].items():
        prop = sculpt_state.map_property(name)
        arrays[prop] = np.asarray(values, dtype=float).ravel()
        settings["maps"][prop] = [int(values.shape[0]), int(values.shape[1])]
    return sculpt_state.SculptState(arrays, settings)
