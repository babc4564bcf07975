"""The overlay's screen-space layer (GUI only): legends, the slider panel's labels and values, the
active tool and mode, drawn in view pixels by a scene of its own with an orthographic camera,
superimposed on the 3D view as FreeCAD's navigation cube is. So it stays inside the view at every
zoom and window size, keeps its size on screen, and Fit All does not see it. No Qt: pivy only.

Layout (pixels, origin bottom-left): the display's legend on the right edge below the navigation
cube's corner, the slider values in the top-left corner, the tool and mode in the bottom-left.
:meth:`Hud.boxes` gives where each item went, for tests and for anything placed beside it.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..app import analysis

FONT_SIZE = 16.0  # points: each text line is about this many pixels high
CUBE_CORNER = 170  # pixels kept free in the top-right corner (FreeCAD's navigation cube)
MARGIN = 12
BAR_WIDTH = 18
LABEL_WIDTH = 96  # room kept left of a colour bar for its range labels
TEXT = (1.0, 1.0, 1.0)
HELD = (1.0, 0.6, 0.0)
U_COLOUR, V_COLOUR = (0.0, 0.85, 0.0), (0.15, 0.35, 1.0)  # the paper's u green, v blue
U_LABEL, V_LABEL = (0.4, 1.0, 0.4), (0.55, 0.7, 1.0)  # the same, light enough to read on any background
UNITS = {"curvature": " 1/mm", "mean": " 1/mm", "gauss": " 1/mm^2"}


class Hud:
    """The screen-space layer of one overlay in one 3D view."""

    def __init__(self, view: Any) -> None:
        from pivy import coin
        self.view = view
        self.root = coin.SoSeparator()
        self.root.ref()
        self.camera = coin.SoOrthographicCamera()
        self.camera.viewportMapping = coin.SoCamera.LEAVE_ALONE
        self.camera.nearDistance = 0.5
        self.camera.farDistance = 2.0
        self.root.addChild(self.camera)
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        self.root.addChild(light)
        font = coin.SoFont()
        font.size = FONT_SIZE
        self.root.addChild(font)
        self.content = coin.SoSeparator()
        self.root.addChild(self.content)
        self._boxes: dict[str, tuple[float, float, float, float]] = {}
        self._handle = view.getViewer().getSoRenderManager().addSuperimposition(self.root)

    def remove(self) -> None:
        try:
            self.view.getViewer().getSoRenderManager().removeSuperimposition(self._handle)
        except Exception:  # noqa: BLE001 - the view is closed: its render manager went with it
            pass
        self.root.unref()

    def boxes(self) -> dict[str, tuple[float, float, float, float]]:
        """Where each item was drawn last: name -> (x0, y0, x1, y1) in view pixels."""
        return dict(self._boxes)

    def clear(self) -> None:
        self.content.removeAllChildren()
        self._boxes = {}

    def update(self, legend: tuple[str, tuple[float, float]] | None, sliders: list[tuple[str, float, bool]],
               status: str) -> None:
        """Redraws the layer: ``legend`` = (display, (lo, hi)) or None; ``sliders`` = (label, value,
        held) per slider in track order, shown while the panel is; ``status`` = the tool and mode."""
        w, h = (int(x) for x in self.view.getSize())
        self.camera.position = (w / 2.0, h / 2.0, 1.0)
        self.camera.height = float(h)
        self.camera.aspectRatio = w / max(h, 1)
        self.content.removeAllChildren()
        self._boxes = {}
        if legend is not None:
            self._legend(w, h, *legend)
        line = FONT_SIZE + 4
        for k, (label, value, held) in enumerate(sliders):
            self._text(f"{k + 1}  {label} {value:.3g}", MARGIN, h - MARGIN - line * (k + 1), HELD if held else TEXT,
                       f"slider{k + 1}", w)
        if status:
            self._text(status, MARGIN, MARGIN, TEXT, "status", w)

    # --- items --------------------------------------------------------------------------------------
    def _legend(self, w: int, h: int, display: str, rng: tuple[float, float]) -> None:
        """Colour bar(s) on the right edge below the cube's corner, range to their left, name above."""
        titles = 2 if display == "curvature" else 1  # text rows above the bar
        head = titles * (FONT_SIZE + 4) + 8
        x1 = w - MARGIN
        top = h - CUBE_CORNER - head
        bottom = max(MARGIN + FONT_SIZE + 8, top - 0.45 * h)
        if top - bottom < 60:  # a low view: no room below the cube's corner, so beside it, full height
            x1 = w - CUBE_CORNER - MARGIN
            top = h - MARGIN - head
            bottom = max(MARGIN + FONT_SIZE + 8, top - 0.6 * h)
        t = np.linspace(0.0, 1.0, 33)
        if display == "curvature":  # two bars: u in green, v in blue, each from 0 to the top value
            bars = [("u", np.outer(t, U_COLOUR), U_LABEL), ("v", np.outer(t, V_COLOUR), V_LABEL)]
        elif display == "zebra":
            bars = [("", np.repeat((np.floor(t * 8) % 2)[:, None], 3, axis=1), TEXT)]
        else:
            bars = [("", analysis.pseudo_colour(t, 0.0, 1.0)[0], TEXT)]
        x0 = x1 - len(bars) * BAR_WIDTH - (len(bars) - 1) * 6
        for k, (name, colours, label) in enumerate(bars):
            bx = x0 + k * (BAR_WIDTH + 6)
            self._bar(bx, bottom, bx + BAR_WIDTH, top, colours)
            if name:
                self._text(name, bx + 4, top + 4, label, f"legend_{name}", w)
        units = UNITS.get(display, "")
        if display != "zebra":
            self._text(f"{rng[1]:.3g}{units}", x0 - 6, top - FONT_SIZE, TEXT, "legend_hi", w, right=True)
            self._text(f"{rng[0]:.3g}{units}", x0 - 6, bottom, TEXT, "legend_lo", w, right=True)
        title = {"curvature": "curvature u / v", "mean": "mean curvature", "gauss": "Gaussian curvature"}.get(display,
                                                                                                          display)
        self._text(title, x1, top + 6 + (titles - 1) * (FONT_SIZE + 4), TEXT, "legend_title", w, right=True)
        self._boxes["legend_bar"] = (float(x0), float(bottom), float(x1), float(top))

    def _bar(self, x0: float, y0: float, x1: float, y1: float, colours: np.ndarray) -> None:
        from pivy import coin
        n = len(colours) - 1
        ys = np.linspace(y0, y1, n + 1)
        quads = np.array([[[x0, ys[k], 0], [x1, ys[k], 0], [x1, ys[k + 1], 0], [x0, ys[k + 1], 0]] for k in range(n)])
        sep = coin.SoSeparator()
        mat = coin.SoMaterial()
        mat.diffuseColor.setValues(0, n, np.asarray(colours[:n], float).tolist())
        sep.addChild(mat)
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_FACE
        sep.addChild(binding)
        coords = coin.SoCoordinate3()
        coords.point.setValues(0, 4 * n, quads.reshape(-1, 3).tolist())
        sep.addChild(coords)
        faces = coin.SoFaceSet()
        faces.numVertices.setValues(0, n, [4] * n)
        sep.addChild(faces)
        self.content.addChild(sep)

    def _text(self, text: str, x: float, y: float, colour: Any, name: str, w: int, right: bool = False) -> None:
        """One line with its baseline at y, starting at x (ending at x if ``right``); its box is an
        estimate from the font size (0.6 em a character)."""
        from pivy import coin
        width = 0.6 * FONT_SIZE * len(text)
        if not right:
            x = min(x, w - MARGIN - width)  # (a long status line stays inside a narrow view)
        sep = coin.SoSeparator()
        mat = coin.SoMaterial()
        mat.diffuseColor = tuple(float(c) for c in colour)
        sep.addChild(mat)
        tr = coin.SoTranslation()
        tr.translation = (float(x), float(y), 0.0)
        sep.addChild(tr)
        t2 = coin.SoText2()
        t2.string = text
        if right:
            t2.justification = coin.SoText2.RIGHT
        sep.addChild(t2)
        self.content.addChild(sep)
        x0 = x - width if right else x
        self._boxes[name] = (float(x0), float(y), float(x0 + width), float(y + FONT_SIZE))
