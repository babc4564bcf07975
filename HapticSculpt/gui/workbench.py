"""What the workbench's commands, keys and mouse act on while it is active (GUI only).

Input in every order: while the workbench is active, every 3D view of every document gets the
workbench's event callbacks, whether it existed before the workbench was chosen or opens later
(a Coin timer looks for new views four times a second and forgets closed ones). Each event acts
on the view it happened in, on the sculpt under the mouse there (else the selected one, else the
document's only one).

The cursor: with a session running it is the device's; without one it follows the mouse over the
surface (or the view's focal plane off it), so constraints and paint dabs go to the mass point
nearest the mouse. Keys as in paper section 5: P, N, C toggle a point, normal or curvature
constraint at the nearest point; M switches between shading and the map display.

Events first: FreeCAD's navigation styles decide which events reach the scene graph, where the
workbench listens, and some (OpenInventor) pass none but selection gestures. So while the
workbench is active its views send events to the scene graph first (FreeCAD's redirect, as its
Esc toggle does), and what nobody there takes goes on to the navigation style: the wheel, the
middle and right buttons, and a left drag that starts off every object still navigate. While the
airbrush is on (without a session) or a mouse session runs, the left button belongs to the workbench
(a mouse session grabs once the held button moved a few pixels: the click that gives the view the
keyboard is no stroke; the session follows the pointer from view to view, its cursor and HUD too). Airbrush strokes lay dabs along the whole
mouse path, however fast it moves, and each stroke is one undo step. With a session the device's
button sprays instead (Session.set_airbrush).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .. import core
from .coin_events import FrontCallbacks
from .echo import ref, run_echoed
from .overlay import Overlay

MAP_CYCLE = ("mass", "damping", "stiffness", "bending", "pull")
CURVATURE_CYCLE = ("curvature", "mean", "gauss")
KEYS = {"p": "point", "n": "normal", "c": "curvature"}
AIRBRUSH_FACTOR = 3.0  # a stroke moves the map toward this times its mean when the stroke began
#: The pull's airbrush takes the pull away where it sprays (a region the scan should not shape:
#: the slider puts it back everywhere).
AIRBRUSH_FACTORS = {"pull": 1e-6}


def airbrush_factor(map: str) -> float:
    """What the airbrush on ``map`` moves it toward, as a factor of its mean when the stroke began."""
    return AIRBRUSH_FACTORS.get(map, AIRBRUSH_FACTOR)
AIRBRUSH_RADIUS = 0.08  # map coordinates (the unit square)
AIRBRUSH_STRENGTH = 0.25  # per dab, at its centre
ECHO_MAX = 200  # an echoed call longer than this goes into the StrokeLog (a person reads the console)
VIEW_SCAN_SECONDS = 0.25  # how often new and closed 3D views are looked for
#: Where the workbench's preferences live (Edit > Preferences > HapticSculpt: resources/preferences.ui).
PREFERENCES = "User parameter:BaseApp/Preferences/Mod/HapticSculpt"
#: Shown in the status bar when the workbench is chosen (the workbench selector keeps the keys).
HELLO = ("HapticSculpt: click in the 3D view, then P / N / C toggle point, normal, curvature constraints at the "
         "mouse, M shows the material map; Start/stop sculpting grabs with the left button\n")


#: The Python object of every 3D viewer the workbench reached (``view.getViewer()``), kept for the
#: session (one small object a view): FreeCAD 1.1 on Python 3.14 releases a viewer's Python object
#: in the viewer's destructor without holding the interpreter, and crashed there (SIGSEGV in
#: _Py_Dealloc) whenever that release was the last one, that is as soon as a view whose viewer had
#: been asked for from Python was closed (FreeCAD issue 27562, pull request 28920). Held here, the
#: release in the destructor is never the last.
_KEPT_VIEWERS: list[Any] = []


class ViewInput:
    """The workbench's event callbacks in one 3D view; each handler knows its view."""

    def __init__(self, ctl: "Controller", view: Any) -> None:
        from pivy import coin
        self.view = view
        _KEPT_VIEWERS.append(view.getViewer())  # (first: see _KEPT_VIEWERS)
        self._callbacks = FrontCallbacks(view, [(event, (lambda h: lambda cb: h(view, cb))(handler))
                                                for event, handler in ((coin.SoLocation2Event, ctl.on_move),
                                                                       (coin.SoKeyboardEvent, ctl.on_key),
                                                                       (coin.SoMouseButtonEvent, ctl.on_button))])

    def alive(self) -> bool:
        try:
            self.view.getSize()
            return True
        except Exception:  # noqa: BLE001 - a closed view raises on any access
            return False

    def events_first(self, take: bool) -> None:
        """Events to the scene graph before the navigation style (see the module docstring), or back."""
        try:
            viewer = self.view.getViewer()
            if bool(viewer.isRedirectedToSceneGraph()) != take:
                viewer.setRedirectToSceneGraph(take)
        except Exception:  # noqa: BLE001 - a closed view
            pass

    def remove(self) -> None:
        self.events_first(False)
        self._callbacks.remove()


def all_3d_views() -> list[tuple[Any, Any]]:
    """Every open 3D view of every document, with its document."""
    import FreeCAD
    import FreeCADGui as Gui
    views = []
    for name, doc in FreeCAD.listDocuments().items():
        gdoc = Gui.getDocument(name)
        if gdoc is None:
            continue
        for view in gdoc.mdiViewsOfType("Gui::View3DInventor"):
            if hasattr(view, "addEventCallbackPivy"):
                views.append((doc, view))
    return views


