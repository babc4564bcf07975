"""The mouse as a session's device: the 3D cursor follows the pointer in FreeCAD's 3D views."""
from __future__ import annotations

from typing import Any, Callable, Sequence

from ..core import native as _core


class MouseDevice:
    """The 3D cursor follows the mouse in a FreeCAD 3D view: onto the surface under the pointer, or
    onto the view's focal plane elsewhere; the left button grabs. Only usable with the GUI up.
    ``yields(view, pixel)``: True where a press belongs to something else (the slider panel): the
    device neither grabs nor takes that press, nor its release."""

    def __init__(self, name: str = "mouse", yields: Callable[[Any, tuple[int, int]], bool] | None = None) -> None:
        self.yields = yields
        self.native = _core.ExternalDevice(name)
        self._callbacks: list[Any] = []
        self._buttons = 0
        self._position = (0.0, 0.0, 0.0)

    def attach(self, view: Any) -> None:
        """Follows the mouse in ``view`` (a FreeCADGui 3D view) until :meth:`detach`."""
        self.attach_all([view])

    def attach_all(self, views: Sequence[Any]) -> None:
        """Follows the mouse in each of ``views``, wherever it is, until :meth:`detach`."""
        from pivy import coin

        from .coin_events import FrontCallbacks
        self.detach()
        for view in views:
            self._callbacks.append(FrontCallbacks(view, [
                (coin.SoLocation2Event, (lambda v: lambda cb: self._on_move(v, cb))(view)),
                (coin.SoMouseButtonEvent, (lambda v: lambda cb: self._on_button(v, cb))(view))]))

    def detach(self) -> None:
        """Stops following the mouse (the device stays usable; its cursor stays where it was)."""
        for callbacks in self._callbacks:
            callbacks.remove()
        self._callbacks = []

    def move_to(self, view: Any, pixel: Sequence[int]) -> tuple[float, float, float]:
        """Puts the cursor under ``pixel`` of ``view`` (surface point if any, else the focal plane)."""
        x, y = int(pixel[0]), int(pixel[1])
        info = view.getObjectInfo((x, y))
        if info and all(k in info for k in ("x", "y", "z")):
            p = (float(info["x"]), float(info["y"]), float(info["z"]))
        else:
            v = view.getPoint(x, y)
            p = (float(v.x), float(v.y), float(v.z))
        self._position = p
        self.native.push(list(p), buttons=self._buttons)
        return p

    def press(self, held: bool) -> None:
        """Button 1 (grab) held or released at the current cursor."""
        self._buttons = 1 if held else 0
        self.native.push(list(self._position), buttons=self._buttons)

    def _on_move(self, view: Any, cb: Any) -> None:
        pos = cb.getEvent().getPosition()
        self.move_to(view, (pos[0], pos[1]))
        if self._buttons:
            cb.setHandled()  # a grab: not a selection box or a rotation

    def _on_button(self, view: Any, cb: Any) -> None:
        from pivy import coin
        event = cb.getEvent()
        if event.getButton() == coin.SoMouseButtonEvent.BUTTON1:
            pos = event.getPosition()
            down = event.getState() == coin.SoButtonEvent.DOWN
            if (down and self.yields is not None and self.yields(view, (pos[0], pos[1]))) or (not down and not self._buttons):
                return
            self.move_to(view, (pos[0], pos[1]))
            self.press(down)
            cb.setHandled()
