"""The overlay's screen-space layer (GUI only): legends, the slider panel (labels, values, tracks
and knobs), the active tool and mode, drawn in view pixels by a scene of its own with an
orthographic camera, superimposed on the 3D view as FreeCAD's navigation cube is (after the scene,
its depth buffer cleared: nothing in 3D draws over it). So it stays inside the view at every zoom
and window size, keeps its size on screen, and Fit All does not see it. No Qt: pivy only.

Layout (pixels, origin bottom-left): the display's legend on the right edge below the navigation
cube's corner, the sliders in the top-left corner (each a text line over its track, one under
another), the tool and mode in the bottom-left. Each group stands on a semi-opaque dark backing,
so its white text reads on any background (white zebra stripes too).
:meth:`Hud.boxes` gives where each item went: the panel grabs its tracks there, tests check them.
"""
from __future__ import annotations

import math
import textwrap
from typing import Any

import numpy as np

from ..app import analysis

FONT_SIZE = 16.0  # points: a text line is about this many pixels high from baseline to cap
CHAR_WIDTH = 0.7 * FONT_SIZE  # pixels a character, a little over what the view's font takes (10.7 measured)
CUBE_CORNER = 170  # pixels kept free in the top-right corner (FreeCAD's navigation cube)
MARGIN = 12
BAR_WIDTH = 18
LABEL_WIDTH = 96  # room kept left of a colour bar for its range labels
TEXT = (1.0, 1.0, 1.0)
HELD = (1.0, 0.6, 0.0)
U_COLOUR, V_COLOUR = (0.0, 0.85, 0.0), (0.15, 0.35, 1.0)  # the paper's u green, v blue
U_LABEL, V_LABEL = (0.4, 1.0, 0.4), (0.55, 0.7, 1.0)  # the same, light enough to read on any background
UNITS = {"curvature": " 1/mm", "mean": " 1/mm", "gauss": " 1/mm^2", "deviation": " mm"}
LINE = FONT_SIZE + 4  # a text line's height
TRACK_ROW = 18  # a slider's track row under its text line
TRACK_WIDTH = 220
KNOB = (10, 14)  # a knob's width and height
TRACK_COLOUR, KNOB_COLOUR = (0.6, 0.6, 0.6), (0.3, 0.8, 1.0)
PAD = 6  # a backing's margin around what it backs
BACKING, BACKING_ALPHA = (0.08, 0.08, 0.1), 0.75  # dark, and opaque enough for white text on white
BACK_Z, FRONT_Z = -0.5, 0.0  # backings behind the items they back (the camera looks down -z from z = 1)