def views_of(doc_name: str) -> list[Any]:
    """The open 3D views of the document named ``doc_name``."""
    return [view for doc, view in all_3d_views() if doc.Name == doc_name]


class Controller:
    """One per GUI session of the workbench (see :func:`controller`)."""

    def __init__(self) -> None:
        self.overlays: dict[tuple[int, str], Overlay] = {}
        self.inputs: list[ViewInput] = []
        self.mouse_point: np.ndarray | None = None
        self._mouse_pixel: tuple[int, int] | None = None  # where mouse_point was taken, in mouse_view
        self.mouse_view: Any = None  # the view the mouse was last seen in
        self.mouse_object: Any = None  # the sculpt under the mouse there, if any
        self.session: Any = None
        self._yielded_to: str | None = None  # the other sculpt a session's press last yielded to (said once)
        self._set_aside: list[tuple[Any, list[str]]] = []  # the selection a session cleared: (object, subelements)
        self._greeted = False  # the report view's first line said (once a run)
        self.mouse: Any = None
        self._scan: Any = None
        self._observer: Any = None
        self.last_map = "mass"
        self.painting: str | None = None  # the map the airbrush paints, None when off
        self._painting_sculpt: Any = None  # the sculpt it was turned on for (it paints no other)
        self._paint_stroke: Any = None  # the sculpt being painted while the button is held
        self._paint_target = 0.0
        self._paint_path: list[tuple[float, float]] = []  # where the stroke's dabs went (map coordinates)
        self.tool = "rope"
        self.falloff = "spherical"
        #: each tool's settings as they were when another tool was chosen: choosing it again takes them
        self.tool_settings: dict[str, dict[str, float]] = {}
        self._populated: set[int] = set()  # views whose sculpts have their overlays (jacks) since they opened

    # --- views ------------------------------------------------------------------------------------
    def activate(self) -> None:
        """The workbench was chosen: attach to every 3D view now and to each one that opens later."""
        from pivy import coin
        self.sync_views()
        if self._scan is None:
            self._scan = coin.SoTimerSensor(lambda *_: self.sync_views(), None)
            self._scan.setInterval(coin.SbTime(VIEW_SCAN_SECONDS))
            self._scan.schedule()
        import FreeCAD
        if self._observer is None:
            self._observer = _UndoObserver(self)
            FreeCAD.addDocumentObserver(self._observer)
        if not self._greeted:  # (once a run: each return to the workbench repeated it)
            self._greeted = True
            FreeCAD.Console.PrintMessage(HELLO)

    def sync_views(self) -> None:
        """Attaches to views that opened and forgets closed ones; stops a session whose sculpt was
        deleted (or its creation undone)."""
        if self.session is not None and (self.session.obj is None or not _alive(self.session.obj)):
            import FreeCAD  # (the session stopped itself: the left button is the view's again)
            self.stop_session()
            FreeCAD.Console.PrintMessage("HapticSculpt: the sculpting session stopped: its sculpt was deleted or "
                                         "its document closed\n")
        for closed in [i for i in self.inputs if not i.alive()]:
            closed.remove()
            self.inputs.remove(closed)
            self._populated.discard(id(closed.view))
        for key in [k for k, ov in self.overlays.items() if not ov.alive()]:
            self.overlays.pop(key).remove()
        from ..app.sculpt_feature import is_sculpt
        for doc, view in all_3d_views():
            if not any(i.view is view for i in self.inputs):
                self.inputs.append(ViewInput(self, view))
                if self.mouse is not None and self.session is not None and doc.Name == self.session.obj.Document.Name:
                    self.mouse.attach_more([view])  # a mouse session follows the pointer into its document's new views
            if id(view) not in self._populated and not doc.Restoring:  # (a sculpt half read is no state)
                self._populated.add(id(view))
                for obj in [o for o in doc.Objects if is_sculpt(o)]:
                    self.overlay(obj, view).refresh()  # its jacks (if any) show in the new view at once
        for i in self.inputs:
            i.events_first(True)  # (each time: FreeCAD's Esc toggles it)

    @staticmethod
    def active_view() -> Any:
        import FreeCADGui as Gui
        doc = Gui.ActiveDocument
        view = getattr(doc, "ActiveView", None) if doc is not None else None
        return view if view is not None and hasattr(view, "getSceneGraph") else None

    def view(self) -> Any:
        """The view the mouse was last in (if still open), else the active 3D view."""
        if self.mouse_view is not None and any(i.view is self.mouse_view and i.alive() for i in self.inputs):
            return self.mouse_view
        return self.active_view()

    # --- what commands act on ---------------------------------------------------------------------
    def active_sculpt(self) -> Any:
        """The selected sculpt, else the session's (in the active document), else the one under the
        mouse, else the active document's only one."""
        import FreeCAD
        picked = _selected_sculpt()
        if picked is not None:
            return picked
        doc = FreeCAD.ActiveDocument
        running = self.session.obj if self.session is not None else None
        if running is not None and _alive(running) and running.Document == doc:
            return running  # (its selection was cleared at the start: the green tint hid the shading)
        if self.mouse_object is not None and _alive(self.mouse_object) and self.mouse_object.Document == doc:
            return self.mouse_object  # (another document's, last under the mouse: a session started there, unseen)
        return _only_sculpt(doc)

    def overlay(self, obj: Any | None = None, view: Any = None) -> Overlay | None:
        obj = obj or self.active_sculpt()
        if obj is None or not _alive(obj):
            return None
        view = view or self.view_of(obj)
        if view is None:
            return None
        key = (id(view), obj.Document.Name + "/" + obj.Name)
        if key in self.overlays and not (self.overlays[key].obj is obj and self.overlays[key].alive()):
            self.overlays.pop(key).remove()  # (a closed document's, opened again: the names are the same)
        if key not in self.overlays:
            self.overlays[key] = Overlay(view, obj)
            self.overlays[key].mode = f"airbrush: {self.painting}" if self.painting else ""
            self.overlays[key].speaks = self.speaks
            self.overlays[key].mouse = self.mouse_cursor
            self.overlays[key].lifting = self.mouse_lift
        return self.overlays[key]

    def speaks(self, overlay: Overlay) -> bool:
        """Whether ``overlay``'s HUD is the one its view shows: of the overlays drawing there, the
        session's, else the active sculpt's, else the first. (Each drew its status line and legend in
        the same place: a deviation display beside a session on a solid printed over each other.)"""
        drawing = [ov for (v, _), ov in self.overlays.items() if v == id(overlay.view) and ov.alive() and ov.needed]
        if len(drawing) < 2:
            return True
        for ov in drawing:
            if ov.obj.Proxy.live.session is not None and ov.live:
                return ov is overlay
        active = self.active_sculpt()
        for ov in drawing:
            if active is not None and ov.obj == active:
                return ov is overlay
        return drawing[0] is overlay

    def mouse_lift(self, overlay: Overlay) -> float | None:
        """How far the session's mouse grab lifted toward the eye (mm) in a view that looks onto
        the surface, on the session's sculpt's overlays; else None."""
        if self.mouse is None or self.session is None or overlay.obj is not self.session.obj:
            return None
        return self.mouse.lifted()

    def mouse_cursor(self, overlay: Overlay) -> tuple[np.ndarray, np.ndarray, bool] | None:
        """The mouse's cursor (position, orientation, grab) if ``overlay`` shows it: the airbrush's,
        on the active sculpt's overlay in the view the mouse is in, while no session runs (its
        device's cursor is the one). (Each overlay kept the last point it had: a view showed a
        cursor per sculpt; and one following the mouse with a display on looked like a session.)"""
        if self.mouse_point is None or self.painting is None or overlay.view is not self.mouse_view or (
                self.session is not None and self.session.running) or overlay.obj != self.active_sculpt():
            return None
        return self.mouse_point, np.array([1.0, 0, 0, 0]), self._paint_stroke is not None

    def view_of(self, obj: Any) -> Any:
        """A 3D view of ``obj``'s document: the one the mouse was last in, else the active one, else
        its first. (The mouse's alone drew a display set from the toolbar in the other document's
        view when the new document had not had the mouse yet.)"""
        import FreeCADGui as Gui
        mine = views_of(obj.Document.Name)
        if self.mouse_view is not None and any(v is self.mouse_view for v in mine):
            return self.mouse_view
        active = self.active_view()
        if active is not None and Gui.ActiveDocument is not None and Gui.ActiveDocument.Document == obj.Document:
            return active
        return mine[0] if mine else None

    def overlays_of(self, obj: Any) -> list[Overlay]:
        name = obj.Document.Name + "/" + obj.Name  # (and the object itself: a closed document's
        return [ov for (_, n), ov in self.overlays.items() if n == name and ov.obj is obj]  # opened again has its names)

    def cursor(self) -> np.ndarray | None:
        """Where the cursor is: the session's device while one runs, else the mouse."""
        if self.session is not None and self.session.running:
            return np.asarray(self.session.status()["cursor"], float)
        return self.mouse_point

    # --- mouse and keys ---------------------------------------------------------------------------
    def point_at(self, view: Any, x: int, y: int) -> np.ndarray:
        """The surface point under pixel (x, y), else the point on the view's focal plane; notes
        which sculpt is under the mouse."""
        at, self.mouse_object = _sculpt_at(view, x, y)
        if at is not None:
            return at
        p = view.getPoint(x, y)
        return np.array([p.x, p.y, p.z], float)

    def on_move(self, view: Any, cb: Any) -> None:
        from .view_focus import give_keyboard_to_view
        give_keyboard_to_view(view)  # (keys and ctrl+z reach it, whoever had them last)
        event = cb.getEvent()
        pos = event.getPosition()
        if any(ov.panel_drag(float(pos[0]), bool(event.wasShiftDown())) for ov in self.overlays.values()):
            cb.setHandled()  # a slider drag: neither a stroke nor a rotation
            return
        if view is not self.mouse_view:
            self._follow(view)
        self.mouse_view = view
        self._mouse_pixel = (int(pos[0]), int(pos[1]))
        self.mouse_point = self.point_at(view, *self._mouse_pixel)
        if self._paint_stroke is not None:
            self._dab_to(self._paint_stroke, self.mouse_point)
            cb.setHandled()
        self.overlay(view=view)  # (the active sculpt's, drawing the mouse's cursor: see mouse_cursor)

    def on_button(self, view: Any, cb: Any) -> None:
        from pivy import coin
        event = cb.getEvent()
        if event.getButton() != coin.SoMouseButtonEvent.BUTTON1:
            return
        if self._panel_button(view, event):
            cb.setHandled()
            return
        if self.mouse is not None:
            return  # the left button belongs to the session's mouse device (it follows every view)
        if self.painting is None:
            return
        pos = event.getPosition()
        self.mouse_view = view
        if event.getState() == coin.SoButtonEvent.DOWN:
            self.mouse_point = self.point_at(view, int(pos[0]), int(pos[1]))
            if self.begin_paint_stroke():
                cb.setHandled()
        elif self._paint_stroke is not None:
            self.end_paint_stroke()
            cb.setHandled()

    def panel_at(self, view: Any, pixel: tuple[int, int]) -> bool:
        """True if a panel shown in ``view`` is under ``pixel``, a slider or the backing between
        them (the mouse device leaves a press there to the panel: it is not a stroke; a press on
        the backing went through and sculpted the patch behind it)."""
        return any(ov.panel.track_at(pixel[0], pixel[1], ov.tracks()) is not None or ov.panel_covers(*pixel)
                   for (vid, _), ov in self.overlays.items() if vid == id(view))

    def _mouse_yields(self, view: Any, pixel: tuple[int, int]) -> bool:
        """A mouse session's press that is not a grab: one on a slider panel (:meth:`panel_at`), or
        on another sculpt than the session's, which FreeCAD then selects (the drag pulled the
        session's sculpt at its nearest edge, unseen where the designer looked)."""
        if self.panel_at(view, pixel):
            return True
        import FreeCAD
        session_obj = self.session.obj if self.session is not None else None
        _, other = _sculpt_at(view, int(pixel[0]), int(pixel[1]))
        if other is None or session_obj is None or other == session_obj:
            return False
        if self._yielded_to != other.Name:  # (once, not at every press on it)
            self._yielded_to = other.Name
            FreeCAD.Console.PrintMessage(f"HapticSculpt: the session sculpts {session_obj.Label}, not {other.Label}: "
                                         f"Start/stop sculpting, with {other.Label} selected, moves it there\n")
        return True

    def _panel_button(self, view: Any, event: Any) -> bool:
        """Button 1 on a slider panel: a press on a track takes it, one on the backing between the
        tracks does nothing (neither a dab nor FreeCAD's selection), the release commits the held one."""
        from pivy import coin
        x, y = (float(c) for c in event.getPosition())
        if event.getState() == coin.SoButtonEvent.DOWN:
            mine = [ov for (vid, _), ov in self.overlays.items() if vid == id(view)]
            return any(ov.panel_press(x, y) for ov in mine) or any(ov.panel_covers(x, y) for ov in mine)
        return any([ov.panel_release() for ov in self.overlays.values()])

    def on_key(self, view: Any, cb: Any) -> None:
        from pivy import coin
        event = cb.getEvent()
        if event.getState() != coin.SoButtonEvent.DOWN:
            return
        if (event.getKey() == coin.SoKeyboardEvent.ESCAPE or (event.getKey() == coin.SoKeyboardEvent.Z and
                                                             event.wasCtrlDown())) and self.drop_held():
            cb.setHandled()  # (ctrl+z reaches the view only while FreeCAD has nothing to undo: see _UndoObserver)
            return
        key = event.getPrintableCharacter().lower() if hasattr(event, "getPrintableCharacter") else ""
        if key not in KEYS and key != "m":
            return
        if event.wasCtrlDown() or event.wasAltDown():
            return  # ctrl+N and the like belong to FreeCAD
        from .view_focus import pointer_over
        if not pointer_over(view):
            return  # (the view kept the keyboard, the pointer went on to the tree: not the view's key)
        self.mouse_view = view
        try:
            if key in KEYS:
                self.toggle_constraint(KEYS[key])
            else:
                self.toggle_map()
        except (ValueError, TypeError, RuntimeError) as exc:  # (what the API refused, said plainly)
            refuse(f"key {key.upper()} ({KEYS.get(key, 'map')})", exc)
        cb.setHandled()

    def holds_stroke(self, doc: Any = None) -> bool:
        """True while the left button holds a stroke (of ``doc``'s sculpt, if given): a mouse
        session's grab, or an airbrush stroke without a session."""
        if self.mouse is not None and self.mouse.grabbing and self.session is not None and self.session.running:
            obj = self.session.obj
        elif self._paint_stroke is not None:
            obj = self._paint_stroke
        else:
            return False
        return doc is None or (_alive(obj) and obj.Document == doc)

    def drop_held(self, why: str = "") -> bool:
        """Drops the stroke the left button holds (Esc, or Undo, during a drag): a mouse session's
        grab lets go and the surface goes back to the document's state; an airbrush stroke's dabs
        are taken back. Nothing of it is committed or echoed, and the rest of the drag does nothing.
        (The drag went on from whatever Undo left, and its release committed it.) True if there was one."""
        if not self.holds_stroke():
            return False
        if self._paint_stroke is not None:
            obj, self._paint_stroke, self._paint_path = self._paint_stroke, None, []
            if _alive(obj):
                obj.Proxy.live.revert_map(self.painting)
                self.refresh(obj)
        else:
            self.session.drop_stroke()  # (before the grab lets go: its end is the one dropped)
            self.mouse.cancel()
        import FreeCAD
        FreeCAD.Console.PrintMessage(f"HapticSculpt: {why + ': ' if why else ''}the stroke in hand was dropped; the "
                                     "surface is as before it\n")
        return True

    def _follow(self, view: Any) -> None:
        """The pointer came into ``view``: a running session's sculpt is drawn each frame there, with
        its cursor and HUD, and no longer in the view it left (one view's frames, not every view's)."""
        obj = self.session.obj if self.session is not None else None
        if obj is None or not _alive(obj):
            return
        if view is not None and not any(v is view for v in views_of(obj.Document.Name)):
            return  # (another document's view: the session's cursor and HUD stay in its own)
        if view is None:
            self.refresh(obj)
            return
        self.overlay(obj, view)
        for ov in self.overlays_of(obj):
            ov.live = ov.view is view
            ov.refresh()

    # --- the airbrush ------------------------------------------------------------------------------
    def set_painting(self, which: str | None) -> str | None:
        """Switches the airbrush to map `which` (off if it was already on, or for None); shows the map."""
        if which is not None and which not in MAP_CYCLE:
            raise ValueError(f"which: one of {', '.join(MAP_CYCLE)}")
        self.painting = None if which is None or which == self.painting else which
        self._painting_sculpt = self.active_sculpt() if self.painting is not None else None
        if self.session is not None and self.session.running:
            self.session.set_airbrush(self.painting, factor=airbrush_factor(self.painting))
        for ov in self.overlays.values():
            ov.mode = f"airbrush: {self.painting}" if self.painting else ""
        if self.painting is not None:
            self.set_display(self.painting)
        return self.painting

    def airbrush_for(self, obj: Any) -> bool:
        """Whether the airbrush is on for ``obj``; turned off (said in the report view) if it was on
        for another sculpt: a stroke on a new patch, in another document, painted that map unseen
        where a designer meant to sculpt."""
        if self.painting is None:
            return False
        if obj is not None and obj == self._painting_sculpt:
            return True
        import FreeCAD
        was, which = self._painting_sculpt, self.painting
        was = was.Label if was is not None and _alive(was) else "another sculpt"
        self.set_painting(None)
        FreeCAD.Console.PrintMessage(f"HapticSculpt: the airbrush is off: it painted the {which} map of {was} (Paint "
                                     f"{which}, in the Material drop-down or the HapticSculpt menu, turns it on here)\n")
        return False

    def begin_paint_stroke(self) -> bool:
        """Button down with the airbrush on: the first dab at the cursor. False (no stroke) where the
        press is off the sculpt (a click on the background to take the keyboard painted its nearest
        edge) or the airbrush is another sculpt's (it goes off)."""
        if self._paint_stroke is not None:
            self.end_paint_stroke()  # a release that never reached the view still ends its stroke
        obj = self.active_sculpt()
        if obj is None or self.mouse_point is None or self.mouse_object != obj or not self.airbrush_for(obj):
            return False
        self._paint_stroke = obj
        surface = obj.Proxy.live.surface
        # One target for the whole stroke (as the session's airbrush), so dabs saturate at it.
        self._paint_target = airbrush_factor(self.painting) * float(np.mean(getattr(surface, self.painting + "_map").values))
        self._paint_path = []
        self._dab_to(obj, self.mouse_point)
        return True

    def end_paint_stroke(self) -> None:
        """Button up: the stroke becomes one undo step, as the scripting call that paints it (the
        dabs shown while dragging are dropped and laid again by that call, identically)."""
        obj, self._paint_stroke = self._paint_stroke, None
        if obj is not None and _alive(obj) and self._paint_path:
            obj.Proxy.live.revert_map(self.painting)  # (the call below lays the same dabs again)
            call = (f"HapticSculpt.paint({ref(obj)}, {self.painting!r}, {self._paint_path!r}, radius={AIRBRUSH_RADIUS!r}, "
                    f"factor={airbrush_factor(self.painting)!r}, strength={AIRBRUSH_STRENGTH!r})")
            if len(call) <= ECHO_MAX:
                run_echoed(call)
            else:  # a long path: kept in the sculpt's StrokeLog, echoed as one short line
                paint_long_stroke(obj, self.painting, self._paint_path)
            self.refresh(obj)

    def _dab_to(self, obj: Any, at: np.ndarray) -> None:
        """Dabs from the last dab to the mass point nearest `at`, shown at once (no session runs
        while the mouse paints)."""
        from ..app.api import paint_dabs
        end = self._map_uv(obj, at)
        if self._paint_path and end == self._paint_path[-1]:
            return
        material = getattr(obj.Proxy.live.surface, self.painting + "_map")
        paint_dabs(material, self._paint_path[-1] if self._paint_path else None, end, AIRBRUSH_RADIUS,
                   self._paint_target, AIRBRUSH_STRENGTH)
        self._paint_path.append(end)
        for ov in self.overlays_of(obj):
            ov.frame()

    # --- actions ----------------------------------------------------------------------------------
    def toggle_constraint(self, kind: str) -> str:
        """Adds a `kind` constraint at the mass point nearest the cursor, or removes the one there."""
        obj, at = self.active_sculpt(), self.cursor()
        if obj is None or at is None:
            raise RuntimeError("no sculpt or no cursor: move the mouse over a sculpt first")
        snapshot = obj.Proxy.live.snapshot()
        index = int(snapshot.nearest_mesh_index(list(at)))
        existing = [c for c in snapshot.constraints if c["kind"] == kind and c["index"] == index]
        if existing:
            run_echoed(f"HapticSculpt.remove_constraint({ref(obj)}, {existing[0]['id']})")
            result = "removed"
        else:
            point = tuple(float(x) for x in np.asarray(snapshot.mesh).reshape(-1, 3)[index])
            run_echoed(f"HapticSculpt.add_constraint({ref(obj)}, {kind!r}, near={point!r})")
            result = "added"
        self.refresh(obj)
        return result

    def _map_uv(self, obj: Any, at: np.ndarray) -> tuple[float, float]:
        """Map coordinates (0..1 over the parametric domain) of the mass point nearest `at`."""
        s = obj.Proxy.live.snapshot()
        u, v = s.mesh_parameters(int(s.nearest_mesh_index(list(at))))
        (u0, u1), (v0, v1) = s.surface.domain
        return float((u - u0) / (u1 - u0)), float((v - v0) / (v1 - v0))

    def set_display(self, display: str) -> None:
        ov = self.overlay()
        if ov is None:
            return
        if display != "shading" and not ov.visible():
            import FreeCAD  # (the scan stayed hidden, nothing drawn in its place, nothing said)
            FreeCAD.Console.PrintWarning(f"HapticSculpt: {ov.obj.Label} is hidden{hidden_by(ov.obj)}: its {display} "
                                         "display shows once it is shown (select it, Space)\n")
        elif display == "deviation" and ov.display != "deviation":
            ov.hide_scan()
        elif display != "deviation" and ov.display == "deviation":
            ov.show_scan()
        ov.display = display
        if display in MAP_CYCLE:
            self.last_map = display
        ov.refresh()

    def toggle_map(self) -> None:
        ov = self.overlay()
        if ov is None:
            raise RuntimeError("no sculpt here: move the mouse over a sculpt first")
        self.set_display("shading" if ov.display in MAP_CYCLE else self.last_map)

    def cycle(self, cycle: tuple[str, ...]) -> str:
        ov = self.overlay()
        if ov is None:
            return "shading"
        nxt = cycle[(cycle.index(ov.display) + 1) % len(cycle)] if ov.display in cycle else cycle[0]
        if ov.display == cycle[-1]:
            nxt = "shading"
        self.set_display(nxt)
        return nxt

    def set_tool(self, tool: str, falloff: str | None = None) -> None:
        if tool not in core.TOOLS:
            raise ValueError(f"tool: unknown tool {tool!r}")
        self.tool = tool
        if falloff is not None:
            self.falloff = falloff
        obj = self.active_sculpt()
        if obj is None:
            return
        current = obj.Proxy.live.snapshot().tool
        if current.name != tool:  # (remember the settings left behind; take back the chosen tool's)
            self.tool_settings[current.name] = {k: getattr(current, k) for k in core.TOOL_INFO[current.name]["parameters"]}
        info = core.TOOL_INFO[tool]
        kept = {k: v for k, v in self.tool_settings.get(tool, {}).items() if v != info["parameters"][k]["default"]}
        call = f"{tool!r}" + (f", falloff={self.falloff!r}" if info["falloff"] else "")
        call += "".join(f", {k}={v!r}" for k, v in kept.items()) if current.name != tool else ""
        run_echoed(f"HapticSculpt.set_tool({ref(obj)}, {call})")

    def start_session(self, device: Any = None, obj: Any = None) -> Any:
        """Starts sculpting `obj` (by default the active sculpt) with `device`, else the first attached
        force device, else a SpaceMouse, else the mouse (devices.pick). The selection is set aside until
        the stop: its highlight tinted the whole surface, and commands act on the session's sculpt."""
        import FreeCADGui as Gui

        from ..runtime import devices
        from ..runtime.session import Session
        from .mouse_device import MouseDevice
        obj = obj or self.active_sculpt()
        if obj is None:
            raise RuntimeError("select the sculpt to sculpt (or create a patch first)")
        rate = None  # (the core's default)
        if device is None:
            device, rate = self._attached_device(obj, devices)
        if device is None:
            device = MouseDevice(yields=self._mouse_yields, normal_at=lambda p: surface_normal(obj, p),
                                 lost_release=lambda: self.drop_held("the drag's release went elsewhere (a dialog?)"))
            # (its document's views only: a drag in another document's view sculpted this one, unseen)
            device.attach_all(views_of(obj.Document.Name))
            Gui.Selection.clearPreselection()  # (the device keeps hovers from the selection: none left lit)
        # (what was selected is set aside and given back at the stop: a sketch picked with the
        # sculpt for Follow curve is picked still when the designer comes back to make it G1)
        self._set_aside = [(o.Object, list(o.SubElementNames)) for o in Gui.Selection.getSelectionEx()]
        Gui.Selection.clearSelection()
        self._yielded_to = None
        self.mouse = device if isinstance(device, MouseDevice) else None
        self.airbrush_for(obj)
        session = Session()
        session.set_airbrush(self.painting, factor=airbrush_factor(self.painting))  # before the first tick can grab
        self.session = session.start(obj, device, tool=obj.Proxy.live.snapshot().tool.name, haptic_rate=rate)
        self._follow(self.view_of(obj))
        pull = obj.Proxy.live.snapshot().pull
        if pull["target"] and pull["enabled"]:
            import FreeCAD  # (it moves the surface from the first step, a stroke or none)
            FreeCAD.Console.PrintMessage(f"HapticSculpt: {obj.Label} is pulled toward its scan while the session "
                                         "runs (Pull toward scan, in the Displays drop-down or the HapticSculpt "
                                         "menu, switches it off)\n")
        return self.session

    @staticmethod
    def _attached_device(obj: Any, devices: Any) -> tuple[Any | None, float | None]:
        """A force device centred on the sculpt, its ~100 mm workspace scaled to the sculpt's size,
        at its fastest rate from the limits table (4 kHz for a Force Dimension device) or the
        preference's limit, else a SpaceMouse; None when there is neither, or the one there fails
        to open (said in the report view: the mouse takes over). With the session's haptic rate."""
        import FreeCAD
        box = obj.Shape.BoundBox
        centre = (box.Center.x, box.Center.y, box.Center.z)
        limit = FreeCAD.ParamGet(PREFERENCES).GetFloat("MaxHapticRate", 0.0)
        try:
            return devices.pick_with_rate(origin=centre, scale=max(1.0, box.DiagonalLength / 100.0), max_rate=limit)
        except (RuntimeError, ValueError) as e:
            FreeCAD.Console.PrintWarning(f"HapticSculpt: {e}; sculpting with the mouse\n")
            return None, None

    def _give_back_selection(self) -> None:
        """The selection set aside at the session's start, where nothing was selected since (what
        of it still exists)."""
        import FreeCADGui as Gui
        aside, self._set_aside = self._set_aside, []
        if Gui.Selection.getSelection():
            return
        for picked, subs in aside:
            if _alive(picked):
                for sub in subs or [""]:
                    Gui.Selection.addSelection(picked, sub)

    def session_switch_target(self) -> Any:
        """The sculpt Start/stop sculpting moves a running session to, None where it stops it: a
        selected sculpt that is not the session's, else, with the session in another document than
        the active one, the active document's only sculpt (the command's tooltip promises either)."""
        import FreeCAD
        running = self.session.obj if self.session is not None else None
        if running is None or not _alive(running):
            return None
        picked = _selected_sculpt()
        if picked is not None:
            return picked if picked != running else None
        doc = FreeCAD.ActiveDocument
        return None if doc is None or running.Document == doc else _only_sculpt(doc)

    def stop_session(self) -> None:
        if self.session is not None:
            obj = self.session.obj
            self.session.stop()
            self.session = None
            if obj is not None and _alive(obj):
                for ov in self.overlays_of(obj):
                    ov.drop_cursor()
                self.refresh(obj)
            self._give_back_selection()
        if self.mouse is not None:
            self.mouse.detach()
            self.mouse = None

    def refresh(self, obj: Any | None = None) -> None:
        """Redraws the sculpt's overlays (making the one in the current view if there is none yet)."""
        obj = obj or self.active_sculpt()
        if obj is None:
            return
        if not self.overlays_of(obj):
            self.overlay(obj)
        for ov in self.overlays_of(obj):
            ov.refresh()

    def refresh_all(self) -> None:
        """Redraws every overlay (after Undo or Redo), the cursor on the restored surface."""
        if self.mouse is not None:
            self.mouse.hover_again()
        elif self.mouse_view is not None and self._mouse_pixel is not None:
            try:
                self.mouse_point = self.point_at(self.mouse_view, *self._mouse_pixel)
            except Exception:  # noqa: BLE001 - its view was closed
                self._mouse_pixel = None
        for ov in list(self.overlays.values()):
            if _alive(ov.obj):
                ov.refresh()

    def shutdown(self) -> None:
        """Leaving the workbench: stop the session (said in the report view: the HUD and the cursor
        went with no word), remove every overlay, drop the callbacks."""
        if self.session is not None and self.session.obj is not None and _alive(self.session.obj):
            import FreeCAD
            FreeCAD.Console.PrintMessage(f"HapticSculpt: the sculpting session on {self.session.obj.Label} stopped: "
                                         "you left the workbench (its strokes are kept; Start/stop sculpting "
                                         "starts it again once you are back)\n")
        self.stop_session()
        self.painting = None
        if self._scan is not None:
            self._scan.unschedule()
            self._scan = None
        for ov in self.overlays.values():
            try:
                ov.remove()
            except Exception:  # noqa: BLE001 - a closed view
                pass
        self.overlays.clear()
        for i in self.inputs:
            i.remove()
        self.inputs = []
        self._populated.clear()
        if self._observer is not None:
            import FreeCAD
            FreeCAD.removeDocumentObserver(self._observer)
            self._observer = None


