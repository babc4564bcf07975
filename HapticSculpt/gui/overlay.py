"""The immediate-mode Coin3D overlay of one sculpt object in one 3D view (GUI only).

Each frame (a Coin timer at up to 60 Hz, scheduled only while a session runs or an analysis display
is on; the constraint jacks alone are drawn once per change) the overlay throws its previous scene
away and draws a new one from the current state: the surface coloured by the active display
(shading, a material map, curvature in the paper's green/blue channels, mean or Gaussian
curvature, zebra stripes), curvature combs, the constraint jacks (point:
red cross, normal: blue line, curvature: white circle), the cursor with its axes, the nearest surface
point with its axes and the rope; its screen-space layer (:mod:`hud`) shows the legend of the
display's range, the slider panel (operated with the mouse there), the tool and the mode. Nothing is
retained between frames but the Coin roots it draws into; nothing is computed for a display that is
off. The displays and the jacks lie on the surface, so they show only while it does: the sculpt
shown, or the SculptedSolid it is a face of shown (a Thickness made from the sculpt, a Part Cut of
its solid hide it, and its displays with it); the cursor and the HUD of a running session stay.
No Qt: everything is pivy.
"""
from __future__ import annotations

import time
from typing import Any

import numpy as np

from .. import core
from ..app import analysis, continuity_check, curve_constraint
from . import coin_shapes as shapes
from . import kept_displays
from . import stripes as stripe_shading
from .hud import Hud
from .panel import SliderPanel, rounded, sliders

MAPS = ("mass", "damping", "stiffness", "bending", "pull")
DISPLAYS = ("shading", *MAPS, "curvature", "mean", "gauss", "zebra", "deviation")
#: Scan points the deviation display colours (evenly taken), and how often they are measured again
#: while the surface moves (a session): the surface's own colours follow every frame.
SCAN_POINTS_SHOWN = 60_000
SCAN_REMEASURE_S = 0.5
JACK_COLOURS = {"point": (1.0, 0.0, 0.0), "tangent": (1.0, 0.5, 0.0), "normal": (0.0, 0.3, 1.0), "curvature": (1.0, 1.0, 1.0)}
#: Curves the surface follows, drawn on it: G0 (through) and G1 (with its normal).
CURVE_COLOURS = {"G0": (0.0, 0.9, 1.0), "G1": (1.0, 0.6, 0.0)}
#: How long the HUD shows what a command refused (s).
NOTICE_SHOWN_S = 8.0
#: The continuity check's combs, by what holds across the edge.
CONTINUITY_COLOURS = {"G2": (0.1, 0.85, 0.2), "G1": (1.0, 0.9, 0.0), "G0": (1.0, 0.45, 0.0), "none": (1.0, 0.0, 0.0)}


