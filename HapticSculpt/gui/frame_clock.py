"""The clock a running session uses to show its shape at graphics rate in FreeCAD's GUI."""
from __future__ import annotations

from typing import Callable

FRAME_SECONDS = 1.0 / 30.0


def coin_frame_clock(tick: Callable[[], None]) -> Callable[[], None]:
    """Calls ``tick`` every frame from FreeCAD's event loop (a Coin timer sensor, as the GUI
    processes them) until the returned function is called."""
    from pivy import coin
    timer = coin.SoTimerSensor(lambda *_: tick(), None)
    timer.setInterval(coin.SbTime(FRAME_SECONDS))
    timer.schedule()
    return timer.unschedule