class _UndoObserver:
    """Undo and Redo show at once: the overlays redraw from the restored state (a running session
    takes it up through its own observer). Undo during a drag (ctrl+z with the button held) takes
    back the stroke in hand, and only that: FreeCAD's Undo has by then taken back the step before
    it, which is done again at once. (Undo took back the previous stroke and the drag carried on
    from there.)"""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self._redo: Any = None  # the one-shot sensor doing the step again, while it is pending

    def slotUndoDocument(self, doc: Any) -> None:
        if self.ctl.holds_stroke(doc) and self.ctl.drop_held():
            self._redo_soon(doc)
        self.ctl.refresh_all()

    def _redo_soon(self, doc: Any) -> None:
        """Redoes ``doc``'s undone step once FreeCAD's Undo has finished (not inside its signal)."""
        from pivy import coin

        def redo(*_: Any) -> None:
            import FreeCADGui as Gui
            self._redo = None
            if not _alive_document(doc) or doc.RedoCount == 0:
                return
            if Gui.ActiveDocument is not None and Gui.ActiveDocument.Document == doc:
                # (echoed as FreeCAD echoes the Undo: a macro plays both, or neither, as its Gui lines)
                Gui.doCommandGui("Gui.runCommand('Std_Redo',0)")
            else:
                doc.redo()
        self._redo = coin.SoOneShotSensor(redo, None)
        self._redo.schedule()

    def slotRedoDocument(self, doc: Any) -> None:
        self.ctl.refresh_all()


