"""What the workbench's commands and keys act on while it is active (GUI only): the active sculpt,
its overlay in the active 3D view, the mouse cursor over the surface, and the session.

The cursor: with a session running it is the device's (the haptic loop's last sample); without one
it follows the mouse over the surface (or the view's focal plane off it), so constraints and paint
dabs go to the mass point nearest the mouse. Keys as in paper section 5: P, N, C toggle a point,
normal or curvature constraint at the nearest point; M switches between shading and the map display.

Airbrush: a paint command switches painting of that map on (again: off). Without a session, holding
the left button sprays dabs along the mouse path, shown live in the map display, and the release
makes the whole stroke one undo step. With a session, the device's button sprays instead of
grabbing: the simulation thread lays the dabs between its steps along the device's path, shown
live in the map display, and each spray is one undo step (Session.set_airbrush).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from . import core
from .overlay import Overlay, readable_surface

MAP_CYCLE = ("mass", "damping", "stiffness")
CURVATURE_CYCLE = ("curvature", "mean", "gauss")
KEYS = {"p": "point", "n": "normal", "c": "curvature"}
AIRBRUSH_FACTOR = 3.0  # a stroke moves the map toward this times its mean when the stroke began


class Controller:
    """One per GUI session of the workbench (see :func:`controller`)."""

    def __init__(self) -> None:
        self.overlays: dict[tuple[int, str], Overlay] = {}
        self.mouse_point: np.ndarray | None = None
        self.session: Any = None
        self.mouse: Any = None
        self._view: Any = None
        self._callbacks: list[tuple[Any, Any]] = []
        self.last_map = "mass"
        self.painting: str | None = None  # the map the airbrush paints, None when off
        self._paint_stroke: Any = None  # the sculpt being painted while the button is held
        self._paint_target = 0.0
        self.tool = "rope"
        self.falloff = "spherical"

    # --- what commands act on ---------------------------------------------------------------------
    @staticmethod
    def active_sculpt() -> Any:
        """The selected sculpt, else the active document's last sculpt, else None."""
        import FreeCAD
        import FreeCADGui as Gui

        from .sculpt_feature import is_sculpt
        sel = [o for o in Gui.Selection.getSelection() if is_sculpt(o)]
        if sel:
            return sel[0]
        doc = FreeCAD.ActiveDocument
        if doc is None:
            return None
        sculpts = [o for o in doc.Objects if is_sculpt(o)]
        return sculpts[-1] if sculpts else None

    @staticmethod
    def view() -> Any:
        import FreeCADGui as Gui
        doc = Gui.ActiveDocument
        view = getattr(doc, "ActiveView", None) if doc is not None else None
        return view if view is not None and hasattr(view, "getSceneGraph") else None

    def overlay(self, obj: Any | None = None) -> Overlay | None:
        obj = obj or self.active_sculpt()
        view = self.view()
        if obj is None or view is None:
            return None
        key = (id(view), obj.Document.Name + "/" + obj.Name)
        if key not in self.overlays:
            self.overlays[key] = Overlay(view, obj)
        return self.overlays[key]

    def cursor(self) -> np.ndarray | None:
        """Where the cursor is: the session's device while one runs, else the mouse."""
        if self.session is not None and self.session.running:
            return np.asarray(self.session.status()["cursor"], float)
        return self.mouse_point

    # --- mouse and keys ---------------------------------------------------------------------------
    def attach(self) -> None:
        """Follows the mouse and the keys in the active view (the workbench's Activated)."""
        from pivy import coin
        view = self.view()
        if view is None or view is self._view:
            return
        self.detach()
        self._view = view
        for event, handler in ((coin.SoLocation2Event, self._on_move), (coin.SoKeyboardEvent, self._on_key),
                               (coin.SoMouseButtonEvent, self._on_button)):
            self._callbacks.append((event, view.addEventCallbackPivy(event.getClassTypeId(), handler)))

    def detach(self) -> None:
        if self._view is not None:
            for event, handle in self._callbacks:
                try:
                    self._view.removeEventCallbackPivy(event.getClassTypeId(), handle)
                except Exception:  # noqa: BLE001 - the view may already be closed
                    pass
        self._callbacks, self._view = [], None

    def point_at(self, view: Any, x: int, y: int) -> np.ndarray:
        """The surface point under pixel (x, y), else the point on the view's focal plane."""
        info = view.getObjectInfo((x, y))
        if info and all(k in info for k in ("x", "y", "z")):
            return np.array([info["x"], info["y"], info["z"]], float)
        p = view.getPoint(x, y)
        return np.array([p.x, p.y, p.z], float)

    def _on_move(self, cb: Any) -> None:
        pos = cb.getEvent().getPosition()
        self.mouse_point = self.point_at(self._view, int(pos[0]), int(pos[1]))
        ov = self.overlay()
        if ov is not None and not (self.session is not None and self.session.running):
            ov.cursor = (self.mouse_point, np.array([1.0, 0, 0, 0]), self._paint_stroke is not None)
        if self._paint_stroke is not None:
            self._dab(self._paint_stroke, self.mouse_point)
            cb.setHandled()

    def _on_button(self, cb: Any) -> None:
        from pivy import coin
        event = cb.getEvent()
        if self.painting is None or event.getButton() != coin.SoMouseButtonEvent.BUTTON1:
            return
        if self.session is not None and self.session.running:
            return  # the left button belongs to the session's mouse device then
        if event.getState() == coin.SoButtonEvent.DOWN:
            pos = event.getPosition()
            self.mouse_point = self.point_at(self._view, int(pos[0]), int(pos[1]))
            self.begin_paint_stroke()
        else:
            self.end_paint_stroke()
        cb.setHandled()

    # --- the airbrush ------------------------------------------------------------------------------
    def set_painting(self, which: str | None) -> str | None:
        """Switches the airbrush to map `which` (off if it was already on, or for None); shows the map."""
        if which is not None and which not in MAP_CYCLE:
            raise ValueError(f"which: one of {', '.join(MAP_CYCLE)}")
        self.painting = None if which is None or which == self.painting else which
        if self.session is not None and self.session.running:
            self.session.set_airbrush(self.painting, factor=AIRBRUSH_FACTOR)
        if self.painting is not None:
            self.set_display(self.painting)
        return self.painting

    def begin_paint_stroke(self) -> None:
        """Button down with the airbrush on: the first dab at the cursor."""
        obj = self.active_sculpt()
        if obj is None or self.painting is None or self.mouse_point is None:
            return
        self._paint_stroke = obj
        # One target for the whole stroke (as the session's airbrush), so dabs saturate at it.
        self._paint_target = AIRBRUSH_FACTOR * float(np.mean(getattr(obj.Proxy.surface, self.painting + "_map").values))
        self._dab(obj, self.mouse_point)

    def end_paint_stroke(self) -> None:
        """Button up: the stroke's dabs become one undo step."""
        obj, self._paint_stroke = self._paint_stroke, None
        if obj is not None:
            from .api import _commit
            _commit(obj, f"Paint {self.painting}")
            self.refresh(obj)

    def _dab(self, obj: Any, at: np.ndarray, radius: float = 0.08, strength: float = 0.25) -> None:
        """One airbrush dab on the painted map around the mass point nearest `at` (no session runs)."""
        m = getattr(obj.Proxy.surface, self.painting + "_map")  # (a uniform map gets a paint resolution on its first dab)
        m.dab(self._map_uv(obj, at), radius, self._paint_target, "spherical", strength)
        ov = self.overlay(obj)
        if ov is not None:
            ov.frame()

    def _on_key(self, cb: Any) -> None:
        from pivy import coin
        event = cb.getEvent()
        if event.getState() != coin.SoButtonEvent.DOWN:
            return
        key = event.getPrintableCharacter().lower() if hasattr(event, "getPrintableCharacter") else ""
        if key in KEYS:
            self.toggle_constraint(KEYS[key])
            cb.setHandled()
        elif key == "m":
            self.toggle_map()
            cb.setHandled()

    # --- actions ----------------------------------------------------------------------------------
    def toggle_constraint(self, kind: str) -> str:
        """Adds a `kind` constraint at the mass point nearest the cursor, or removes the one there."""
        from .session import edit_surface
        obj, at = self.active_sculpt(), self.cursor()
        if obj is None or at is None:
            raise RuntimeError("no sculpt or no cursor: move the mouse over a sculpt first")
        index = int(self._nearest(obj, at))
        existing = [c for c in readable_surface(obj).constraints if c["kind"] == kind and c["index"] == index]
        if existing:
            edit_surface(obj, lambda s: s.remove_constraint(existing[0]["id"]), f"Remove {kind} constraint")
            result = "removed"
        else:
            edit_surface(obj, lambda s: s.add_constraint(kind, index=index), f"Add {kind} constraint")
            result = "added"
        self.refresh(obj)
        return result

    def _map_uv(self, obj: Any, at: np.ndarray) -> tuple[float, float]:
        """Map coordinates (0..1 over the parametric domain) of the mass point nearest `at`."""
        s = readable_surface(obj)
        u, v = s.mesh_parameters(self._nearest(obj, at))
        (u0, u1), (v0, v1) = s.surface.domain
        return (u - u0) / (u1 - u0), (v - v0) / (v1 - v0)

    def _nearest(self, obj: Any, at: np.ndarray) -> int:
        """Mass point nearest `at` on the newest shape (the overlay's copy: never the stepped surface)."""
        ov = self.overlay(obj)
        surface = ov.scratch() if ov is not None else readable_surface(obj)
        return int(surface.nearest_mesh_index(list(at)))

    def set_display(self, display: str) -> None:
        ov = self.overlay()
        if ov is None:
            return
        ov.display = display
        if display in MAP_CYCLE:
            self.last_map = display
        ov.refresh()

    def toggle_map(self) -> None:
        ov = self.overlay()
        if ov is not None:
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
        from .session import edit_surface
        if tool not in core.TOOLS:
            raise ValueError(f"tool: unknown tool {tool!r}")
        self.tool = tool
        if falloff is not None:
            self.falloff = falloff
        obj = self.active_sculpt()
        if obj is None:
            return

        def change(s: Any) -> None:
            s.set_tool(tool)
            if tool == "magnet":
                s.tool.falloff = self.falloff
        edit_surface(obj, change, f"Tool: {tool}")

    def start_session(self, device: Any = None) -> Any:
        """Starts sculpting the active sculpt with `device`, else the first attached device, else the mouse."""
        from .devices import MouseDevice, list_devices, spacemouse
        from .session import Session
        obj = self.active_sculpt()
        if obj is None:
            raise RuntimeError("no sculpt to sculpt: create a patch first")
        if device is None:
            found = [d for d in list_devices() if d.get("spacemouse")]
            if found:
                device = spacemouse(found[0]["path"])
            else:
                device = MouseDevice()
                view = self.view()
                if view is not None:
                    device.attach(view)
        self.mouse = device if isinstance(device, MouseDevice) else None
        self.session = Session().start(obj, device, tool=readable_surface(obj).tool.name)
        if self.painting is not None:
            self.session.set_airbrush(self.painting, factor=AIRBRUSH_FACTOR)
        self.refresh(obj)
        return self.session

    def stop_session(self) -> None:
        if self.session is not None:
            self.session.stop()
            self.session = None
        if self.mouse is not None:
            self.mouse.detach()
            self.mouse = None
        self.refresh()

    def refresh(self, obj: Any | None = None) -> None:
        ov = self.overlay(obj)
        if ov is not None:
            ov.refresh()

    def shutdown(self) -> None:
        """Leaving the workbench: stop the session, remove every overlay, drop the callbacks."""
        self.stop_session()
        for ov in self.overlays.values():
            try:
                ov.remove()
            except Exception:  # noqa: BLE001 - a closed view
                pass
        self.overlays.clear()
        self.detach()


_CONTROLLER: list[Controller] = []


def controller() -> Controller:
    """The workbench's controller (created on first use)."""
    if not _CONTROLLER:
        _CONTROLLER.append(Controller())
    return _CONTROLLER[0]
