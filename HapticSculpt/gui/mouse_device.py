"""The mouse as a session's device: the 3D cursor follows the pointer in FreeCAD's 3D views."""
from __future__ import annotations

import math
from typing import Any, Callable, Sequence

from ..core import native as _core


#: A press grabs once the pointer has moved this many pixels with the button held: a click (to
#: give the view the keyboard, say) is no stroke.
GRAB_PIXELS = 4
#: A view looks onto the surface when its direction is within this many degrees of the surface's
#: normal at the grab: a drag in the plane facing the screen would then slide the grab along the
#: surface, unseen, so the drag lifts it toward the eye instead. (An isometric view of a flat patch
#: is 55 degrees off its normal: its drags stay in the plane facing the screen, which lifts there.)
FACING_DEGREES = 45.0


class MouseDevice:
    """The 3D cursor follows the mouse in a FreeCAD 3D view: onto the surface under the pointer, or
    onto the view's focal plane elsewhere; the left button, held and moved, grabs. Only usable
    with the GUI up. ``yields(view, pixel)``: True where a press belongs to something else (the
    slider panel): the device neither grabs nor takes that press, nor its release. ``normal_at(point)``:
    the sculpted surface's unit normal nearest ``point`` (None: unknown), which tells a view that
    looks onto the surface (see :meth:`press`). ``lost_release()``: called on a press that comes
    while a grab is still held, its release having gone elsewhere (a dialog opened by a key during
    the drag took it, and the grab went on with the hover): it drops the stroke (without it, the
    grab ends there as if released)."""

    def __init__(self, name: str = "mouse", yields: Callable[[Any, tuple[int, int]], bool] | None = None,
                 normal_at: Callable[[Sequence[float]], Sequence[float] | None] | None = None,
                 lost_release: Callable[[], None] | None = None) -> None:
        self.yields = yields
        self.normal_at = normal_at
        self.lost_release = lost_release
        self.native = _core.ExternalDevice(name)
        self._callbacks: list[Any] = []
        self._buttons = 0
        self._position = (0.0, 0.0, 0.0)
        self._grab_plane: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None
        self._lift: _Lift | None = None  # a grab in a view that looks onto the surface
        self._pressed: tuple[Any, int, int] | None = None  # view and pixel of a press not yet a grab
        self._pointer: tuple[Any, tuple[int, int]] | None = None  # view and pixel of the last move
        self._dropped = False  # a grab let go by cancel(): the button's release is still to come
        self._navigating: set[int] = set()  # the other buttons held (the navigation style's)

    def attach(self, view: Any) -> None:
        """Follows the mouse in ``view`` (a FreeCADGui 3D view) until :meth:`detach`."""
        self.attach_all([view])

    def attach_all(self, views: Sequence[Any]) -> None:
        """Follows the mouse in each of ``views``, wherever it is, until :meth:`detach`."""
        self.detach()
        self.attach_more(views)

    def attach_more(self, views: Sequence[Any]) -> None:
        """Follows the mouse in ``views`` too (views opened during a session)."""
        from pivy import coin

        from .coin_events import FrontCallbacks
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
        """Puts the cursor under ``pixel`` of ``view``: on the surface there if any, else on the
        focal plane; during a grab, on the plane through the grab point that faces the screen."""
        x, y = int(pixel[0]), int(pixel[1])
        if self._buttons and self._lift is not None:
            p = self._lift.at(view, x, y)
        elif self._buttons and self._grab_plane is not None:
            p = _on_plane(view, x, y, *self._grab_plane)
        else:
            p = _picked(view, x, y) or _vector(view.getPoint(x, y))
        self._position, self._pointer = p, (view, (x, y))
        self.native.push(list(p), buttons=self._buttons)
        return p

    def hover_again(self) -> None:
        """The surface changed under a pointer that did not move (Undo, Redo): the cursor goes onto
        it again, unless it grabs (it stayed where the surface was before)."""
        if self._pointer is None or self._buttons or self._pressed is not None:
            return
        try:
            self.move_to(*self._pointer)
        except Exception:  # noqa: BLE001 - its view was closed: the cursor stays
            self._pointer = None

    def lifted(self) -> float | None:
        """How far a grab in a view that looks onto the surface has taken the grab point toward
        the eye (mm), or None when no such grab is held (what the HUD says: from such a view the
        grab moves along the line of sight and the cursor ball seems to stay put)."""
        if not self._buttons or self._lift is None:
            return None
        return sum((p - g) * e for p, g, e in zip(self._position, self._lift.grab, self._lift.toward_eye))

    @property
    def grabbing(self) -> bool:
        """True while the left button holds a grab (a press not yet moved is no grab)."""
        return bool(self._buttons)

    def cancel(self) -> bool:
        """Lets go of the grab the button holds (Esc, Undo): the cursor hovers again and the rest of
        the drag, up to the release, is the pointer's alone. True if there was a grab."""
        grabbed = bool(self._buttons)
        if grabbed or self._pressed is not None:
            self._dropped = True
        self._pressed = None
        if grabbed:
            self.press(False)
        return grabbed

    def press(self, held: bool, view: Any = None, pixel: Sequence[int] | None = None) -> None:
        """Button 1 (grab) held or released at the current cursor. A grab in ``view`` then moves the
        cursor in the plane through the grab point that faces the screen: the pointer dragged up in
        a view from above and aside lifts the surface. (The surface under the pointer, as before
        the grab, is the surface being pulled: a cursor put on it slid along it, and a face of a
        solid, with the solid all around under the pointer, barely rose.) Where the view looks onto
        the sculpted surface at the grab (within FACING_DEGREES of its normal there, as from the
        top onto a flat patch, or onto a bump's side), that plane slides the grab along the surface,
        so the drag up from ``pixel`` lifts it straight toward the eye instead, as the designer
        looking down expects, and a drag sideways moves it sideways on the screen. (The sculpted
        surface's normal, not the one of the face under the pointer: a slab's side, seen from the
        front, faces the eye where the surface does not.)"""
        self._buttons = 1 if held else 0
        d = view.getViewDirection() if held and view is not None else None
        self._grab_plane = (self._position, (float(d.x), float(d.y), float(d.z))) if d is not None else None
        self._lift = None
        if d is not None and pixel is not None and self.normal_at is not None:
            n = self.normal_at(self._position)
            along = 0.0 if n is None else n[0] * d.x + n[1] * d.y + n[2] * d.z
            if abs(along) >= math.cos(math.radians(FACING_DEGREES)):
                self._lift = _Lift(view, int(pixel[0]), int(pixel[1]), self._position,
                                   (-float(d.x), -float(d.y), -float(d.z)))
        self.native.push(list(self._position), buttons=self._buttons)

    def _on_move(self, view: Any, cb: Any) -> None:
        pos = cb.getEvent().getPosition()
        if self._pressed is not None and self._pressed[0] is view and \
                max(abs(int(pos[0]) - self._pressed[1]), abs(int(pos[1]) - self._pressed[2])) >= GRAB_PIXELS:
            self.move_to(view, self._pressed[1:])
            self.press(True, view, self._pressed[1:])  # the grab starts where the button went down
            self._pressed = None
        self.move_to(view, (pos[0], pos[1]))
        event = cb.getEvent()
        if self._buttons or self._pressed is not None or self._dropped or not (
                self._navigating or event.wasShiftDown() or event.wasCtrlDown() or event.wasAltDown()):
            # A grab (or a cancelled one's drag): not a selection box or a rotation. A hover: no
            # preselection, whose highlight washed out the surface being sculpted under the pointer.
            # (A move with another button or a modifier held is the navigation style's: the
            # preselection it lit, a pan's, goes at the next hover.)
            cb.setHandled()
            _unlight()

    def _on_button(self, view: Any, cb: Any) -> None:
        from pivy import coin
        event = cb.getEvent()
        if event.getButton() != coin.SoMouseButtonEvent.BUTTON1:
            if event.getState() == coin.SoButtonEvent.DOWN:
                self._navigating.add(event.getButton())
            else:
                self._navigating.discard(event.getButton())
        if event.getButton() == coin.SoMouseButtonEvent.BUTTON1:
            pos = event.getPosition()
            down = event.getState() == coin.SoButtonEvent.DOWN
            if down and self._buttons:  # (its release went elsewhere)
                if self.lost_release is not None:
                    self.lost_release()
                if self._buttons:
                    self.press(False)
            if down and self.yields is not None and self.yields(view, (pos[0], pos[1])):
                return
            if not down and self._dropped and not self._buttons and self._pressed is None:
                self._dropped = False
                cb.setHandled()  # (the release of a cancelled grab: no click for the selection)
                return
            if not down and not self._buttons and self._pressed is None:
                return  # (the release of a press it did not take)
            self._dropped = False
            self.move_to(view, (pos[0], pos[1]))
            if event.getState() == coin.SoButtonEvent.DOWN:
                self._pressed = (view, int(pos[0]), int(pos[1]))  # a grab once it moves (GRAB_PIXELS)
            else:
                self._pressed = None
                self.press(False)
            cb.setHandled()