def hidden_by(sculpt: Any) -> str:
    """The text ' behind X' naming the shown objects made from ``sculpt`` (a Thickness hides it), or ''."""
    shown = [o.Label for o in sculpt.InList if getattr(getattr(o, "ViewObject", None), "Visibility", False)]
    return f" behind {', '.join(shown)}" if shown else ""


def surface_normal(sculpt: Any, point: Any) -> tuple[float, float, float] | None:
    """The unit normal of ``sculpt``'s live surface at its mesh point nearest ``point`` (central
    differences over its neighbours), or None where the mesh gives none there."""
    from ..app.analysis import vertex_normals
    s = sculpt.Proxy.live.snapshot()
    mesh = np.asarray(s.mesh, float)
    i, j = divmod(int(s.nearest_mesh_index([float(c) for c in point])), mesh.shape[1])
    around = mesh[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2]
    n = vertex_normals(around)[min(i, 1), min(j, 1)]
    return tuple(float(c) for c in n) if np.linalg.norm(n) > 0.5 else None


def _selected_sculpt() -> Any:
    """The first selected sculpt (a sculpted solid stands for its sculpt), or None."""
    import FreeCADGui as Gui

    from ..app.sculpted_solid import sculpt_for
    return next((sculpt_for(o) for o in Gui.Selection.getSelection() if sculpt_for(o) is not None), None)


