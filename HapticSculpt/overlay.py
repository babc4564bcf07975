"""The immediate-mode Coin3D overlay of one sculpt object in one 3D view (GUI only).

Each frame (a Coin timer at up to 60 Hz, scheduled only while a session runs or an analysis display
is on) the overlay throws its previous scene away and draws a new one from the current state: the
surface coloured by the active display (shading, a material map, curvature in the paper's green/blue
channels, mean or Gaussian curvature, zebra stripes), curvature combs, the constraint jacks (point:
red cross, normal: blue line, curvature: white circle), the cursor with its axes, the nearest surface
point with its axes, the rope, the legend of the display's range and the slider panel. Nothing is
retained between frames but the Coin root it draws into; nothing is computed for a display that is
off. No Qt: everything is pivy.
"""
from __future__ import annotations

import functools
import math
import time
from typing import Any

import numpy as np

from . import analysis, core, sculpt_state
from .panel import SliderPanel

DISPLAYS = ("shading", "mass", "damping", "stiffness", "curvature", "mean", "gauss", "zebra")
JACK_COLOURS = {"point": (1.0, 0.0, 0.0), "tangent": (1.0, 0.5, 0.0), "normal": (0.0, 0.3, 1.0), "curvature": (1.0, 1.0, 1.0)}


def readable_surface(obj: Any) -> core.DynamicSurface:
    """The sculpt's core surface for reading what the simulation never writes (the B-spline's knots
    and degrees, constraints, tool settings), also while a session steps it. Its poles and mesh
    move under a session: take those from :meth:`Overlay.scratch`; the airbrush paints its maps:
    take those from :func:`material_values`."""
    proxy = obj.Proxy
    session = getattr(proxy, "session", None)
    if session is not None and session.running and getattr(proxy, "_surface", None) is not None:
        return proxy._surface
    return proxy.surface


def material_values(obj: Any, name: str) -> np.ndarray:
    """Material map ``name`` ("mass", "damping", "stiffness") as a (rows, cols) array. While a
    session runs its simulation thread may be spraying the live map, so this reads the session's
    newest snapshot of a sprayed map (published at the graphics rate), else the stored one."""
    session = getattr(obj.Proxy, "session", None)
    if session is not None and session.running:
        if name in session.latest_maps:
            return session.latest_maps[name]
        prop = sculpt_state.map_property(name)
        rows, cols = sculpt_state.parse_settings(obj.SculptSettings)["maps"][prop]
        return np.asarray(getattr(obj, prop), dtype=float).reshape(int(rows), int(cols))
    return np.array(getattr(obj.Proxy.surface, name + "_map").values)