def _unlight() -> None:
    """Takes away FreeCAD's preselection highlight, if any."""
    import FreeCADGui as Gui
    if Gui.Selection.getPreselection().ObjectName:
        Gui.Selection.clearPreselection()


def _on_plane(view: Any, x: int, y: int, point: Sequence[float], normal: Sequence[float]) -> tuple[float, float, float]:
    """Where the ray under pixel (x, y) of ``view`` meets the plane through ``point`` with
    ``normal`` (the view direction at the grab): straight along the view direction for an
    orthographic camera, from the eye for a perspective one."""
    q = view.getPoint(x, y)  # (on the focal plane)
    q = (float(q.x), float(q.y), float(q.z))
    ray = tuple(normal)
    origin = q
    if "erspective" in str(view.getCameraType()):
        eye = view.getCameraNode().position.getValue()
        origin = (float(eye[0]), float(eye[1]), float(eye[2]))
        ray = tuple(qi - oi for qi, oi in zip(q, origin))
    along = sum(r * n for r, n in zip(ray, normal))
    if abs(along) < 1e-12:  # (a ray in the plane: none to meet)
        return q
    t = sum((p - o) * n for p, o, n in zip(point, origin, normal)) / along
    return tuple(o + t * r for o, r in zip(origin, ray))


def _picked(view: Any, x: int, y: int) -> tuple[float, float, float] | None:
    """The point of a shape under pixel (x, y) of ``view``, if any."""
    info = view.getObjectInfo((x, y))
    if info and all(k in info for k in ("x", "y", "z")):
        return float(info["x"]), float(info["y"]), float(info["z"])
    return None