def _only_sculpt(doc: Any) -> Any:
    """``doc``'s sculpt where it has exactly one, else None."""
    from ..app.sculpt_feature import is_sculpt
    sculpts = [o for o in doc.Objects if is_sculpt(o)] if doc is not None else []
    return sculpts[0] if len(sculpts) == 1 else None


def _alive(obj: Any) -> bool:
    try:
        return obj.Document is not None and obj.Document.getObject(obj.Name) is obj
    except Exception:  # noqa: BLE001 - a deleted object raises on any access
        return False


def _sculpt_at(view: Any, x: int, y: int) -> tuple[np.ndarray | None, Any]:
    """The shape point under pixel (x, y) of ``view`` (None: none) and the sculpt it belongs to
    (itself, or the sculpt an object built from it comes from; None: no sculpt's)."""
    import FreeCAD

    from ..app.sculpted_solid import sculpt_for
    info = view.getObjectInfo((x, y))
    if not info or not all(k in info for k in ("x", "y", "z")):
        return None, None
    doc = FreeCAD.getDocument(info["Document"]) if info.get("Document") else None
    obj = doc.getObject(info["Object"]) if doc is not None and info.get("Object") else None
    return np.array([info["x"], info["y"], info["z"]], float), sculpt_for(obj)


def _alive_document(doc: Any) -> bool:
    import FreeCAD
    try:
        return FreeCAD.listDocuments().get(doc.Name) == doc
    except Exception:  # noqa: BLE001 - a closed document raises on any access
        return False


