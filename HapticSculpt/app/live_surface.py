"""The one owner of a Sculpt object's core surface: ``obj.Proxy.live``.

Readers call :meth:`LiveSurface.snapshot`, writers :meth:`LiveSurface.edit`, whether or not a
sculpting session runs; nobody else touches the core surface or asks whether a session runs.

- Without a session the core surface is a cache of the document properties (rebuilt when they
  change under it: Undo, Redo, a file opened), an edit changes it and is committed as one undo
  transaction at once.
- While a session runs its simulation thread steps the surface, so an edit is applied to a private
  copy configured from the document and holding the newest shape, and handed to the session
  (:class:`SessionLink`), which swaps it in between two simulation steps without letting go of the
  device and commits it as one undo transaction when its event comes back. Reads come from a
  shadow copy holding the newest shape the session published.

No FreeCAD import here beyond what the document layer needs; nothing from the runtime or the GUI.
"""
from __future__ import annotations

from typing import Any, Callable, Protocol, TypeVar

import numpy as np

from .. import core
from . import scan_deviation, scan_target, sculpt_state
from .sculpt_properties import face_of, read_state, set_error, write_state
from .undo import transaction

T = TypeVar("T")

#: Settings whose change does not alter the Part face (no pole moves): the Shape is not rebuilt.
_SHAPE_ARRAYS = ("Poles", "KnotsU", "KnotsV", "Weights")


class SessionLink(Protocol):
    """What a running session offers the live surface (implemented by the runtime layer)."""

    @property
    def running(self) -> bool:
        """False once its loops ended (by stop() or by themselves)."""

    def stop(self, commit: bool = True) -> Any:
        """Ends the session and hands the surface back (see LiveSurface.detach)."""

    def post_edit(self, prepared: core.DynamicSurface, state: sculpt_state.SculptState | None, title: str,
                  restore: bool, keep_maps: bool, keep_shape: bool,
                  replay: Callable[[core.DynamicSurface], None] | None = None) -> None:
        """Queues an edit for the simulation thread; when it applied, commits ``state`` (the
        configuration it leaves) as ``title`` with the motion it took over (not if ``state`` is None:
        the document's own state restored). ``replay`` applies the edit to a surface as the same
        scripting call does without a session (in a macro replayed in console mode)."""

    def latest_poles(self) -> np.ndarray | None:
        """The newest pole snapshot ((nu*nv, 3)) the session published, None before the first."""

    def latest_map(self, name: str) -> np.ndarray | None:
        """The newest snapshot of a map the session's airbrush sprayed, None if it sprayed none."""


