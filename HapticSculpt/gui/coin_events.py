"""Event callbacks at the front of a 3D view's scene graph (GUI only; pivy, no Qt).

FreeCAD's own event callback node (``addEventCallbackPivy``) sits inside the selection node
(SoFCUnifiedSelection, what ``view.getSceneGraph()`` returns), which handles a button release over
an object (it selects it) before its children see it: a drag that ends on the sculpt then loses
its release. A node of our own, inserted in the viewer's root just before the selection node (after
the lights and the camera), sees every event that reaches the scene graph first; what it does not
mark handled goes on to selection and the navigation style."""
from __future__ import annotations

from typing import Any, Callable


class FrontCallbacks:
    """``handlers``: (Coin event class, function(callback node)) pairs, attached to ``view``."""

    def __init__(self, view: Any, handlers: list[tuple[Any, Callable[[Any], None]]]) -> None:
        from pivy import coin
        self.view = view
        self.node = coin.SoEventCallback()
        self.node.setName("HapticSculptEvents")
        for event, handler in handlers:
            self.node.addEventCallback(event.getClassTypeId(), (lambda h: lambda _data, node: h(node))(handler))
        self.parent = view.getViewer().getSoRenderManager().getSceneGraph()
        at = self.parent.findChild(view.getSceneGraph())
        if at < 0:  # (a root laid out otherwise: first in the selection node, as FreeCAD's own)
            self.parent, at = view.getSceneGraph(), 0
        self.parent.insertChild(self.node, at)

    def remove(self) -> None:
        try:
            self.view.getSize()
        except Exception:  # noqa: BLE001 - a closed view: its scene went with it
            return
        if self.parent.findChild(self.node) >= 0:
            self.parent.removeChild(self.node)