class Overlay:
    """Draws the sculpt `obj` in `view` (a FreeCADGui 3D view) from scratch every frame."""

    def __init__(self, view: Any, obj: Any) -> None:
        from pivy import coin
        self.view, self.obj = view, obj
        self.display = "shading"
        self.combs = False
        self.panel_visible = False
        self.panel = SliderPanel()
        self.cursor: tuple[np.ndarray, np.ndarray, bool] | None = None  # position, quaternion (w, x, y, z), grab
        self.contact: np.ndarray | None = None
        self.frame_ms = 0.0  # cost of the last frame
        self.frames = 0
        self._root = coin.SoSeparator()
        self._root.setName("HapticSculptOverlay")
        self._timer: Any = None
        self._scratch: core.DynamicSurface | None = None  # private copy for analysis (never the live one)
        view.getSceneGraph().addChild(self._root)

    # --- life cycle -------------------------------------------------------------------------------
    @property
    def needed(self) -> bool:
        """True while anything is to be drawn each frame."""
        session = getattr(self.obj.Proxy, "session", None)
        return bool((session is not None and session.running) or self.display != "shading" or self.combs
                    or self.panel_visible)

    def start(self, rate: float = 60.0) -> None:
        from pivy import coin
        if self._timer is None:
            self._timer = coin.SoTimerSensor(lambda *_: self.frame(), None)
            self._timer.setInterval(coin.SbTime(1.0 / rate))
            self._timer.schedule()

    def stop(self) -> None:
        if self._timer is not None:
            self._timer.unschedule()
            self._timer = None
        self._root.removeAllChildren()

    def remove(self) -> None:
        self.stop()
        graph = self.view.getSceneGraph()
        if graph.findChild(self._root) >= 0:
            graph.removeChild(self._root)

    def refresh(self) -> None:
        """Starts or stops the timer to match what is on, and draws once."""
        if self.needed:
            self.start()
            self.frame()
        else:
            self.stop()

    # --- state ------------------------------------------------------------------------------------
    def scratch(self) -> core.DynamicSurface:
        """A private analysis surface holding the newest poles (the session's snapshot while one
        runs, else the object's), so the GUI never reads the surface the simulation steps."""
        live = readable_surface(self.obj)
        session = getattr(self.obj.Proxy, "session", None)
        running = session is not None and session.running
        poles = getattr(session, "latest_poles", None) if running else None
        if self._scratch is None or self._scratch.mesh.shape != live.mesh.shape or \
                self._scratch.poles.shape != live.poles.shape:
            self._scratch = core.DynamicSurface(live.surface, live.mesh.shape[:2])
        if poles is not None or not running:  # (before a session's first snapshot: the shape it started from)
            self._scratch.set_poles(np.asarray(poles if poles is not None else live.poles).reshape(live.poles.shape))
        return self._scratch

    def _update_cursor(self) -> None:
        session = getattr(self.obj.Proxy, "session", None)
        if session is not None and session.running:
            st = session.status()
            if "cursor" in st:
                self.cursor = (np.asarray(st["cursor"], float), np.asarray(st["orientation"], float), bool(st["grab"]))
                self.contact = None if st.get("contact") is None else np.asarray(st["contact"], float)

    # --- one frame --------------------------------------------------------------------------------
    def frame(self) -> None:
        """Rebuilds the whole overlay from the current state."""
        from pivy import coin
        t0 = time.perf_counter()
        if not self.needed:
            self.stop()
            return
        self._update_cursor()
        s = self.scratch()
        mesh = np.array(s.mesh)
        live = readable_surface(self.obj)
        scene = coin.SoSeparator()
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        if self.display != "shading":
            colours, rng = self._colours(s, mesh, live)
            scene.addChild(_coloured_mesh(mesh, colours))
            scene.addChild(_legend(mesh, self.display, rng))
        decor = coin.SoSeparator()
        decor.addChild(light)
        if self.combs:
            segments, _ = analysis.curvature_combs(mesh, s.curvature_grid().reshape(mesh.shape[:2] + (6,)))
            decor.addChild(_lines(segments, (1.0, 0.0, 1.0), 1.0))
        decor.addChild(self._jacks(live, mesh))
        if self.cursor is not None:
            decor.addChild(self._cursor(s, mesh))
        if self.panel_visible:
            grab = self.cursor[2] if self.cursor is not None else False
            if self.cursor is not None:
                self.panel.operate(self.cursor[0], grab, self.obj)
            decor.addChild(self.panel.draw(self.obj, mesh))
        scene.addChild(decor)
        self._root.removeAllChildren()
        self._root.addChild(scene)
        self.frames += 1
        self.frame_ms = (time.perf_counter() - t0) * 1e3

    def _colours(self, s: core.DynamicSurface, mesh: np.ndarray, live: core.DynamicSurface) -> tuple[np.ndarray, tuple[float, float]]:
        g, h = mesh.shape[:2]
        if self.display in ("mass", "damping", "stiffness"):
            return analysis.map_colours(material_values(self.obj, self.display), (g, h))
        if self.display == "zebra":
            d = self.view.getViewDirection()
            return analysis.zebra_colours(mesh, np.array([d[0], d[1], d[2]]))
        curv = s.curvature_grid().reshape(g, h, 6)
        if self.display == "curvature":
            return analysis.curvature_channels(curv)
        if self.display == "mean":
            return analysis.mean_curvature_colours(curv)
        return analysis.gaussian_curvature_colours(curv)

    def _jacks(self, live: core.DynamicSurface, mesh: np.ndarray) -> Any:
        from pivy import coin
        sep = coin.SoSeparator()
        flat = mesh.reshape(-1, 3)
        size = float(np.linalg.norm(flat.max(0) - flat.min(0))) or 1.0
        r = 0.03 * size
        g, h = mesh.shape[:2]
        for c in live.constraints:
            p = flat[c["index"]]
            kind = c["kind"]
            colour = JACK_COLOURS[kind]
            if kind == "point":
                segs = [[p - [r, r, 0], p + [r, r, 0]], [p - [r, -r, 0], p + [r, -r, 0]], [p - [0, 0, r], p + [0, 0, r]]]
                sep.addChild(_lines(np.array(segs), colour, 3.0))
            elif kind in ("normal", "tangent"):
                n = np.asarray(c["target"], float)
                sep.addChild(_lines(np.array([[p, p + 3 * r * n]]), colour, 3.0))
            else:
                i, j = divmod(c["index"], h)
                sep.addChild(_circle(p, _frame(*_tangents(mesh, i, j))[:, 2], r, colour))
        return sep

    def _cursor(self, s: core.DynamicSurface, mesh: np.ndarray) -> Any:
        from pivy import coin
        pos, quat, grab = self.cursor
        flat = mesh.reshape(-1, 3)
        size = float(np.linalg.norm(flat.max(0) - flat.min(0))) or 1.0
        sep = coin.SoSeparator()
        sep.addChild(_sphere(pos, 0.02 * size, (1.0, 0.85, 0.0) if grab else (0.9, 0.9, 0.9)))
        sep.addChild(_axes(pos, _rotation(quat), 0.06 * size))
        nearest = int(s.nearest_mesh_index(list(pos)))
        i, j = divmod(nearest, mesh.shape[1])
        frame = _frame(*_tangents(mesh, i, j))
        point = flat[nearest]
        sep.addChild(_sphere(point, 0.012 * size, (0.2, 1.0, 0.2)))
        sep.addChild(_axes(point, frame, 0.05 * size))
        if self.contact is not None and grab:
            sep.addChild(_lines(np.array([[pos, self.contact]]), (1.0, 0.85, 0.0), 2.0))
        return sep