class LiveSurface:
    """See the module docstring. One per Sculpt object; nothing of it is saved."""

    def __init__(self, obj: Any) -> None:
        self._obj = obj
        self._surface: core.DynamicSurface | None = None
        self._stale = True
        self._session: SessionLink | None = None
        self._shadow: core.DynamicSurface | None = None  # reads while a session runs
        self._shadow_stale = True
        # What the document's state properties hold, as this object last wrote or read them (None:
        # unknown, read them): a commit compares with it instead of reading them all back.
        self._stored: sculpt_state.SculptState | None = None
        self._own_write = False
        # During a session: the configuration the last edit left, which the next one builds on (its
        # commit may not have reached the document yet); None: the document's.
        self._head: sculpt_state.SculptState | None = None
        #: True while this object writes the document properties (their change is no news then)
        self.writing = False
        #: What the last Fair changed (api.fair's report), for the GUI's report line
        self.last_fair: dict[str, float] | None = None
        #: The last fit's report (scan_api.fit_to_target), for the GUI's line and its remedy
        self.last_fit: dict[str, Any] | None = None
        #: The last curve followed (curve_follow.add_curve_constraint): its id, label, tolerance and
        #: the net before and after it was refined for it, for the GUI's line
        self.last_curve: dict[str, Any] | None = None

    # --- who owns the surface ---------------------------------------------------------------------
    @property
    def session(self) -> SessionLink | None:
        """The running session that steps the surface, else None."""
        return self._session

    def attach(self, session: SessionLink) -> core.DynamicSurface:
        """A session takes the surface over (its threads step it from now on); returns it, at rest
        (and a clay surface relaxed in the shape it has: a stored stroke may hold elastic strain
        below the yield, which would otherwise spring back with no input)."""
        if self._session is not None:
            raise RuntimeError(f"{self._obj.Label} is already being sculpted by another session")
        surface = self.surface
        surface.set_velocities(np.zeros_like(np.asarray(surface.velocities)))  # a session starts from rest
        if surface.plasticity[0]:
            surface.relax()  # clay: its rest shape is the shape it has, so it stays until touched
        self._session = session
        self._shadow_stale = True
        self._head = None
        return surface

    def detach(self, surface: core.DynamicSurface) -> None:
        """The session stopped: ``surface`` (the one its simulation stepped last) is the live one again."""
        self._session = None
        self._surface = surface
        self._stale = False
        self._head = None

    # --- reads ------------------------------------------------------------------------------------
    @property
    def surface(self) -> core.DynamicSurface:
        """The core surface itself, for stepping it synchronously (``api.run``). Raises
        ``RuntimeError`` while a session steps it and ``ValueError`` with the reason when the stored
        state is corrupt."""
        if self._session is not None:
            raise RuntimeError(f"{self._obj.Label}: a sculpting session is running on this surface; stop it first "
                               "(read it with obj.Proxy.live.snapshot(), change it with obj.Proxy.live.edit())")
        if self._surface is None or self._stale:
            self._surface = self._from_document()
            self._stale = False
        return self._surface

    def snapshot(self) -> core.DynamicSurface:
        """The newest state to read (shape, mesh, maps, constraints, tool): the surface itself
        without a session; during one a private copy holding the newest shape and sprayed maps the
        session published. Treat it as read-only: change the surface with :meth:`edit`."""
        if self._session is None:
            return self.surface
        if self._shadow is None or self._shadow_stale:
            self._shadow = self._configured()
            self._shadow_stale = False
        poles = self._session.latest_poles()
        if poles is not None:
            self._shadow.set_poles(np.asarray(poles, float).reshape(np.asarray(self._shadow.poles).shape))
        return self._shadow

    def map_values(self, name: str) -> np.ndarray:
        """Material map ``name`` ("mass", "damping", "stiffness", "bending") as a (rows, cols) array, newest first
        (a spray under way in a session included)."""
        if self._session is not None:
            sprayed = self._session.latest_map(name)
            if sprayed is not None:
                return np.asarray(sprayed)
        return np.array(getattr(self.snapshot(), name + "_map").values)

    # --- writes -----------------------------------------------------------------------------------
    def edit(self, change: Callable[[core.DynamicSurface], T], title: str, keep_shape: bool = False,
             new_shape: bool = False, inside: Callable[[], None] | None = None) -> T:
        """Applies ``change(surface)`` as one undo transaction named ``title`` and returns its result.

        Without a session it changes the surface and commits at once. During one ``change`` runs on
        a copy configured from the document with the newest shape, which the session swaps in
        between two steps without letting go of the device (the transaction follows when the
        simulation has applied it). ``keep_shape`` then makes the current shape the rest shape.
        ``new_shape``: ``change`` moves the poles (Fair), so the session takes the copy as it is, at
        rest, as it takes an Undo, instead of carrying its own shape over. ``inside`` (no session
        only) runs inside the transaction, after the state is written: the GUI keeps and echoes the
        change there, in the same undo step."""
        if self._session is not None and not self._session.running:
            self._session.stop()  # its loops ended by themselves: commit its strokes, take the surface back
        if self._session is None:
            surface = self.surface
            result = change(surface)
            if keep_shape:
                surface.relax()
            self.commit(title, inside=inside)
            return result
        prepared = self._configured()
        poles = self._session.newest_poles()
        if poles is not None:
            prepared.set_poles(np.asarray(poles, float).reshape(np.asarray(prepared.poles).shape))
        before = _maps(prepared)
        result = change(prepared)
        after = _maps(prepared)
        keep_maps = all(np.array_equal(before[k], after[k]) for k in before)
        head = sculpt_state.capture(prepared)  # (before the simulation thread owns it)

        def replay(surface: core.DynamicSurface) -> None:  # (what this call does without a session)
            change(surface)
            if keep_shape:
                surface.relax()
        self._session.post_edit(prepared, head, title, restore=new_shape, keep_maps=keep_maps, keep_shape=keep_shape,
                                replay=replay)
        self._head = head
        self._shadow_stale = True
        return result

    def commit(self, title: str, strokes: int = 0, inside: Callable[[], None] | None = None) -> None:
        """Writes the surface's state to the document as one undo transaction (no session);
        ``inside`` runs in it after the write."""
        obj = self._obj
        with transaction(obj.Document, title):
            self.write(sculpt_state.capture(self.surface))
            if strokes:
                obj.Strokes = obj.Strokes + strokes
            if inside is not None:
                inside()
            obj.purgeTouched()

    def write(self, state: sculpt_state.SculptState) -> None:
        """Stores ``state`` in the properties (those that changed) and rebuilds the Shape if its
        geometry changed; the caller holds the transaction."""
        obj = self._obj
        stored = self.stored()
        geometry = any(not np.array_equal(stored.arrays[k], state.arrays[k]) for k in _SHAPE_ARRAYS)
        self.writing = self._own_write = True
        try:
            write_state(obj, state, stored)
            self._stored = state
            if geometry or obj.Shape.isNull():
                obj.Shape = face_of(state)
            if geometry:
                scan_deviation.refresh_property(obj)  # (in the same undo step as the shape)
        finally:
            self.writing = self._own_write = False
        self._shadow_stale = True
        if geometry:
            notify_dependents(obj)
            recompute_dependents(obj)

    def show_poles(self, poles: np.ndarray, base: sculpt_state.SculptState, preview: bool = True) -> None:
        """Redraws the Shape from intermediate poles on the knots and weights of ``base`` (a GUI
        frame during a session; not stored, not an undo step); with ``preview`` (a stroke is held)
        the objects built from the sculpt show it too, else they keep the stored state's shape."""
        frame = sculpt_state.SculptState({**base.arrays, "Poles": np.asarray(poles, dtype=float).ravel()}, base.settings)
        self.writing = True
        try:
            with unsaved_shape(self._obj):
                self._obj.Shape = face_of(frame)
        finally:
            self.writing = False
        if preview:
            notify_dependents(self._obj, frame)

    def reset_shape(self) -> None:
        """Puts the Shape back to the stored state's face after a session's frames redrew it. Done
        outside any transaction, before the next one opens, so Undo never restores a frame."""
        self.writing = True
        try:
            with unsaved_shape(self._obj):
                self._obj.Shape = face_of(read_state(self._obj))
        finally:
            self.writing = False
        notify_dependents(self._obj)

    def revert_map(self, name: str) -> None:
        """Puts material map ``name`` back to its stored values, dropping a preview painted on the
        surface (the GUI's airbrush shows its dabs before the stroke is committed; no session)."""
        state = read_state(self._obj)
        prop = sculpt_state.map_property(name)
        rows, cols = state.settings["maps"][prop]
        getattr(self.surface, name + "_map").set_values(state.arrays[prop].reshape(int(rows), int(cols)))

    def stored(self) -> sculpt_state.SculptState:
        """What the document's state properties hold, as this object last wrote or read them (read
        once after anything else wrote them). Read-only: states are replaced, never changed."""
        if self._stored is None:
            self._stored = read_state(self._obj)
        return self._stored

    def property_written(self) -> None:
        """A state property was written: unless by :meth:`write`, what they hold is no longer known."""
        if not self._own_write:
            self._stored = None

    def document_changed(self) -> None:
        """The document properties changed from outside (Undo, Redo, a script): during a session the
        surface is restored to them, as it is and at rest, without stopping the session (not a new
        undo step); otherwise the cache is rebuilt on the next read."""
        self._stale = True
        self._shadow_stale = True
        self._head = None

    def target_changed(self) -> None:
        """The ``Target`` link changed: the surface pulls toward the new target (none) from now on;
        a running session takes it at once, carrying its motion on (no undo step of its own: the
        link's is the one)."""
        if self._session is None:
            if self._surface is not None and not self._stale:
                self._with_target(self._surface)
            return
        if not self._session.running:
            return
        prepared = self._configured()
        poles = self._session.newest_poles()
        if poles is not None:
            prepared.set_poles(np.asarray(poles, float).reshape(np.asarray(prepared.poles).shape))
        self._session.post_edit(prepared, None, "", restore=False, keep_maps=True, keep_shape=False)
        self._shadow_stale = True

    def restore_into_session(self) -> None:
        """Hands the document's state (after Undo or Redo) to the running session, at rest."""
        if self._session is None:
            return
        restored = self._from_document()
        restored.set_velocities(np.zeros_like(np.asarray(restored.velocities)))
        self._session.post_edit(restored, None, "", restore=True, keep_maps=False, keep_shape=False)

    # --- helpers ----------------------------------------------------------------------------------
    def _configured(self) -> core.DynamicSurface:
        """A new surface configured as the last edit left it (the document's, before any)."""
        if self._head is None:
            return self._from_document()
        return self._with_target(sculpt_state.restore(self._head))

    def _from_document(self) -> core.DynamicSurface:
        obj = self._obj
        try:
            surface = sculpt_state.restore(read_state(obj))
        except ValueError as exc:
            message = f"{obj.Label}: stored sculpt state is invalid: {exc}"
            set_error(obj, message, self)
            raise ValueError(message) from exc
        set_error(obj, "", self)
        return self._with_target(surface)

    def _with_target(self, surface: core.DynamicSurface) -> core.DynamicSurface:
        """``surface`` pulling toward the scan the ``Target`` link names (no target: no pull)."""
        try:
            target = scan_target.target_of(self._obj)
        except ValueError:
            target = None  # (a deleted or emptied target: the Deviation property and deviation_of say so)
        surface.set_pull_target(target.tree if target is not None else None, scan_target.PULL_REACH * surface.size)
        return surface