class Overlay:
    """Draws the sculpt `obj` in `view` (a FreeCADGui 3D view) from scratch every frame."""

    def __init__(self, view: Any, obj: Any) -> None:
        from pivy import coin
        self.view, self.obj = view, obj
        self.display = "shading"
        self.combs = False
        self.continuity = False  # the continuity check: combs across edges, seams and curves
        self.neighbours_drawn = 0  # faces next to the sculpted ones the last frame's display covered
        self.continuity_worst: dict[str, Any] = {}
        # poles, profiles, their samples' levels, when, cost
        self._continuity: tuple[bytes, list[Any], list[np.ndarray], float, float] | None = None
        self._own_edges: tuple[Any, dict[str, str]] | None = None  # (the solid's names of its edges, see _edge_said)
        self.comb_every = 4  # a comb on every n-th iso-line of the mesh (density)
        self.comb_gain = 1.0  # the longest tooth is this many tenths of the patch size (scale)
        self.panel_visible = False
        self.panel = SliderPanel()
        self.cursor: tuple[np.ndarray, np.ndarray, bool] | None = None  # position, quaternion (w, x, y, z), grab
        self.contact: np.ndarray | None = None
        self.cursor_shown = False  # whether the last frame drew the cursor
        self.surface_drawn = False  # whether the last frame drew anything on the surface (a display, jacks)
        self.live = True  # a session is drawn each frame here (the view the pointer is in; see Controller)
        self.frame_ms = 0.0  # cost of the last frame
        self.frames = 0
        self.mode = ""  # what the workbench is doing besides (the airbrush), shown in the HUD
        self.stripe_mode = "reflection"  # zebra: "reflection" (view-dependent) or "isophote" (world-fixed)
        self.stripes = 12.0  # zebra: bands over a half turn
        self.status_text = ""  # the HUD's status line, as last drawn
        self._notice: tuple[str, float] | None = None  # (what a command refused or did, when): shown a while
        self.stripe_direction = (0.0, 0.0, 1.0)  # isophote: the direction the bands' angle is taken to
        self.stripe_angle = 0.0  # reflection: the light strips' angle from the view's up direction (degrees)
        self.per_pixel = True  # zebra per pixel where the driver runs GLSL (False: per mesh vertex)
        self._sampled: tuple[bytes, np.ndarray, tuple[bytes, bytes], int] | None = None  # poles, points, texture, size
        self._scan: tuple[bytes, float, Any, Any] | None = None  # poles, when, the scan's points, their deviations
        self.legend: tuple[str, tuple[float, float]] | None = None  # the HUD legend's display and range
        self._live_deviation: str | None = None  # the HUD's line as the scan's points last measured it
        self._trims: dict[tuple[int, int], list[int] | None] = {}  # grid size -> cells on the trimmed face
        self._curve_rows: tuple[Any, list[tuple[str, Any]]] = (None, [])  # (CurveConstraints text, net) -> (kind, rows)
        self.hud: Hud | None = None  # the screen-space layer, made when the overlay first draws
        self.speaks: Any = lambda overlay: True  # whether its HUD is the view's one (set by the Controller)
        self.mouse: Any = lambda overlay: None  # the mouse's cursor it shows, if any (set by the Controller)
        self.lifting: Any = lambda overlay: None  # mm a mouse grab lifted toward the eye, if any (the Controller's)
        self.hidden_scan: Any = None  # the target's mesh the deviation display hid (it draws the points)
        self._root = coin.SoSeparator()
        self._root.setName("HapticSculptOverlay")
        self._timer: Any = None
        self._lift = coin.SoTranslation()  # see _place_lift
        self._lift_by = 0.0
        self._camera_sensor = coin.SoNodeSensor(lambda *_: self._place_lift(), None)
        view.getSceneGraph().addChild(self._root)
        self._defaults = kept_displays.settings_of(self)
        choices = {"display": DISPLAYS, "stripe_mode": stripe_shading.MODES}
        for name, value in kept_displays.kept(obj).items():  # (as the file was saved)
            if value in choices.get(name, (value,)):
                setattr(self, name, value)

    # --- life cycle -------------------------------------------------------------------------------
    @property
    def needed(self) -> bool:
        """True while anything is to be drawn each frame (a notice too, until it is taken away)."""
        return bool((self._session() is not None and self.live) or self.panel_visible
                    or ((self.display != "shading" or self.combs or self.continuity) and self.visible())
                    or (self._notice is not None and self.visible()))

    @property
    def shown(self) -> bool:
        """True while anything is to be drawn at all: what runs each frame, and the constraint jacks,
        which show whenever the sculpt does (drawn once per change, no timer)."""
        return self.needed or bool(self.visible() and (self.snapshot().constraints or self._curves_text()))

    def visible(self) -> bool:
        """The surface shows: the sculpt itself, a shown SculptedSolid it is a face of, or a shown
        Thickness made from it (drawn on the slab's face: :meth:`offset`)."""
        from ..app.sculpted_solid import solid_of
        vobj = getattr(self.obj, "ViewObject", None)
        if vobj is None or vobj.Visibility:
            return True
        solid = solid_of(self.obj)
        svobj = getattr(solid, "ViewObject", None) if solid is not None else None
        return bool(svobj is not None and svobj.Visibility) or self._thickness() is not None

    def _thickness(self) -> Any:
        """A shown Thickness made from this sculpt, which hides it, else None."""
        from ..app.thickness import is_thickness
        vobj = getattr(self.obj, "ViewObject", None)
        if vobj is None or vobj.Visibility:
            return None
        return next((o for o in self.obj.InList if is_thickness(o)
                     and getattr(getattr(o, "ViewObject", None), "Visibility", False)), None)

    def offset(self) -> float:
        """How far along the surface's normal the displays are drawn (mm): a shown Thickness's
        value where it is positive, so they lie on the slab's face on that side (the sculpt's own
        face is then inside the slab, where they could not be seen); else 0."""
        thickness = self._thickness()
        return max(float(thickness.Thickness.Value), 0.0) if thickness is not None else 0.0

    def _session(self) -> Any:
        live = getattr(self.obj.Proxy, "live", None)  # (None while its document is being read)
        return live.session if live is not None else None

    def start(self, rate: float = 60.0) -> None:
        from pivy import coin
        if self._timer is None:
            self._timer = coin.SoTimerSensor(lambda *_: self._tick(), None)
            self._timer.setInterval(coin.SbTime(1.0 / rate))
            self._timer.schedule()

    def _tick(self) -> None:
        """A frame, unless the object was deleted (or its creation undone) or the view closed since
        the last one: then the overlay takes itself away (the controller forgets it on its next look)."""
        if self.alive():
            self.frame()
        else:
            self.remove()

    def stop(self) -> None:
        self._camera_sensor.detach()
        if self._timer is not None:
            self._timer.unschedule()
            self._timer = None
        self._root.removeAllChildren()
        self.cursor_shown = False
        self.surface_drawn = False
        if self.hud is not None:
            self.hud.clear()

    def refusal(self, text: str) -> None:
        """Shows what a command refused in the HUD's status line for NOTICE_SHOWN_S (a session's
        designer has the device in hand, not the report view in sight)."""
        self.notice(f"refused: {text}")

    def notice(self, text: str) -> None:
        """Shows ``text`` (what a command did that the designer did not see happen: a net refined)
        in the HUD's status line for NOTICE_SHOWN_S, from its next frame."""
        self._notice = (text, time.monotonic())  # (a session draws each frame; else the caller refreshes)

    def _edge_said(self, name: str, found: list[Any]) -> str:
        """How the HUD names the base's edge ``name`` (edge_pick.edge_said): found on the solid once
        per set of edges it has (a session moves the seams; the names stay)."""
        from ..app.edge_pick import edge_said, own_edge_names
        from ..app.sculpted_solid import solid_of
        solid = solid_of(self.obj)
        if solid is None:
            return name
        key = (solid.Name, len(solid.Shape.Edges), tuple(sorted(p.edge for p in found)))
        if self._own_edges is None or self._own_edges[0] != key:
            self._own_edges = (key, own_edge_names(solid, found))
        return edge_said(name, solid, self._own_edges[1])

    def alive(self) -> bool:
        """False once its view is closed or its object deleted."""
        try:
            self.view.getSize()
        except Exception:  # noqa: BLE001 - a closed view raises on any access
            return False
        return self._object_alive()

    def _object_alive(self) -> bool:
        try:
            return self.obj.Document.getObject(self.obj.Name) is self.obj
        except Exception:  # noqa: BLE001 - a deleted object raises on any access
            return False

    def hide_scan(self) -> None:
        """Hides the sculpt's target (the deviation display draws its points in colour: the plain
        mesh would hide them)."""
        scan = getattr(self.obj, "Target", None)
        vobj = getattr(scan, "ViewObject", None)
        if vobj is not None:
            vobj.Visibility = False
            self.hidden_scan = scan

    def show_scan(self) -> None:
        """Shows again the mesh hide_scan hid, if it is still there."""
        scan, self.hidden_scan = self.hidden_scan, None
        try:
            if scan is not None and scan.Document.getObject(scan.Name) == scan:
                scan.ViewObject.Visibility = True
        except Exception:  # noqa: BLE001 - deleted, or its document closed: nothing to show
            pass

    def remove(self) -> None:
        if self.hidden_scan is not None and not self._object_alive():
            self.show_scan()  # (its sculpt deleted: the scan stayed hidden, no display to show it)
        self.stop()
        if self.hud is not None:
            self.hud.remove()
            self.hud = None
        try:
            graph = self.view.getSceneGraph()
        except Exception:  # noqa: BLE001 - the view is closed: its scene went with it
            return
        if graph.findChild(self._root) >= 0:
            graph.removeChild(self._root)

    def refresh(self) -> None:
        """Starts or stops the timer to match what is on, and draws once; keeps what it shows with
        the document."""
        if self._object_alive():
            kept_displays.keep(self.obj, kept_displays.settings_of(self), self._defaults)
        if self.needed:
            self.start()
            self.frame()
        elif self.shown:
            self.stop()
            self.frame()
        else:
            self.stop()

    def drop_cursor(self) -> None:
        """The session stopped: no device cursor, no contact (the mouse's own shows when it moves)."""
        self.cursor = None
        self.contact = None

    # --- state ------------------------------------------------------------------------------------
    def snapshot(self) -> core.DynamicSurface:
        """The newest state to draw (see LiveSurface.snapshot)."""
        return self.obj.Proxy.live.snapshot()

    def _update_cursor(self) -> None:
        """A session's device cursor, else the mouse's, if the controller gives it this overlay."""
        session = self._session()
        if session is None:
            self.cursor = self.mouse(self)
        else:
            st = session.status()
            if "cursor" in st:
                self.cursor = (np.asarray(st["cursor"], float), np.asarray(st["orientation"], float), bool(st["grab"]))
                self.contact = None if st.get("contact") is None else np.asarray(st["contact"], float)

    # --- one frame --------------------------------------------------------------------------------
    def frame(self) -> None:
        """Rebuilds the whole overlay from the current state."""
        from pivy import coin
        t0 = time.perf_counter()
        seen = self.visible()
        if self.hidden_scan is not None and (self.display != "deviation" or not seen
                                             or getattr(self.obj, "Target", None) != self.hidden_scan):
            self.show_scan()  # (the target cleared or changed, its Set target undone, the sculpt hidden)
        if self.display == "deviation" and seen and self.hidden_scan is None and getattr(self.obj, "Target", None) is not None:
            self.hide_scan()  # (a new target's mesh, or one set again by Redo)
        if not self.shown:
            self.stop()
            return
        self._update_cursor()
        s = self.snapshot()
        mesh = np.array(s.mesh)
        offset = self.offset()
        if offset:
            mesh = mesh + offset * analysis.vertex_normals(mesh)
        scene = coin.SoSeparator()
        unpickable = coin.SoPickStyle()  # the mouse finds the face under the displays and the jacks
        unpickable.style = coin.SoPickStyle.UNPICKABLE
        scene.addChild(unpickable)
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        legend = None
        display = self.display if seen else "shading"
        glsl = stripe_shading.shaders_work() if self.per_pixel else False
        if display == "zebra" and glsl is None:
            scene.addChild(stripe_shading.probe())  # (per vertex this frame; the answer comes with its render)
        self._lift_by = 2.0 * (face_deflection(self.obj) + mesh_sag(mesh)) + 1e-4 * _size(mesh)
        self._place_lift()
        scene.addChild(self._lift)  # the displays and the jacks lie on the surface: in front of the face
        if display == "zebra" and glsl:
            scene.addChild(self._stripes(s, offset))
            legend = (self.display, (0.0, 1.0))
        elif display != "shading":
            colours, rng = self._colours(s, mesh)
            scene.addChild(shapes.coloured_mesh(mesh, colours, self._cells(mesh.shape[:2], s.mesh_parameters_u,
                                                                           s.mesh_parameters_v),
                                                lit=display in MAPS))  # (a material map says nothing of the shape)
            legend = (self.display, rng)
            if display == "deviation" and self._target() is not None:
                scene.addChild(self._scan_points(s, rng))
        self.neighbours_drawn = 0
        if display != "shading" and display not in MAPS and display != "deviation":
            for node in self._neighbours(display, bool(glsl) and display == "zebra", legend[1] if legend else None):
                scene.addChild(node)
                self.neighbours_drawn += 1
        decor = coin.SoSeparator()
        decor.addChild(light)
        if self.combs and seen:
            teeth, envelope, _ = analysis.curvature_combs(mesh, s.curvature_grid().reshape(mesh.shape[:2] + (6,)),
                                                          every=self.comb_every, gain=self.comb_gain)
            decor.addChild(shapes.lines(teeth, (1.0, 0.0, 1.0), 1.0))
            decor.addChild(shapes.lines(envelope, (1.0, 0.0, 1.0), 2.0))
        if self.continuity and seen:
            decor.addChild(self._continuity_combs(s))
        if seen:
            decor.addChild(self._jacks(s, mesh))
            decor.addChild(self._curves(s))
        self.surface_drawn = seen and (display != "shading" or (self.combs or self.continuity or bool(s.constraints)
                                                                 or bool(self._curves_text())))
        self.cursor_shown = self.cursor is not None and self.needed  # (the jacks alone are not redrawn as the mouse moves)
        if self.cursor_shown:  # (unpickable too: the mouse put the cursor on its own ball, not the surface)
            decor.addChild(self._cursor(s, mesh))
        scene.addChild(decor)
        self._root.removeAllChildren()
        self._root.addChild(scene)
        if self.hud is None:
            self.hud = Hud(self.view)
        if not self.needed or not self.speaks(self):  # the jacks alone, or another sculpt's HUD is shown here
            self.hud.clear()
            self.frames += 1
            return
        sliders = self.panel.values(self.obj) if self.panel_visible else []
        self.status_text = self._status(s)
        self.legend = legend if legend is None else (legend[0], (float(legend[1][0]), float(legend[1][1])))
        self.hud.update(legend, sliders, self.status_text, zebra_bands=int(self.stripes), tolerance=self.tolerance())
        self.frames += 1
        self.frame_ms = (time.perf_counter() - t0) * 1e3

    # --- the slider panel, operated with the mouse in view pixels -------------------------------------
    def tracks(self) -> dict[str, tuple[float, float, float, float]]:
        """Each shown slider's track in view pixels (where the HUD drew it last): name -> box."""
        if not self.panel_visible or self.hud is None:
            return {}
        boxes = self.hud.boxes()
        return {name: boxes[f"track{k + 1}"] for k, (name, _, _, _) in enumerate(sliders(self.obj))
                if f"track{k + 1}" in boxes}

    def panel_covers(self, x: float, y: float) -> bool:
        """True if view pixel (x, y) lies on the shown slider panel, its tracks or the backing
        between them (a press there is the panel's, never a stroke or a dab)."""
        if not self.panel_visible or self.hud is None:
            return False
        box = self.hud.boxes().get("back_sliders")
        return box is not None and box[0] <= x <= box[2] and box[1] <= y <= box[3]

    def panel_press(self, x: float, y: float) -> bool:
        """Button down at view pixel (x, y): True if it took a slider (shown at once)."""
        if not self.panel.press(x, y, self.tracks(), self.obj):
            return False
        self.frame()
        return True

    def panel_drag(self, x: float, fine: bool = False) -> bool:
        """The mouse moved to view pixel column x (``fine``: Shift held): True if a slider is held
        (it followed)."""
        if self.panel.held is None:
            return False
        self.panel.drag(x, fine)
        self.frame()
        return True

    def panel_release(self) -> bool:
        """Button up: True if a slider was held (its value is now one undo step)."""
        if not self.panel.release(self.obj):
            return False
        self.frame()
        return True

    def _place_lift(self) -> None:
        """Moves everything drawn toward the camera by more than the displays' meshes and the face's
        own tessellation can be apart (each within its chordal deviation of the exact surface), so
        neither the face's shading nor its selection highlight shows through a display, nor the
        face through a jack, at any zoom. Along the view direction the picture does not move
        (orthographic; by a negligible scale in perspective), only the depth: placed again each
        time the camera moves (a sensor on it), also between frames."""
        camera = self.view.getCameraNode()
        if self._camera_sensor.getAttachedNode() is not camera:
            self._camera_sensor.detach()
            self._camera_sensor.attach(camera)
        d = np.array(tuple(self.view.getViewDirection()), float)
        d /= np.linalg.norm(d) or 1.0
        self._lift.translation.setValue(*(-self._lift_by * d))

    def _stripes(self, s: core.DynamicSurface, offset: float) -> Any:
        """Zebra stripes per pixel on the exact surface (sampled again only when the poles moved)."""
        size = stripe_shading.TEXTURE // (2 if self._session() is not None else 1)
        key = np.asarray(s.poles).tobytes()
        if self._sampled is None or self._sampled[0] != key or self._sampled[3] != size:
            points, texture = stripe_shading.sample(s.surface, size)
            self._sampled = (key, points, texture, size)
        _, points, texture, size = self._sampled
        if offset:  # (the frame's: see offset())
            points = points + offset * analysis.vertex_normals(points)
        g, h = points.shape[:2]
        (u0, u1), (v0, v1) = s.surface.domain
        cells = self._cells((g, h), np.linspace(u0, u1, g), np.linspace(v0, v1, h))
        return stripe_shading.stripe_mesh(points, texture, size, self.stripe_mode, self.stripes,
                                          self.stripe_direction, shapes.quad_indices(g, h) if cells is None else cells,
                                          self.stripe_angle)

    def _neighbours(self, display: str, per_pixel: bool, rng: tuple[float, float] | None) -> list[Any]:
        """The same display on the faces next to the sculpted ones (a face of a SculptedSolid), so a
        seam with a face that is not sculpted can be judged across it; the curvature maps on the
        sculpt's own colour scale."""
        from ..app.neighbour_faces import neighbour_grids
        from ..app.sculpted_solid import solid_of
        solid = solid_of(self.obj)
        if solid is None:
            return []
        try:
            grids = neighbour_grids(solid)
        except (RuntimeError, ValueError):
            return []
        nodes = []
        for grid in grids:
            quads = shapes.quad_indices(*grid.inside.shape) if grid.inside.all() else shapes.masked_quad_indices(grid.inside)
            if per_pixel:
                nodes.append(stripe_shading.stripe_mesh(grid.points, stripe_shading.normal_texture(grid.normals),
                                                        grid.normals.shape[0], self.stripe_mode, self.stripes,
                                                        self.stripe_direction, quads, self.stripe_angle))
                continue
            if display == "zebra":
                d = self.view.getViewDirection()
                colours, _ = analysis.zebra_colours(grid.points, np.array([d[0], d[1], d[2]]), self.stripes)
            elif display == "curvature":
                top = rng[1] if rng and rng[1] > 0 else 1.0
                colours = np.zeros(grid.points.shape)
                colours[..., 1] = np.clip(np.abs(grid.curvature[..., 0]) / top, 0, 1)
                colours[..., 2] = np.clip(np.abs(grid.curvature[..., 1]) / top, 0, 1)
            else:
                lo, hi = rng if rng else analysis.symmetric_range(grid.curvature[..., 4 if display == "mean" else 5])
                colours, _ = analysis.pseudo_colour(grid.curvature[..., 4 if display == "mean" else 5], lo, hi)
            nodes.append(shapes.coloured_mesh(grid.points, colours, quads))
        return nodes

    def _cells(self, shape: tuple[int, int], us: Any, vs: Any) -> list[int] | None:
        """The cells of a grid over the domain that lie on the face when the sculpt is a face of a
        solid with trims (a hole stays open in the displays); None: all (found once per grid size)."""
        from ..app.sculpted_solid import trim_mask
        key = (int(shape[0]), int(shape[1]))
        if key not in self._trims:
            inside = trim_mask(self.obj, us, vs)
            self._trims[key] = None if inside is None or inside.all() else shapes.masked_quad_indices(inside)
        return self._trims[key]

    def _status(self, s: core.DynamicSurface) -> str:
        """The tool, the material and what goes on, for the HUD's status line."""
        parts = [f"tool: {s.tool.name}", "clay" if s.plasticity[0] else "elastic"]
        session = self._session()
        if session is not None:
            from ..app.sculpted_solid import solid_of
            # (a SculptedSolid's face sculpt is hidden: the designer knows the solid, as the tree shows it)
            shown = solid_of(self.obj) or self.obj
            parts.append(f"sculpting {shown.Label} with the {session.device_name or 'mouse'}")
            if session.device_name not in ("", "mouse") and session.rate_and_priority:
                parts.append(session.rate_and_priority)
            if not s.held_poles and not any(c["kind"] == "point" for c in s.constraints):
                # (a free sheet pulled at a corner swung up whole, flat: it looked broken on a first try)
                parts.append("edges free: a pull lifts it whole, P pins a point")
            lifted = self.lifting(self)
            if lifted is not None:
                parts.append(f"lifting toward you: {lifted:.1f} mm (seen from above: drag up lifts, sideways moves)")
            elif session.last_stroke is not None:
                parts.append(stroke_text(session.last_stroke))
        if self.display == "zebra":
            turn = (f"stripes at {self.stripe_angle:g} deg" if self.stripe_mode == "reflection"
                    else "to ({:.2g}, {:.2g}, {:.2g})".format(*self.stripe_direction))
            parts.append(f"zebra: {self.stripe_mode}, {self.stripes:g} stripes, {turn}")
        if self.display == "deviation":
            # (in a session the surface moves between commits: the line the points shown give)
            parts.append(self._live_deviation if session is not None and self._live_deviation else
                         self._deviation_text())
        pull = s.pull
        if pull["target"] and (session is not None or self.display == "deviation"):
            # (on by default: a session drew a bump sculpted before toward the scan, unannounced)
            parts.append(f"pull toward the scan: {'on' if pull['enabled'] else 'off'}")
        if self.combs:
            parts.append(f"combs: every {self.comb_every}, x{self.comb_gain:g}")
        if self.continuity:
            parts.append(continuity_text(self.continuity_worst))
        if self.mode:
            parts.append(self.mode)
        if self._notice is not None:
            if time.monotonic() - self._notice[1] <= NOTICE_SHOWN_S:
                parts.append(self._notice[0])
            else:
                self._notice = None
        return "  |  ".join(parts)

    def _deviation_text(self) -> str:
        """The stored deviation report in a line (as of the last recompute: after a stroke)."""
        import json
        text = getattr(self.obj, "Deviation", "")
        if not text:
            return "deviation: no scan target (select a mesh and the sculpt: Set scan target)"
        report = json.loads(text)
        if "error" in report:
            return f"deviation: {report['error']}"
        return (f"deviation: {report['within_pct']:.1f} % within \u00b1{report['tolerance_mm']:g} mm, p95 "
                f"{report['p95_mm']:.3g} mm, max {report['max_mm']:.3g} mm")

    def _target(self) -> Any:
        """The sculpt's scan target (points and k-d tree), or None (none set, or it cannot be read)."""
        from ..app.scan_target import target_of
        try:
            return target_of(self.obj)
        except ValueError:
            return None

    def tolerance(self) -> float:
        """The deviation display's tolerance band (mm): the sculpt's TargetTolerance."""
        return float(getattr(self.obj, "TargetTolerance", 0.1) or 0.1)

    def _deviation(self, s: core.DynamicSurface, mesh: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
        """The scan's signed distance at each mesh point, coloured; grey everywhere without a scan."""
        from ..app.scan_deviation import mesh_deviation
        target = self._target()
        tol = self.tolerance()
        if target is None:
            return analysis.deviation_colours(np.full(mesh.shape[:2], np.nan), tol, (-2 * tol, 2 * tol))
        # a point past the scan's edge by a spacing and a half shows no scan (grey), not the edge's colour
        signed = mesh_deviation(mesh, analysis.vertex_normals(mesh), target.tree, target.points,
                                int(getattr(self.obj, "TargetSide", 0)), 1.5 * target.spacing + tol)
        # (the legend spans the largest deviation shown: the surface's and the scan points')
        _, at_points = self._scan_measured(s)
        return analysis.deviation_colours(signed, tol, analysis.deviation_range(np.concatenate(
            [signed.ravel(), at_points]), tol))

    def _scan_measured(self, s: core.DynamicSurface) -> tuple[Any, np.ndarray]:
        """The scan's points (up to SCAN_POINTS_SHOWN) and their signed deviations from the surface
        (NaN: past its edge); measured again when the poles moved or the tolerance changed, at most
        every SCAN_REMEASURE_S during a session."""
        from ..app.scan_deviation import signed_distances, thinned
        key = (np.asarray(s.poles).tobytes(), self.tolerance())  # (a new tolerance colours them anew)
        now = time.monotonic()
        if self._scan is not None and (self._scan[0] == key or now - self._scan[1] < SCAN_REMEASURE_S):
            return self._scan[2], self._scan[3]
        target = self._target()
        points = thinned(target.points, SCAN_POINTS_SHOWN)
        distances, over = signed_distances(s.surface, points, float(int(getattr(self.obj, "TargetSide", 0)) or 1))
        shown = np.where(over, distances, np.nan)
        self._scan = (key, now, points, shown)
        tol = self.tolerance()
        d = np.abs(distances[over])
        self._live_deviation = (f"deviation: {100.0 * float(np.mean(d <= tol)):.1f} % within \u00b1{tol:g} mm, p95 "
                                f"{float(np.percentile(d, 95)):.3g} mm, max {float(d.max()):.3g} mm (live, "
                                f"{d.size} points)") if d.size else None
        return points, shown

    def _scan_points(self, s: core.DynamicSurface, rng: tuple[float, float]) -> Any:
        """The scan's points coloured by their signed deviation from the surface on the legend's scale."""
        points, shown = self._scan_measured(s)
        colours, _ = analysis.deviation_colours(shown, self.tolerance(), rng)
        return shapes.coloured_points(points, colours, 3.0)

    def _colours(self, s: core.DynamicSurface, mesh: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
        g, h = mesh.shape[:2]
        if self.display == "deviation":
            return self._deviation(s, mesh)
        if self.display in MAPS:
            return analysis.map_colours(self.obj.Proxy.live.map_values(self.display), (g, h))
        if self.display == "zebra":
            d = self.view.getViewDirection()
            return analysis.zebra_colours(mesh, np.array([d[0], d[1], d[2]]), self.stripes)
        curv = s.curvature_grid().reshape(g, h, 6)
        if self.display == "curvature":
            return analysis.curvature_channels(curv)
        if self.display == "mean":
            return analysis.mean_curvature_colours(curv)
        return analysis.gaussian_curvature_colours(curv)

    def _jacks(self, s: core.DynamicSurface, mesh: np.ndarray) -> Any:
        from pivy import coin
        sep = coin.SoSeparator()
        flat = mesh.reshape(-1, 3)
        size = float(np.linalg.norm(flat.max(0) - flat.min(0))) or 1.0
        r = 0.03 * size
        g, h = mesh.shape[:2]
        for c in s.constraints:
            p = flat[c["index"]]
            kind = c["kind"]
            colour = JACK_COLOURS[kind]
            if kind == "point":
                segs = [[p - [r, r, 0], p + [r, r, 0]], [p - [r, -r, 0], p + [r, -r, 0]], [p - [0, 0, r], p + [0, 0, r]]]
                sep.addChild(shapes.lines(np.array(segs), colour, 3.0))
            elif kind in ("normal", "tangent"):
                n = np.asarray(c["target"], float)
                sep.addChild(shapes.lines(np.array([[p, p + 3 * r * n]]), colour, 3.0))
            else:
                i, j = divmod(c["index"], h)
                sep.addChild(shapes.circle(p, shapes.frame(*shapes.tangents(mesh, i, j))[:, 2], r, colour))
        return sep

    def _continuity_combs(self, s: core.DynamicSurface) -> Any:
        """Curvature combs across every edge, seam and curve of the sculpt, on both sides, coloured
        by what holds there; measured again when the poles moved, but during a session not more
        often than every twice its cost (it rebuilds the faces' surfaces: 5-20 ms)."""
        from pivy import coin

        from ..app import sculpt_properties, sculpt_state
        key = np.asarray(s.poles).tobytes()
        now = time.perf_counter()
        if self._continuity is None or (self._continuity[0] != key and
                                        now - self._continuity[3] >= 2.0 * self._continuity[4]):
            state = sculpt_properties.read_state(self.obj)
            frame = sculpt_state.SculptState({**state.arrays, "Poles": np.asarray(s.poles, float).ravel()},
                                             state.settings)
            try:
                found = continuity_check.profiles(self.obj, frame)
            except (RuntimeError, ValueError):
                found = []
            levels = [continuity_check.sample_levels(p) for p in found]  # (measured once, drawn each frame)
            self._continuity = (key, found, levels, now, time.perf_counter() - now)
            shares = continuity_check.shares(found, continuity_check.holds(self.obj))
            for r in shares:  # (with the solid's own names, which the view picks, beside the base's)
                r["said"] = self._edge_said(r["edge"], found)
            self.continuity_worst = {**continuity_check.worst(found), "profiles": len(found),
                                     "levels": {p.edge: continuity_check.level(p) for p in found}, "shares": shares}
        found, levels_of = self._continuity[1], self._continuity[2]
        sep = coin.SoSeparator()
        kappa = max((float(np.nanmax(np.abs(k))) for p in found for _, k in p.sides if np.isfinite(k).any()),
                    default=0.0)
        flat = np.asarray(s.mesh).reshape(-1, 3)
        size = float(np.linalg.norm(flat.max(0) - flat.min(0))) or 1.0
        scale = 0.1 * size * self.comb_gain / kappa if kappa > 0 else 0.0
        for p, levels in zip(found, levels_of):
            # coloured along its length by what holds at each point (a seam G2 in its middle and G1
            # toward its ends shows both), not by its worst point alone
            for k, (normals, curvature) in enumerate(p.sides):
                ok = np.isfinite(curvature) & np.all(np.isfinite(normals), axis=1)
                base, at = p.points[ok], levels[ok]
                tips = base - normals[ok] * (curvature[ok] * scale)[:, None]
                teeth = np.stack([base, tips], axis=1)
                outline = np.stack([tips[:-1], tips[1:]], axis=1)
                every = np.arange(len(teeth)) % (2 if k else 1) == 0  # (the far side's: every other tooth)
                for index, name in enumerate(continuity_check.LEVELS):
                    segments = np.concatenate([teeth[every & (at == index)], outline[at[:-1] == index]])
                    if len(segments):
                        sep.addChild(shapes.lines(segments, CONTINUITY_COLOURS[name], 1.5 if k else 2.0))
        return sep

    def _curves_text(self) -> str:
        return getattr(self.obj, curve_constraint.PROPERTY, "")

    def _curves(self, s: core.DynamicSurface) -> Any:
        """The curves the surface follows, where they run on it now (their rows are kept while the
        constraints do not change: each frame only applies them to the newest poles)."""
        from pivy import coin
        sep = coin.SoSeparator()
        text = self._curves_text()
        # (keyed by the net too: Follow curve refines it in the same step as it writes the curve, and
        # rows of the coarser net applied to the finer one's poles drew a squiggle off the curve)
        key = (text, tuple(s.surface.controls), tuple(s.surface.knots_u), tuple(s.surface.knots_v))
        if self._curve_rows[0] != key:
            self._curve_rows = (key, [(r.continuity, curve_constraint.rows(s.surface, r.uv))
                                      for r in curve_constraint.records_from_json(text)])
        poles = np.asarray(s.poles, float).reshape(-1, 3)
        for kind, rows in self._curve_rows[1]:
            points = rows.apply(rows.s, poles)
            sep.addChild(shapes.lines(np.stack([points[:-1], points[1:]], axis=1), CURVE_COLOURS[kind], 4.0))
        return sep

    def _cursor(self, s: core.DynamicSurface, mesh: np.ndarray) -> Any:
        from pivy import coin
        pos, quat, grab = self.cursor
        flat = mesh.reshape(-1, 3)
        size = float(np.linalg.norm(flat.max(0) - flat.min(0))) or 1.0
        sep = coin.SoSeparator()
        sep.addChild(shapes.sphere(pos, 0.02 * size, (1.0, 0.85, 0.0) if grab else (0.9, 0.9, 0.9)))
        sep.addChild(shapes.axes(pos, shapes.rotation(quat), 0.06 * size))
        nearest = int(s.nearest_mesh_index(list(pos)))
        i, j = divmod(nearest, mesh.shape[1])
        frame = shapes.frame(*shapes.tangents(mesh, i, j))
        point = flat[nearest]
        sep.addChild(shapes.sphere(point, 0.012 * size, (0.2, 1.0, 0.2)))
        sep.addChild(shapes.axes(point, frame, 0.05 * size))
        if self.contact is not None and grab:
            sep.addChild(shapes.lines(np.array([[pos, self.contact]]), (1.0, 0.85, 0.0), 2.0))
        return sep


#: A stroke that moved the surface less than this share of the cursor's pull barely followed it.
BARELY_FOLLOWED = 0.05
#: A mean stiffness above this (ten times a new sculpt's 100) is what holds a stroke back.
STIFF = 1000.0


def stroke_text(last: dict[str, float]) -> str:
    """The HUD's line for a session's last stroke (Session.last_stroke): how far it moved the
    surface, and, where that was a small part of the pull, why, as things stood at the stroke (a
    stroke on a very stiff sculpt changed nothing one could see, and nothing said so: the
    stiffness slider spans five decades; held edges pin rows of poles)."""
    moved, pulled, stiffness = last["moved_mm"], last["pulled_mm"], last["stiffness"]
    text = f"last stroke moved it {moved:.2g} mm"
    if last.get("tool") == "flatten":  # (it presses toward a plane, pulls nothing: a flat place has nothing to flatten)
        return text + (": nothing stood above or below its plane there" if moved < 1e-3 else "")
    if pulled >= 1.0 and moved < BARELY_FOLLOWED * pulled:
        text += f" of a {pulled:.2g} mm pull"
        if stiffness > STIFF:
            text += f": stiffness {rounded(stiffness, 2):g} holds it, lower it in the slider panel"
        elif last["held"] or last.get("curves"):
            causes = [c for c, on in (("the curves it follows", last.get("curves")), ("held poles", last["held"])) if on]
            remedies = [r for r, on in (("Follow curve: off", last.get("curves")), ("Hold edges, P", last["held"])) if on]
            text += f": {' and '.join(causes)} pin it there ({', '.join(remedies)}), or it is heavy or damped"
        else:
            text += ": the material is heavy or damped (slider panel)"
    return text


#: Edges whose share of their hold the HUD's continuity line lists (the least met first).
SHARES_SHOWN = 4


def continuity_text(worst: dict[str, Any]) -> str:
    """The HUD's line for the continuity check: the worst g0, g1 and g2 over the smooth edges."""
    if not worst or worst.get("g0_mm") is None:
        return "continuity: held edges and curves only (they hold exactly)" if worst.get("profiles") else \
            "continuity: no edge held, no curve followed"

    def show(value: float | None, unit: str, digits: str) -> str:
        return "-" if value is None else f"{value:{digits}}{unit}"
    text = (f"continuity: worst g0 {show(worst['g0_mm'], ' mm', '.1e')}, g1 {show(worst['g1_deg'], ' deg', '.3g')}, "
            f"g2 jump {show(worst['g2_pct'], ' %', '.3g')} ({worst['smooth']} smooth of {worst['edges']} edges)")
    held = worst.get("shares") or []
    if held:  # (the least first: where a hold is met over part of an edge only, it says how much)
        # ("of their length": beside the worst g2 jump of 100 % where a seam fades at its end, a bare
        # "G2 over 94 %" read as a contradiction)
        listed = [f"{r.get('said', r['edge'])} {r['kind']} over {100 * r['share']:.0f} %" for r in held[:SHARES_SHOWN]]
        more = len(held) - SHARES_SHOWN
        text += "; of their length: " + ", ".join(listed) + (f" and {more} more" if more > 0 else "")
    return text


def _size(mesh: np.ndarray) -> float:
    flat = mesh.reshape(-1, 3)
    return float(np.linalg.norm(flat.max(0) - flat.min(0))) or 1.0


def mesh_sag(mesh: np.ndarray) -> float:
    """How far a grid of surface points' flat cells can be from the surface (mm): a chord's sag is
    an eighth of the second difference along it; both directions and the twist, with a margin."""
    if min(mesh.shape[:2]) < 3:
        return 0.0
    du = np.linalg.norm(mesh[2:] - 2 * mesh[1:-1] + mesh[:-2], axis=-1).max()
    dv = np.linalg.norm(mesh[:, 2:] - 2 * mesh[:, 1:-1] + mesh[:, :-2], axis=-1).max()
    twist = np.linalg.norm(mesh[1:, 1:] - mesh[1:, :-1] - mesh[:-1, 1:] + mesh[:-1, :-1], axis=-1).max()
    return float(du + dv + twist) / 4.0


def face_deflection(obj: Any) -> float:
    """The largest distance FreeCAD's tessellation of ``obj``'s face may have from it (mm): Part's
    view provider meshes with a deflection of Deviation percent of the bounding box's mean side
    (the sum of its sides / 300 * Deviation)."""
    vobj = getattr(obj, "ViewObject", None)
    deviation = float(getattr(vobj, "Deviation", 0.5)) if vobj is not None else 0.5
    box = obj.Shape.BoundBox
    return (box.XLength + box.YLength + box.ZLength) / 300.0 * deviation