# --- Coin building blocks (each returns a new node) --------------------------------------------------
def _material(colour: tuple[float, float, float]) -> Any:
    from pivy import coin
    m = coin.SoMaterial()
    m.diffuseColor = colour
    m.emissiveColor = colour
    return m


def _lines(segments: np.ndarray, colour: tuple[float, float, float], width: float) -> Any:
    from pivy import coin
    sep = coin.SoSeparator()
    style = coin.SoDrawStyle()
    style.lineWidth = width
    sep.addChild(style)
    sep.addChild(_material(colour))
    coords = coin.SoCoordinate3()
    pts = np.asarray(segments, float).reshape(-1, 3)
    coords.point.setValues(0, len(pts), pts.tolist())
    sep.addChild(coords)
    lines = coin.SoLineSet()
    lines.numVertices.setValues(0, len(segments), [2] * len(segments))
    sep.addChild(lines)
    return sep


def _sphere(centre: np.ndarray, radius: float, colour: tuple[float, float, float]) -> Any:
    from pivy import coin
    sep = coin.SoSeparator()
    sep.addChild(_material(colour))
    t = coin.SoTranslation()
    t.translation = tuple(float(x) for x in centre)
    sep.addChild(t)
    sphere = coin.SoSphere()
    sphere.radius = radius
    sep.addChild(sphere)
    return sep


def _axes(origin: np.ndarray, rotation: np.ndarray, length: float) -> Any:
    from pivy import coin
    sep = coin.SoSeparator()
    for k, colour in enumerate(((1.0, 0.0, 0.0), (0.0, 0.8, 0.0), (0.0, 0.3, 1.0))):
        sep.addChild(_lines(np.array([[origin, origin + length * rotation[:, k]]]), colour, 2.0))
    return sep