def _maps(surface: core.DynamicSurface) -> dict[str, np.ndarray]:
    return {name: np.array(getattr(surface, name + "_map").values) for name in core.MAPS}


class unsaved_shape:
    """Writes to ``obj.Shape`` inside are no change to save (a session's frames, the stored face put
    back): FreeCAD's GUI does not mark the document modified for a property with NoModify, so a
    session that commits nothing leaves it unmodified. The object is not left touched either."""

    def __init__(self, obj: Any) -> None:
        self.obj = obj

    def __enter__(self) -> None:
        self.touched = "Touched" in self.obj.State
        self.obj.setPropertyStatus("Shape", "NoModify")

    def __exit__(self, *exc: Any) -> None:
        self.obj.setPropertyStatus("Shape", "-NoModify")
        if not self.touched:
            self.obj.purgeTouched()


def notify_dependents(obj: Any, frame: sculpt_state.SculptState | None = None) -> None:
    """Objects built from this sculpt (a SculptedSolid: their proxy has ``sculpt_changed``) rebuild
    now, in the caller's transaction, so one undo step restores both; given a session's ``frame``
    (not stored), they show a preview of it instead."""
    for parent in obj.InList:
        proxy = getattr(parent, "Proxy", None)
        hook = getattr(proxy, "sculpt_changed" if frame is None else "sculpt_frame", None)
        if hook is not None:
            touched = "Touched" in parent.State
            hook(parent) if frame is None else hook(parent, frame)
            if not touched:  # (rebuilt, or showing a frame: nothing for a recompute to do; the tree
                parent.purgeTouched()  # showed a solid touched after every session)


def recompute_dependents(obj: Any) -> None:
    """The features built on this sculpt (a Thickness, a Part Cut or a PartDesign Body on its
    SculptedSolid) recompute now, in the caller's transaction, so they follow each stroke and one
    undo step restores them too. The sculpt and its SculptedSolids are up to date already (their
    shapes were just written): they are not recomputed again."""
    built = [p for p in obj.InList if hasattr(getattr(p, "Proxy", None), "sculpt_changed")]
    for o in built:  # (rebuilt just now: not "touched", in the tree, in the file, after reopening)
        o.purgeTouched()
    users = [u for o in [obj] + built for u in o.InList if u not in built]
    if not users:
        return
    obj.purgeTouched()
    for user in users:
        user.touch()
    obj.Document.recompute([o for o in obj.InListRecursive if o not in built])
