"""A session's held stroke shown on what is built from a sculpt (a SculptedSolid, a Thickness):
frames come 30 times a second, and a preview costs milliseconds, so one is skipped unless twice
the last one's cost has passed since it: previews take at most a third of the GUI's time."""
from __future__ import annotations

import time
from typing import Any, Callable


def show_frame(proxy: Any, obj: Any, build: Callable[[], Any]) -> None:
    """Sets ``obj.Shape`` to ``build()`` unless the last preview (kept on ``proxy``, not saved) was
    too recent; a frame that cannot be built leaves the last one (the commit says what is wrong)."""
    now = time.perf_counter()
    last, cost = getattr(proxy, "_preview", (-1.0, 0.0))
    if now - last < 2.0 * cost:
        return
    try:
        obj.Shape = build()
    except (RuntimeError, ValueError):
        pass
    proxy._preview = (now, time.perf_counter() - now)