class _Lift:
    """A grab in a view that looks onto the surface: the pointer's move from the press, measured on
    the view's focal plane, moves the grab point as far, its upward part ``toward_eye`` (against
    the view direction) and its sideways part sideways on the screen."""

    def __init__(self, view: Any, x: int, y: int, grab: Sequence[float], toward_eye: Sequence[float]) -> None:
        self.grab, self.toward_eye = tuple(grab), tuple(toward_eye)
        self.start = _vector(view.getPoint(x, y))
        self.right = _unit(_minus(_vector(view.getPoint(x + 1, y)), self.start))
        self.up = _unit(_minus(_vector(view.getPoint(x, y + 1)), self.start))

    def at(self, view: Any, x: int, y: int) -> tuple[float, float, float]:
        move = _minus(_vector(view.getPoint(x, y)), self.start)
        side = sum(a * b for a, b in zip(move, self.right))
        up = sum(a * b for a, b in zip(move, self.up))
        return tuple(g + side * r + up * e for g, r, e in zip(self.grab, self.right, self.toward_eye))


def _vector(v: Any) -> tuple[float, float, float]:
    return float(v.x), float(v.y), float(v.z)


def _minus(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float]:
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


def _unit(v: Sequence[float]) -> tuple[float, float, float]:
    length = math.sqrt(sum(c * c for c in v)) or 1.0
    return v[0] / length, v[1] / length, v[2] / length
