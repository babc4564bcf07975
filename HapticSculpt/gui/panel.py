"""The paper's 3D control panel, immediate-mode: sliders for mass, damping, stiffness and the
curvature targets drawn in the scene beside the surface and operated with the cursor.

Every frame :meth:`SliderPanel.draw` builds the panel from the current values and
:meth:`SliderPanel.operate` reads the cursor: grabbing within reach of a slider's track takes that
slider, moving along the track sets its value (shown at once), releasing commits it as one undo
transaction. Nothing about the panel is retained but which slider is held.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from . import coin_shapes as shapes

# name, label, low, high (log scale)
SLIDERS = (("mass", "mass", 1e-2, 1e2), ("damping", "damping", 1e-2, 1e3), ("stiffness", "stiffness", 1e0, 1e5),
           ("curvature_u", "curvature u (1/mm)", 1e-4, 1e-1), ("curvature_v", "curvature v (1/mm)", 1e-4, 1e-1))


class SliderPanel:
    """Vertical sliders standing beside the patch on its -x side."""

    def __init__(self) -> None:
        self.held: str | None = None
        self.pending: float | None = None  # the held slider's value while dragging
        self._tracks: dict[str, tuple[np.ndarray, np.ndarray]] = {}

    # --- values -----------------------------------------------------------------------------------
    @staticmethod
    def value(obj: Any, name: str) -> float:
        live = obj.Proxy.live
        if name in ("mass", "damping", "stiffness"):
            return float(np.mean(live.map_values(name)))
        s = live.snapshot()
        curv = [c for c in s.constraints if c["kind"] == "curvature"]
        if not curv:
            return 0.0
        return float(curv[-1]["curvature"][0 if name == "curvature_u" else 1])

    @staticmethod
    def apply(obj: Any, name: str, value: float) -> None:
        """Sets slider ``name`` to ``value`` as one undo step through the scripting call (echoed to
        the Python console and a recorded macro); a running session takes it at once."""
        from .echo import ref, run_echoed
        if name in ("mass", "damping", "stiffness"):
            run_echoed(f"HapticSculpt.set_uniform({ref(obj)}, {name!r}, {float(value)!r})")
        elif [c for c in obj.Proxy.live.snapshot().constraints if c["kind"] == "curvature"]:
            run_echoed(f"HapticSculpt.set_curvature_target({ref(obj)}, {name[-1]}={float(value)!r})")

    # --- geometry ---------------------------------------------------------------------------------
    def layout(self, mesh: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Track end points of each slider: bottom and top, in a row on the patch's -x side."""
        flat = mesh.reshape(-1, 3)
        lo, hi = flat.min(0), flat.max(0)
        size = float(np.linalg.norm(hi - lo)) or 1.0
        x = lo[0] - 0.12 * size
        tracks = {}
        for k, (name, _, _, _) in enumerate(SLIDERS):
            y = lo[1] + (k + 0.5) * (hi[1] - lo[1]) / len(SLIDERS)
            tracks[name] = (np.array([x, y, lo[2]]), np.array([x, y, lo[2] + 0.4 * size]))
        self._tracks = tracks
        return tracks

    @staticmethod
    def fraction(name: str, value: float) -> float:
        _, _, low, high = next(s for s in SLIDERS if s[0] == name)
        if value <= 0:
            return 0.0
        return float(np.clip((math.log10(value) - math.log10(low)) / (math.log10(high) - math.log10(low)), 0, 1))

    @staticmethod
    def from_fraction(name: str, f: float) -> float:
        _, _, low, high = next(s for s in SLIDERS if s[0] == name)
        return 10 ** (math.log10(low) + float(np.clip(f, 0, 1)) * (math.log10(high) - math.log10(low)))

    # --- immediate mode ---------------------------------------------------------------------------
    def operate(self, cursor: np.ndarray, grab: bool, obj: Any) -> None:
        """Reads the cursor: takes, drags or releases a slider."""
        if not self._tracks:
            return
        if grab and self.held is None:
            reach = 0.06 * max(float(np.linalg.norm(b - a)) for a, b in self._tracks.values())
            best = min(self._tracks, key=lambda n: _distance_to_segment(cursor, *self._tracks[n]))
            if _distance_to_segment(cursor, *self._tracks[best]) <= reach:
                self.held = best
        if self.held is not None:
            a, b = self._tracks[self.held]
            f = float(np.dot(cursor - a, b - a) / max(np.dot(b - a, b - a), 1e-300))
            self.pending = self.from_fraction(self.held, f)
            if not grab:
                name, value = self.held, self.pending
                self.held, self.pending = None, None
                self.apply(obj, name, value)

    def shown_value(self, obj: Any, name: str) -> float:
        """The value a slider shows: the one being dragged, else the sculpt's."""
        return self.pending if self.held == name and self.pending is not None else self.value(obj, name)

    def values(self, obj: Any) -> list[tuple[str, float, bool]]:
        """(label, shown value, held) of each slider in track order, for the HUD."""
        return [(label, self.shown_value(obj, name), self.held == name) for name, label, _, _ in SLIDERS]

    def draw(self, obj: Any, mesh: np.ndarray) -> Any:
        """The tracks and knobs in the scene, each numbered at its foot (its label and value are in
        the HUD under the same number, where they never leave the view)."""
        from pivy import coin
        sep = coin.SoSeparator()
        tracks = self.layout(mesh)
        size = float(np.linalg.norm(mesh.reshape(-1, 3).max(0) - mesh.reshape(-1, 3).min(0))) or 1.0
        for k, (name, _, _, _) in enumerate(SLIDERS):
            a, b = tracks[name]
            knob = a + self.fraction(name, self.shown_value(obj, name)) * (b - a)
            sep.addChild(shapes.lines(np.array([[a, b]]), (0.7, 0.7, 0.7), 2.0))
            sep.addChild(shapes.sphere(knob, 0.015 * size, (1.0, 0.6, 0.0) if self.held == name else (0.3, 0.8, 1.0)))
            number = coin.SoSeparator()
            number.addChild(shapes.material((1.0, 1.0, 1.0)))
            tr = coin.SoTranslation()
            tr.translation = tuple(float(x) for x in a - [0.0, 0.0, 0.03 * size])
            number.addChild(tr)
            t2 = coin.SoText2()
            t2.string = str(k + 1)
            number.addChild(t2)
            sep.addChild(number)
        return sep


def _distance_to_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = float(np.clip(np.dot(p - a, ab) / max(np.dot(ab, ab), 1e-300), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))
