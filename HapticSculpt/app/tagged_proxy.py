"""A document object's proxy that keeps no state of its own: the file holds only its type tag,
everything else lives in the object's properties (FreeCAD's dumps/loads and Python's pickle
names both)."""
from __future__ import annotations

from typing import Any


class TaggedProxy:
    """Base of such proxies; a subclass sets ``TYPE``."""

    TYPE = ""

    def dumps(self) -> dict[str, Any]:
        """Proxy state for the file: only the type tag."""
        return {"Type": self.TYPE}

    def loads(self, state: Any) -> None:
        self.Type = self.TYPE

    def __getstate__(self) -> dict[str, Any]:
        return self.dumps()

    def __setstate__(self, state: Any) -> None:
        self.loads(state)