def readable(value: float) -> str:
    """A slider's value in plain decimals to three significant figures, six decimals at most: 2190,
    0.0123, 0.0001, 0 for 3e-17 (never 2.19e+03)."""
    if value == 0 or not math.isfinite(value):
        return f"{value:g}"
    decimals = min(6, max(0, 2 - math.floor(math.log10(abs(value)))))
    text = f"{value:.{decimals}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


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
        blend = coin.SoTransparencyType()  # backings blend in drawing order, before what they back
        blend.value = coin.SoTransparencyType.BLEND
        self.root.addChild(blend)
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

    def update(self, legend: tuple[str, tuple[float, float]] | None, sliders: list[tuple[str, float, bool, float]],
               status: str, zebra_bands: int = 12, tolerance: float = 0.1) -> None:
        """Redraws the layer: ``legend`` = (display, (lo, hi)) or None; ``sliders`` = (label, value,
        held, knob position 0..1) per slider, shown while the panel is; ``status`` = the tool and
        mode; ``zebra_bands``: the black and white bands the zebra legend shows (the stripe count);
        ``tolerance``: the deviation legend's band (mm)."""
        w, h = (int(x) for x in self.view.getSize())
        self.camera.position = (w / 2.0, h / 2.0, 1.0)
        self.camera.height = float(h)
        self.camera.aspectRatio = w / max(h, 1)
        self.content.removeAllChildren()
        self._boxes = {}
        lines = _wrap(status, int((w - 2 * MARGIN - 2 * PAD) // CHAR_WIDTH)) if status else []
        floor = MARGIN + len(lines) * LINE + 2 * PAD + 8  # the legend stays above the status lines
        if legend is not None:
            self._group("legend", lambda: self._legend(w, h, *legend, zebra_bands, floor, tolerance), w, h)
        if sliders:
            self._group("sliders", lambda: self._sliders(w, h, sliders, floor), w, h)
        if lines:
            self._group("status", lambda: [self._text(line, MARGIN + PAD, MARGIN + PAD + (len(lines) - 1 - k) * LINE,
                                                      TEXT, "status" if k == 0 else f"status{k + 1}", w)
                                           for k, line in enumerate(lines)], w, h)

    def _sliders(self, w: int, h: int, sliders: list[tuple[str, float, bool, float]], floor: float) -> None:
        """Each slider: its number, label and value, and its track with the knob, down from the
        top-left corner to the status lines (``floor``), left of the navigation cube's corner. The
        first layout that fits: each text over its track in one column; text and track side by
        side (a low view); either in more columns; else the first, running past the floor."""
        texts = [f"{k + 1}  {label} {readable(value)}" for k, (label, value, _, _) in enumerate(sliders)]
        chars = max(len(f"{k + 1}  {label} ") + 9 for k, (label, *_) in enumerate(sliders))  # (9: any value)
        top, room = h - MARGIN - PAD, w - CUBE_CORNER - MARGIN  # (room: where a column may end)
        layouts = []  # (row height, track's offset right of the text, column width)
        for side_by_side in (False, True):
            offset = chars * CHAR_WIDTH + PAD if side_by_side else 0.0
            layouts.append((FONT_SIZE + 6 if side_by_side else LINE + TRACK_ROW, offset,
                            max(TRACK_WIDTH + offset, chars * CHAR_WIDTH) + 2 * PAD + MARGIN))
        chosen = None
        for columns in (1, 2, 3):
            for step, offset, column in layouts:
                rows = -(-len(sliders) // columns)
                if top - rows * step >= floor and MARGIN + PAD + columns * column - MARGIN <= room:
                    chosen = (step, offset, column, rows)
                    break
            if chosen:
                break
        step, offset, column, rows = chosen or (*layouts[0], len(sliders))
        for k, (text, (_, _, held, f)) in enumerate(zip(texts, sliders)):
            x0 = MARGIN + PAD + (k // rows) * column
            row = top - (k % rows) * step
            self._text(text, x0, row - FONT_SIZE, HELD if held else TEXT, f"slider{k + 1}", w)
            tx = x0 + offset
            yc = row - FONT_SIZE / 2 - 1 if offset else row - LINE - TRACK_ROW / 2
            self._quad(tx, yc - 1.5, tx + TRACK_WIDTH, yc + 1.5, TRACK_COLOUR)
            kx = tx + f * TRACK_WIDTH
            self._quad(kx - KNOB[0] / 2, yc - KNOB[1] / 2, kx + KNOB[0] / 2, yc + KNOB[1] / 2, HELD if held else KNOB_COLOUR)
            self._boxes[f"track{k + 1}"] = (float(tx), float(yc - KNOB[1] / 2), float(tx + TRACK_WIDTH),
                                            float(yc + KNOB[1] / 2))

    def _group(self, name: str, draw: Any, w: int, h: int) -> None:
        """Draws a group of items, then its backing behind them: their bounding box and a margin,
        first in the scene (drawn first, further back), kept inside the view."""
        before = set(self._boxes)
        at = self.content.getNumChildren()
        draw()
        items = [b for k, b in self._boxes.items() if k not in before]
        if not items:
            return
        box = np.array(items)
        x0, y0 = max(box[:, 0].min() - PAD, 0.0), max(box[:, 1].min() - PAD, 0.0)
        x1, y1 = min(box[:, 2].max() + PAD, float(w)), min(box[:, 3].max() + PAD, float(h))
        self.content.insertChild(self._quad_node(x0, y0, x1, y1, BACKING, BACK_Z, 1.0 - BACKING_ALPHA), at)
        self._boxes[f"back_{name}"] = (float(x0), float(y0), float(x1), float(y1))

    def _quad(self, x0: float, y0: float, x1: float, y1: float, colour: Any) -> None:
        self.content.addChild(self._quad_node(x0, y0, x1, y1, colour, FRONT_Z, 0.0))

    @staticmethod
    def _quad_node(x0: float, y0: float, x1: float, y1: float, colour: Any, z: float, transparency: float) -> Any:
        from pivy import coin
        sep = coin.SoSeparator()
        mat = coin.SoMaterial()
        mat.diffuseColor = tuple(float(c) for c in colour)
        mat.transparency = float(transparency)
        sep.addChild(mat)
        coords = coin.SoCoordinate3()
        coords.point.setValues(0, 4, [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])
        sep.addChild(coords)
        faces = coin.SoFaceSet()
        faces.numVertices.setValue(4)
        sep.addChild(faces)
        return sep

    # --- items --------------------------------------------------------------------------------------
    def _legend(self, w: int, h: int, display: str, rng: tuple[float, float], zebra_bands: int, floor: float,
                tolerance: float = 0.1) -> None:
        """Colour bar(s) on the right edge below the cube's corner, range to their left, name above;
        zebra: ``zebra_bands`` black and white bands, one per stripe the display shows; deviation:
        the +-``tolerance`` band marked."""
        titles = 2 if display == "curvature" else 1  # text rows above the bar
        head = titles * (FONT_SIZE + 4) + 8
        x1 = w - MARGIN - PAD
        top = h - CUBE_CORNER - head
        bottom = max(floor, top - 0.45 * h)
        if top - bottom < 60:  # a low view: no room below the cube's corner, so beside it, full height
            x1 = w - CUBE_CORNER - MARGIN
            top = h - MARGIN - PAD - head
            bottom = max(floor, top - 0.6 * h)
        # A material map the same everywhere: one swatch and its value (its two ends read alike).
        # Zebra: a bar as tall as its bands need (its backing was a tall, mostly empty box).
        uniform = display not in UNITS and display != "zebra" and rng[1] - rng[0] <= 1e-6 * max(abs(rng[0]), 1.0)
        if uniform:
            bottom = max(bottom, top - 2 * FONT_SIZE)
        elif display == "zebra":
            bottom = max(bottom, top - max(8.0 * zebra_bands, 96.0))
        t = np.linspace(0.0, 1.0, 33)
        if uniform:
            bars = [("", analysis.pseudo_colour(np.zeros(2), 0.0, 1.0)[0], TEXT)]
        elif display == "curvature":  # two bars: u in green, v in blue, each from 0 to the top value
            bars = [("u", np.outer(t, U_COLOUR), U_LABEL), ("v", np.outer(t, V_COLOUR), V_LABEL)]
        elif display == "zebra":
            bands = np.arange(int(zebra_bands) + 1) % 2  # (one more: _bar draws n - 1 quads for n colours)
            bars = [("", np.repeat(bands[:, None].astype(float), 3, axis=1), TEXT)]
        elif display == "deviation":
            bars = [("", analysis.deviation_colours(rng[0] + t * (rng[1] - rng[0]), tolerance, rng)[0], TEXT)]
        else:
            bars = [("", analysis.pseudo_colour(t, 0.0, 1.0)[0], TEXT)]
        x0 = x1 - len(bars) * BAR_WIDTH - (len(bars) - 1) * 6
        for k, (name, colours, label) in enumerate(bars):
            bx = x0 + k * (BAR_WIDTH + 6)
            self._bar(bx, bottom, bx + BAR_WIDTH, top, colours)
            if name:
                self._text(name, bx + 4, top + 4, label, f"legend_{name}", w)
        units = UNITS.get(display, "")
        if uniform:
            self._text(f"{readable(rng[0])} everywhere", x0 - 6, bottom, TEXT, "legend_lo", w, right=True)
        elif display != "zebra":  # (a material map's values as the sliders give them: 100000, not 1e+05)
            show = (lambda v: f"{v:.3g}") if display in UNITS else readable
            self._text(f"{show(rng[1])}{units}", x0 - 6, top - FONT_SIZE, TEXT, "legend_hi", w, right=True)
            self._text(f"{show(rng[0])}{units}", x0 - 6, bottom, TEXT, "legend_lo", w, right=True)
        if display == "deviation" and rng[1] > rng[0]:  # the band within the tolerance, labelled at its middle
            middle = bottom + (top - bottom) * (0.0 - rng[0]) / (rng[1] - rng[0])
            self._text(f"\u00b1{tolerance:.3g}{units}", x0 - 6, middle - FONT_SIZE / 2, TEXT, "legend_band", w, right=True)
        title = {"curvature": "curvature u / v", "mean": "mean curvature", "gauss": "Gaussian curvature",
                 "zebra": f"zebra: {int(zebra_bands)} stripes", "deviation": "deviation from the scan"}.get(display, display)
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
        estimate from the font size (CHAR_WIDTH)."""
        from pivy import coin
        width = CHAR_WIDTH * len(text)
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


def _wrap(text: str, width: int) -> list[str]:
    """The status line in lines of at most ``width`` characters, broken between its parts, and a
    part longer than a line between its words (a last stroke's reason ran off a narrow view)."""
    lines: list[str] = []
    for part in text.split("  |  "):
        if lines and len(lines[-1]) + 5 + len(part) <= width:
            lines[-1] += "  |  " + part
        else:
            lines.extend(textwrap.wrap(part, max(width, 10)) or [part])
    return lines