def _circle(centre: np.ndarray, normal: np.ndarray, radius: float, colour: tuple[float, float, float]) -> Any:
    a = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(a) < 1e-6:
        a = np.cross(normal, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(normal, a)
    t = np.linspace(0, 2 * math.pi, 33)
    pts = centre + radius * (np.cos(t)[:, None] * a + np.sin(t)[:, None] * b)
    return _lines(np.stack([pts[:-1], pts[1:]], axis=1), colour, 3.0)


def _rotation(quat: np.ndarray) -> np.ndarray:
    w, x, y, z = quat / (np.linalg.norm(quat) or 1.0)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _tangents(mesh: np.ndarray, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
    """Mesh tangents along u and v at point (i, j) by differences (one-sided at the border)."""
    g, h = mesh.shape[:2]
    du = mesh[min(i + 1, g - 1), j] - mesh[max(i - 1, 0), j]
    dv = mesh[i, min(j + 1, h - 1)] - mesh[i, max(j - 1, 0)]
    return du, dv


def _frame(du: np.ndarray, dv: np.ndarray) -> np.ndarray:
    u = du / (np.linalg.norm(du) or 1.0)
    n = np.cross(du, dv)
    n = n / (np.linalg.norm(n) or 1.0)
    v = np.cross(n, u)
    return np.column_stack([u, v, n])


def _coloured_mesh(mesh: np.ndarray, colours: np.ndarray) -> Any:
    """The mesh as triangles with per-vertex colours, unlit, pulled a hair toward the viewer so it
    covers the shaded face."""
    from pivy import coin
    g, h = mesh.shape[:2]
    sep = coin.SoSeparator()
    light = coin.SoLightModel()
    light.model = coin.SoLightModel.BASE_COLOR
    sep.addChild(light)
    offset = coin.SoPolygonOffset()
    offset.factor = -1.0
    offset.units = -1.0
    sep.addChild(offset)
    mat = coin.SoMaterial()
    mat.diffuseColor.setValues(0, g * h, np.asarray(colours, float).reshape(-1, 3).tolist())
    sep.addChild(mat)
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.PER_VERTEX_INDEXED
    sep.addChild(binding)
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, g * h, mesh.reshape(-1, 3).tolist())
    sep.addChild(coords)
    quads = _quad_indices(g, h)
    faces = coin.SoIndexedFaceSet()
    faces.coordIndex.setValues(0, len(quads), quads)  # (materialIndex empty: colours follow coordIndex)
    sep.addChild(faces)
    return sep


@functools.lru_cache(maxsize=8)
def _quad_indices(g: int, h: int) -> list[int]:
    """Face indices of a g x h grid as quads (-1 separated); the same every frame, so made once."""
    i, j = np.meshgrid(np.arange(g - 1), np.arange(h - 1), indexing="ij")
    a = (i * h + j).ravel()
    return np.stack([a, a + h, a + h + 1, a + 1, np.full_like(a, -1)], axis=1).ravel().tolist()


def _legend(mesh: np.ndarray, display: str, rng: tuple[float, float]) -> Any:
    """A colour bar beside the patch (+x side) with the display's name and range."""
    from pivy import coin
    flat = mesh.reshape(-1, 3)
    lo, hi = flat.min(0), flat.max(0)
    size = float(np.linalg.norm(hi - lo)) or 1.0
    x0, y0, z0 = hi[0] + 0.08 * size, lo[1], hi[2]
    steps = 16
    t = np.linspace(0, 1, steps + 1)
    if display == "curvature":
        colours = np.stack([np.zeros_like(t), t, t[::-1] * 0 + t], axis=1)
    elif display == "zebra":
        colours = np.repeat((np.floor(t * 8) % 2)[:, None], 3, axis=1)
    else:
        colours, _ = analysis.pseudo_colour(t, 0.0, 1.0)
    w = 0.04 * size
    ys = y0 + t * (hi[1] - lo[1])
    quads = np.array([[[x0, ys[k], z0], [x0 + w, ys[k], z0], [x0 + w, ys[k + 1], z0], [x0, ys[k + 1], z0]]
                      for k in range(steps)])
    sep = coin.SoSeparator()
    light = coin.SoLightModel()
    light.model = coin.SoLightModel.BASE_COLOR
    sep.addChild(light)
    mat = coin.SoMaterial()
    mat.diffuseColor.setValues(0, steps, colours[:steps].tolist())
    sep.addChild(mat)
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.PER_FACE
    sep.addChild(binding)
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, 4 * steps, quads.reshape(-1, 3).tolist())
    sep.addChild(coords)
    faces = coin.SoFaceSet()
    faces.numVertices.setValues(0, steps, [4] * steps)
    sep.addChild(faces)
    units = {"mass": "", "damping": "", "stiffness": "", "curvature": " 1/mm", "mean": " 1/mm",
             "gauss": " 1/mm^2", "zebra": ""}[display]
    for y, text in ((ys[0], f"{rng[0]:.3g}{units}"), (ys[-1], f"{rng[1]:.3g}{units}"),
                    (ys[-1] + 0.15 * size, display)):
        label = coin.SoSeparator()
        label.addChild(_material((1.0, 1.0, 1.0)))
        tr = coin.SoTranslation()
        tr.translation = (float(x0 + 1.3 * w), float(y), float(z0))
        label.addChild(tr)
        font = coin.SoFont()
        font.size = 18.0  # screen points: Coin's default bitmap font is hard to read beside a patch
        label.addChild(font)
        txt = coin.SoText2()
        txt.string = text
        label.addChild(txt)
        sep.addChild(label)
    return sep
