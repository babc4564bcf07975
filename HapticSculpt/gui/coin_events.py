"""Event callbacks at the front of a 3D view's scene graph (GUI only; pivy, no Qt).

FreeCAD's own event callback node (``addEventCallbackPivy``) sits behind the selection node, which
takes a click on a selected object before it gets there. A node of our own, inserted as the scene
graph's first child, sees every event that reaches the scene graph first; what it does not mark
handled goes on to selection and the navigation style."""
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
        view.getSceneGraph().insertChild(self.node, 0)

    def remove(self) -> None:
        try:
            graph = self.view.getSceneGraph()
        except Exception:  # noqa: BLE001 - a closed view: its scene went with it
            return
        if graph.findChild(self.node) >= 0:
            graph.removeChild(self.node)