_CONTROLLER: list[Controller] = []


def refuse(what: str, exc: BaseException) -> None:
    """A refusal as a designer reads it: one plain line in the report view, and in the HUD of a
    running session (never a traceback: the message says what to do)."""
    import FreeCAD
    text = f"{what}: {exc}"
    FreeCAD.Console.PrintWarning(f"HapticSculpt: {text}\n")
    ctl = controller()
    if ctl.session is not None:
        for overlay in ctl.overlays_of(ctl.session.obj):
            overlay.refusal(text)


def controller() -> Controller:
    """The workbench's controller (created on first use)."""
    if not _CONTROLLER:
        _CONTROLLER.append(Controller())
    return _CONTROLLER[0]


def paint_long_stroke(obj: Any, map: str, path: list[tuple[float, float]]) -> None:
    """An airbrush stroke whose ``paint`` call would be longer than a line: painted, kept in the
    sculpt's StrokeLog and echoed as ``HapticSculpt.replay_stroke``, in one undo step."""
    from ..app import api
    from ..app.sculpt_properties import read_state
    from .echo import echo_stroke
    title = f"Paint {map}"
    before = read_state(obj)
    change = api.paint_change(map, path, radius=AIRBRUSH_RADIUS, factor=airbrush_factor(map), strength=AIRBRUSH_STRENGTH)
    obj.Proxy.live.edit(change, title, inside=lambda: echo_stroke(obj, before, title, 0))
