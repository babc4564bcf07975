"""The paper's control panel: sliders for mass, damping, stiffness, bending and the curvature targets,
then one per setting of the current tool (as the core declares them: core.TOOL_INFO), drawn
in the screen-space HUD (:mod:`hud`, top-left corner) and operated with the mouse in view pixels.

The HUD lays the tracks out (in a column, one under another, so they never overlap in any view) and
tells where they went; :class:`SliderPanel` reads the mouse against them: a press on a track takes
that slider (the value jumps to the press), a drag sets its value (shown at once), the release
commits it as one undo step through the scripting call. A slider drag never reaches the 3D cursor,
so it is never a stroke. With Shift held the knob moves a tenth as far as the mouse (a track spans
up to five decades: 60 pixels took stiffness from 100 to 2,190). Values are kept to two significant
figures (three with Shift) and shown in plain decimals. Nothing is retained but which slider is held.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import core
from ..app import sculpt_state

# name, label, low, high (log scale)
SLIDERS = (("mass", "mass", 1e-2, 1e2), ("damping", "damping", 1e-2, 1e3), ("stiffness", "stiffness", 1e0, 1e5),
           ("bending", "bending (plate/springs)", 1e-1, 1e3), ("pull", "pull toward the target", 1e-2, 1e2),
           ("curvature_u", "curvature u (1/mm)", 1e-4, 1e-1), ("curvature_v", "curvature v (1/mm)", 1e-4, 1e-1))
MAPS = ("mass", "damping", "stiffness", "bending", "pull")
#: Sliders whose left end is 0, not their low value: no plate at all is springs alone, no pull none.
ZERO_AT_LEFT = ("bending", "pull")

#: A tool setting's slider spans this factor either side of its declared default (log scale).
TOOL_RANGE = 10.0
#: With Shift held, the knob moves this many times less than the mouse.
FINE = 10.0


def rounded(value: float, figures: int) -> float:
    """``value`` to ``figures`` significant figures (a slider's value: 2200, not 2187.76)."""
    if value <= 0 or not math.isfinite(value):
        return value
    return round(value, figures - 1 - math.floor(math.log10(value)))


def tool_sliders(tool: str, scale: float = 1.0) -> list[tuple[str, str, float, float]]:
    """The sliders of ``tool``'s settings: "tool.<tool>.<setting>", its label, its range (about the
    default; a length's default times ``scale``, the sculpt's ``sculpt_state.tool_scale``)."""
    out = []
    for name, default in sculpt_state.tool_defaults(tool, scale).items():
        default = default if default > 0 else 1.0
        out.append((f"tool.{tool}.{name}", f"{tool} {core.TOOL_INFO[tool]['parameters'][name]['label']}",
                    default / TOOL_RANGE, default * TOOL_RANGE))
    return out


def _scale(obj: Any) -> float:
    return sculpt_state.tool_scale(obj.Proxy.live.snapshot())


def sliders(obj: Any) -> list[tuple[str, str, float, float]]:
    """The panel's sliders for ``obj``: the material's and curvature's, then its current tool's."""
    return [*SLIDERS, *tool_sliders(obj.Proxy.live.snapshot().tool.name, _scale(obj))]


def _spec(name: str, scale: float) -> tuple[str, str, float, float]:
    if name.startswith("tool."):
        tool = name.split(".")[1]
        return next(s for s in tool_sliders(tool, scale) if s[0] == name)
    return next(s for s in SLIDERS if s[0] == name)


def _zero_at_left(name: str) -> bool:
    if name.startswith("tool."):
        _, tool, setting = name.split(".")
        return bool(core.TOOL_INFO[tool]["parameters"][setting]["allow_zero"])
    return name in ZERO_AT_LEFT


Box = tuple[float, float, float, float]  # x0, y0, x1, y1 in view pixels, origin bottom-left
REACH = 8  # pixels beyond a track's ends that still take it (a knob at an end sticks out by half)


class SliderPanel:
    """Which slider the mouse holds, and the values to show."""

    def __init__(self) -> None:
        self.held: str | None = None
        self.pending: float | None = None  # the held slider's value while dragging
        self._track: Box | None = None  # the held slider's track
        self._scale = 1.0  # the held sculpt's tool scale
        self._knob = 0.0  # the held knob's position (0..1)
        self._fine_from: tuple[float, float] | None = None  # (mouse x, knob) where Shift went down
        self._last_x: float | None = None  # the mouse's last column seen in this drag

    # --- values -----------------------------------------------------------------------------------
    @staticmethod
    def value(obj: Any, name: str) -> float:
        live = obj.Proxy.live
        if name.startswith("tool."):
            tool = live.snapshot().tool
            _, owner, setting = name.split(".")
            return float(getattr(tool, setting)) if tool.name == owner else 0.0
        if name in MAPS:
            return float(np.mean(live.map_values(name)))
        s = live.snapshot()
        curv = [c for c in s.constraints if c["kind"] == "curvature"]
        if not curv:
            return 0.0
        return float(curv[-1]["curvature"][0 if name == "curvature_u" else 1])

    @staticmethod
    def apply(obj: Any, name: str, value: float) -> None:
        """Sets slider ``name`` to ``value`` as one undo step through the scripting call (echoed to
        the Python console and a recorded macro); a running session takes it at once. A material
        slider shows its map's mean: a painted map is scaled to the new mean, a uniform one set."""
        from .echo import ref, run_echoed
        if name.startswith("tool."):
            _, tool, setting = name.split(".")
            run_echoed(f"HapticSculpt.set_tool({ref(obj)}, {tool!r}, {setting}={float(value)!r})")
        elif name in MAPS:  # (a painted map is scaled to the new mean: its pattern kept)
            values = obj.Proxy.live.map_values(name)
            mean = float(np.mean(values))
            if value > 0 and mean > 0 and float(np.ptp(values)) > 0:
                run_echoed(f"HapticSculpt.scale_map({ref(obj)}, {name!r}, {float(value) / mean!r})")
            else:
                run_echoed(f"HapticSculpt.set_uniform({ref(obj)}, {name!r}, {float(value)!r})")
        elif [c for c in obj.Proxy.live.snapshot().constraints if c["kind"] == "curvature"]:
            run_echoed(f"HapticSculpt.set_curvature_target({ref(obj)}, {name[-1]}={float(value)!r})")
        else:  # (the targets belong to curvature constraints: nothing to set yet)
            import FreeCAD
            FreeCAD.Console.PrintWarning("HapticSculpt: the curvature sliders set the targets of curvature "
                                         "constraints, and this sculpt has none: press C over the surface to add one\n")

    @staticmethod
    def fraction(name: str, value: float, scale: float = 1.0) -> float:
        """Where ``value`` sits along slider ``name`` (0..1), its lengths' range times ``scale``."""
        _, _, low, high = _spec(name, scale)
        if value <= 0:
            return 0.0
        return float(np.clip((math.log10(value) - math.log10(low)) / (math.log10(high) - math.log10(low)), 0, 1))

    @staticmethod
    def from_fraction(name: str, f: float, scale: float = 1.0) -> float:
        """The value at ``f`` (0..1) along slider ``name``, its lengths' range times ``scale``."""
        _, _, low, high = _spec(name, scale)
        if f <= 0 and _zero_at_left(name):
            return 0.0
        return 10 ** (math.log10(low) + float(np.clip(f, 0, 1)) * (math.log10(high) - math.log10(low)))

    # --- the mouse, in view pixels ----------------------------------------------------------------
    @staticmethod
    def track_at(x: float, y: float, tracks: dict[str, Box]) -> str | None:
        """The slider whose track (``tracks``: name -> its box, from the HUD) is under pixel (x, y)."""
        return next((name for name, (x0, y0, x1, y1) in tracks.items()
                     if x0 - REACH <= x <= x1 + REACH and y0 <= y <= y1), None)

    def press(self, x: float, y: float, tracks: dict[str, Box], obj: Any) -> bool:
        """Button down at (x, y) over the sliders of ``obj``: takes the slider there, if any (True)."""
        name = self.track_at(x, y, tracks)
        if name is None:
            return False
        self.held, self._track, self._scale, self._fine_from = name, tracks[name], _scale(obj), None
        self._last_x = None
        self.drag(x)
        return True

    def drag(self, x: float, fine: bool = False) -> None:
        """The held slider follows the mouse along its track; ``fine`` (Shift held) a tenth as far,
        from where the knob was when Shift went down."""
        if self.held is None or self._track is None:
            return
        x0, _, x1, _ = self._track
        width = max(x1 - x0, 1.0)
        if fine:
            # (from the last column seen without Shift: the move that came with Shift may already
            # be 20 px on, Qt having merged the moves in between under load)
            if self._fine_from is None:
                self._fine_from = (x if self._last_x is None else self._last_x, self._knob)
            f = self._fine_from[1] + (x - self._fine_from[0]) / width / FINE
        else:
            self._fine_from, f = None, (x - x0) / width
        self._knob = float(np.clip(f, 0.0, 1.0))
        self._last_x = x
        self.pending = rounded(self.from_fraction(self.held, self._knob, self._scale), 3 if fine else 2)

    def release(self, obj: Any) -> bool:
        """Button up: the held slider's value becomes one undo step (True if one was held)."""
        if self.held is None:
            return False
        name, value = self.held, self.pending
        self.held, self.pending, self._track, self._fine_from = None, None, None, None
        if value is not None:
            self.apply(obj, name, value)
        return True

    def shown_value(self, obj: Any, name: str) -> float:
        """The value a slider shows: the one being dragged, else the sculpt's."""
        return self.pending if self.held == name and self.pending is not None else self.value(obj, name)

    def values(self, obj: Any) -> list[tuple[str, float, bool, float]]:
        """(label, shown value, held, knob position 0..1) of each slider in order, for the HUD."""
        out, scale = [], _scale(obj)
        for name, label, _, _ in sliders(obj):
            v = self.shown_value(obj, name)
            out.append((label, v, self.held == name, self.fraction(name, v, scale)))
        return out
