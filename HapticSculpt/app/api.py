"""The scripting API of the FreeCAD layer (a contract scripts rely on; see the README).

Every function validates its arguments before it touches the document and raises ``ValueError`` or
``TypeError`` naming the argument, so a bad call leaves the document as it was. FreeCAD is imported
inside the functions: importing :mod:`HapticSculpt` never needs it.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Protocol, Sequence

import numpy as np

from .. import core
from . import curve_api, recorded_state, sculpt_state, stroke_log
from .sculpt_feature import SculptFeature, attach_view_provider, is_sculpt
from .sculpt_properties import face_of, read_state
from .sculpted_solid import is_sculpted_solid, sculpt_of
from .source_surface import source_surface
from .edge_holds import BOUNDARIES, EDGES, boundary_poles, kinds_held
from .undo import transaction


def _int_pair(value: Any, name: str, minimum: int) -> tuple[int, int]:
    try:
        a, b = value
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected a pair of integers, got {value!r}") from None
    for x in (a, b):
        if isinstance(x, bool) or not isinstance(x, (int, np.integer)):
            raise TypeError(f"{name}: expected integers, got {value!r}")
        if x < minimum:
            raise ValueError(f"{name}: each must be >= {minimum}, got {value!r}")
    return int(a), int(b)


def _finite(value: Any, name: str, positive: bool = False, nonnegative: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name}: must be finite, got {x}")
    if positive and not x > 0:
        raise ValueError(f"{name}: must be > 0, got {x}")
    if nonnegative and not x >= 0:
        raise ValueError(f"{name}: must be >= 0, got {x}")
    return x


def _document(doc: Any) -> Any:
    import FreeCAD
    if doc is None:
        doc = FreeCAD.ActiveDocument or FreeCAD.newDocument()
    if not hasattr(doc, "addObject") or not hasattr(doc, "openTransaction"):
        raise TypeError(f"doc: expected a FreeCAD document, got {type(doc).__name__}")
    return doc


def _sculpt(obj: Any, name: str = "obj", solids: bool = False) -> Any:
    """The Sculpt ``obj`` is, or (``solids``) the one a SculptedSolid sculpts its faces with."""
    if solids and is_sculpted_solid(obj):
        return sculpt_of(obj)
    if not is_sculpt(obj):
        what = "Sculpt or SculptedSolid" if solids else "Sculpt"
        raise TypeError(f"{name}: expected a HapticSculpt {what} object, got {getattr(obj, 'TypeId', type(obj).__name__)}")
    return obj


def make_sculpt(doc: Any = None, source: Any = None, controls: tuple[int, int] = (8, 8),
                degree: tuple[int, int] = (3, 3), mesh: tuple[int, int] = (40, 40),
                size: tuple[float, float] = (100.0, 100.0), name: str = "Sculpt", material: str = "elastic",
                edges: Any = "free", centre: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Any:
    """A new Sculpt object in ``doc`` (the active or a new document when None).

    ``source``: None (a flat ``size`` patch in XY, centred at ``centre``), a ``Part.Face``, a
    ``Part.BSplineSurface`` or ``(document_object, "FaceN")``. Faces with an exact B-spline form are
    converted exactly and refined exactly to at least ``controls`` poles of at least ``degree``;
    others are fitted at ``controls``/``degree``. The conversion error (mm) is stored in
    ``obj.ConversionError``. ``mesh`` is the g x h mass-point sampling (at least the control count).
    ``material``: "elastic" (what a stroke pulls springs back unless held by constraints: the
    scripting default) or "clay" (plastic: what a stroke pulls stays, the GUI's default); see
    :func:`set_material`. ``edges``: "free" (a free sheet), "held" (a clamped sheet: every edge
    and its tangent plane held, as :func:`hold_boundary` "G1"), or what :func:`hold_boundary` takes.
    Undo is switched on for the document if it was off, so each stroke can be undone.
    """
    controls, degree, mesh = _checked_resolution(controls, degree, mesh)
    edges = _edges(edges)
    try:  # validated (names, rows left free) before the document changes
        boundary_poles(controls, edges)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"edges: 'free', 'held' or as hold_boundary takes it ({exc})") from None
    doc = _document(doc)
    try:
        sx, sy = size
    except (TypeError, ValueError):
        raise TypeError(f"size: expected (width, height), got {size!r}") from None
    size = (_finite(sx, "size", positive=True), _finite(sy, "size", positive=True))
    try:
        centre = tuple(_finite(c, "centre") for c in centre)
    except TypeError as exc:
        raise TypeError(f"centre: expected (x, y, z) in mm ({exc})") from None
    if len(centre) != 3:
        raise ValueError(f"centre: expected (x, y, z) in mm, got {len(centre)} numbers")
    if source is not None and any(centre):
        raise ValueError("centre: only for a flat patch (source None): a face stays where it is")
    if not isinstance(name, str) or not name:
        raise TypeError("name: expected a non-empty string")
    _material(material)
    made = source_surface(source, controls, degree, size, doc, centre=centre)
    state = _sculpt_state(made, mesh, material, held=boundary_poles(tuple(made.surface.controls), edges))
    if doc.UndoMode == 0:
        doc.UndoMode = 1
    with transaction(doc, "Create sculpt"):
        return _add_sculpt(doc, name, made, state)


def _checked_resolution(controls: Any, degree: Any, mesh: Any) -> tuple[tuple[int, int], ...]:
    degree = _int_pair(degree, "degree", 1)
    if max(degree) > core.MAX_DEGREE:
        raise ValueError(f"degree: at most {core.MAX_DEGREE}, got {degree}")
    controls = _int_pair(controls, "controls", 2)
    if controls[0] < degree[0] + 1 or controls[1] < degree[1] + 1:
        raise ValueError(f"controls: need at least degree+1 = {(degree[0] + 1, degree[1] + 1)}, got {controls}")
    return controls, degree, _int_pair(mesh, "mesh", 2)


def _sculpt_state(made: Any, mesh: tuple[int, int], material: str, held: Sequence[int] = (),
                  symmetry: dict[str, Any] | None = None, links: Sequence[Any] = (),
                  walls: Sequence[Any] = ()) -> sculpt_state.SculptState:
    """The state of a new sculpt of ``made`` (a SourceSurface) sampled at ``mesh``, poles ``held``
    and ``links`` linked, behind ``walls`` (face_walls), mirror ``symmetry`` (face_net.Mirror.settings()) or none."""
    nu, nv = made.surface.controls
    if mesh[0] < nu or mesh[1] < nv:
        raise ValueError(f"mesh: must be at least the control resolution {(nu, nv)}, got {mesh}")
    surface = core.DynamicSurface(made.surface, mesh)
    _apply_material(surface, material)
    surface.bending_map.set_uniform(FAIR_BENDING)
    sculpt_state.choose_tool(surface, surface.tool.name)  # (its lengths fitted to the sculpt's size)
    if held or links:
        surface.hold_poles(list(held), list(links))
    if walls:
        surface.set_walls(list(walls))
    if symmetry is not None:
        surface.set_symmetry(symmetry["direction"], symmetry["point"], symmetry["normal"])
    return sculpt_state.capture(surface)


def _add_sculpt(doc: Any, name: str, made: Any, state: sculpt_state.SculptState) -> Any:
    """A new Sculpt object with ``state`` (the caller holds the transaction)."""
    obj = doc.addObject("Part::FeaturePython", name)
    SculptFeature(obj, state, made.method, made.error, made.description)
    attach_view_provider(obj)
    obj.Shape = face_of(state)
    obj.purgeTouched()
    return obj


#: The "clay" material: springs stretched past 1 % creep toward their new length at a rate of 5 per
#: second (the demo's plasticity), the release makes the stroke's shape the rest shape (the core),
#: and ten times the default damping, so a released patch stops
#: where it was left instead of flying on (measured: a free patch pulled to 28 mm ends at 27.0 mm
#: 6 s later with damping 10, at 76 mm with the default 1).
CLAY = (True, 0.01, 5.0)
CLAY_DAMPING = 10.0
ELASTIC_DAMPING = 1.0  # the core's default
#: The bending (thin-plate) weight, a ratio to the stiffness (docs/solver.md), at which a rope
#: stroke leaves a fair bump, no tents or creases (tests/test_fairness.py): every new sculpt's
#: bending map (make_sculpt, sculpt_solid, the GUI's New patch), both materials. A map like the
#: others: ``set_uniform(obj, "bending", 0)`` is springs alone (sculpts made before it existed).
FAIR_BENDING = 10.0
MATERIALS = ("elastic", "clay")


def _material(material: Any) -> str:
    if material not in MATERIALS:
        raise ValueError(f"material: one of {', '.join(MATERIALS)}, got {material!r}")
    return material


def _apply_material(surface: core.DynamicSurface, material: str) -> None:
    if material == "clay":
        surface.set_plasticity(*CLAY)
        surface.damping_map.set_uniform(CLAY_DAMPING)
    else:
        surface.set_plasticity(False, *surface.plasticity[1:])
        surface.damping_map.set_uniform(ELASTIC_DAMPING)


def set_material(obj: Any, material: str) -> None:
    """Makes the sculpt "elastic" (springs back to its rest shape; damping 1) or "clay" (plastic
    and damped: what a stroke pulls stays where it is left; damping 10). Sets the damping map
    uniformly. One undo step; a running session takes it at once."""
    obj = _sculpt(obj, solids=True)
    _material(material)
    obj.Proxy.live.edit(lambda s: _apply_material(s, material), f"Material: {material}")


def material_of(obj: Any) -> str:
    """"clay" if the sculpt is plastic, else "elastic"."""
    return "clay" if _sculpt(obj, solids=True).Proxy.live.snapshot().plasticity[0] else "elastic"


def set_regional(obj: Any, enabled: bool = True, wake: float | None = None, margin: int | None = None) -> None:
    """Regional steps (docs/solver.md): a stroke steps only the region of poles it moves, plus
    `margin` quiet poles (1..1000, default 4), the rest held at rest until the motion reaches it;
    a pole counts as moving above `wake` (0..1, default 0.01) of the fastest one's speed. Faster on
    large nets where a stroke stays local, at an error docs/benchmarks.md measures; off by default.
    One undo step; a running session takes it at once."""
    obj = _sculpt(obj, solids=True)
    if not isinstance(enabled, bool):
        raise ValueError(f"enabled: True or False, got {enabled!r}")
    if wake is not None and not (isinstance(wake, (int, float)) and 0.0 <= wake <= 1.0):
        raise ValueError(f"wake: a fraction in [0, 1], got {wake!r}")
    if margin is not None and not (isinstance(margin, int) and not isinstance(margin, bool) and 1 <= margin <= 1000):
        raise ValueError(f"margin: a whole number of poles in 1..1000, got {margin!r}")

    def apply(s: core.DynamicSurface) -> None:
        s.regional = enabled
        if wake is not None:
            s.region_wake = float(wake)
        if margin is not None:
            s.region_margin = margin
    obj.Proxy.live.edit(apply, "Regional steps " + ("on" if enabled else "off"))


def keep_shape(obj: Any) -> None:
    """Makes the current shape the rest shape, so an elastic sculpt stays as it is. One undo
    step; a running session takes it at once, also while the tool is held."""
    obj = _sculpt(obj, solids=True)
    obj.Proxy.live.edit(lambda s: None, "Keep shape", keep_shape=True)


def record_state(obj: Any, packed: str, title: str = "Sculpt stroke", strokes: int = 1) -> bool:
    """Gives ``obj`` a recorded state: ``packed`` is what a stroke (or a spray, or a session's end)
    in a threaded session changed, as :func:`HapticSculpt.app.recorded_state.pack` writes it. One
    undo step named ``title``, counting ``strokes``. Returns False and does nothing if ``obj``
    holds that state already. The GUI echoed this call after each stroke before it kept strokes in
    the sculpt (:func:`replay_stroke`); macros recorded then still replay exactly with it."""
    obj = _sculpt(obj, solids=True)
    if not isinstance(title, str) or not title:
        raise TypeError("title: expected a non-empty string")
    if isinstance(strokes, bool) or not isinstance(strokes, int) or strokes < 0:
        raise ValueError(f"strokes: expected a count >= 0, got {strokes!r}")
    before = read_state(obj)
    state = recorded_state.unpack(packed, before)
    if state.settings_json() == before.settings_json() and all(
            np.array_equal(state.arrays[k], before.arrays[k]) for k in state.arrays):
        return False
    sculpt_state.restore(state)  # (raises ValueError naming what does not fit, before anything changes)
    live = obj.Proxy.live
    with transaction(obj.Document, title):
        live.write(state)
        if strokes:
            obj.Strokes = obj.Strokes + strokes
        obj.purgeTouched()
    live.document_changed()
    live.restore_into_session()  # (a running session takes it up, at rest, as after an Undo)
    return True


def replay_stroke(obj: Any, stroke: str) -> bool:
    """Replays stroke ``stroke`` (a name such as "Stroke003") that a threaded session in the GUI made
    on ``obj`` and kept in its ``StrokeLog``: the state it left, bit for bit, as one undo step with
    the stroke's own title. In a new document (a recorded macro replayed) the record is taken from
    the open document it was made in (see :mod:`HapticSculpt.app.stroke_log`). Returns False and
    does nothing if ``obj`` holds that state already: the GUI echoes this call after each stroke."""
    obj = _sculpt(obj, solids=True)
    if not isinstance(stroke, str) or not stroke:
        raise TypeError(f"stroke: expected a stroke's name such as 'Stroke001', got {stroke!r}")
    before = read_state(obj)
    found = stroke_log.find(obj, stroke, before)
    now = stroke_log.fingerprint(before)
    if now == found["after"]:
        return False
    if now != found["before"]:
        raise ValueError(f"stroke: {stroke} starts from another state than {obj.Name} holds "
                         "(replay the strokes before it first, in order)")
    state = recorded_state.unpack(found["change"], before)
    if stroke_log.fingerprint(state) != found["after"]:
        raise ValueError(f"stroke: the record of {stroke} does not give the state it was recorded with")
    sculpt_state.restore(state)  # (raises ValueError naming what does not fit, before anything changes)
    live = obj.Proxy.live
    with transaction(obj.Document, found["title"]):
        live.write(state)
        if found["strokes"]:
            obj.Strokes = obj.Strokes + int(found["strokes"])
        stroke_log.keep(obj, stroke, found)
        obj.purgeTouched()
    live.document_changed()
    live.restore_into_session()  # (a running session takes it up, at rest, as after an Undo)
    return True


def set_tool(obj: Any, tool: str, falloff: str | None = None, **settings: float) -> None:
    """Selects the sculpting tool (one of ``core.TOOLS``: "rope", "magnet", ...); ``falloff`` sets the
    falloff of a tool that has one (``core.TOOL_INFO[tool]["falloff"]``: "constant", "spherical",
    "cylindrical", "conical"); ``settings`` set its parameters by name (``radius=25``; the names,
    defaults and meanings in ``core.TOOL_INFO[tool]["parameters"]``, plus ``max_force`` and
    ``ramp_time``). The current tool keeps the settings not given; another tool starts from its
    defaults, its lengths (``length`` there) shorter on a sculpt smaller than a 100 mm patch
    (``sculpt_state.tool_scale``). One undo step; a running session takes it at once."""
    obj = _sculpt(obj, solids=True)
    if tool not in core.TOOLS:
        raise ValueError(f"tool: unknown tool {tool!r} (one of {', '.join(core.TOOLS)})")
    if falloff is not None and falloff not in core.FALLOFFS:
        raise ValueError(f"falloff: one of {', '.join(core.FALLOFFS)}, got {falloff!r}")
    if falloff is not None and not core.TOOL_INFO[tool]["falloff"]:
        with_falloff = [t for t in core.TOOLS if core.TOOL_INFO[t]["falloff"]]
        raise ValueError(f"falloff: only the {', '.join(with_falloff)} tools have one, not {tool}")
    known = [k for k in core.tool_settings_of(tool) if k != "falloff"]
    unknown = sorted(set(settings) - set(known))
    if unknown:
        raise ValueError(f"{tool}: no setting {', '.join(unknown)} (it has {', '.join(known)})")
    values = {k: _finite(v, k) for k, v in settings.items()}
    probe = core.make_tool(tool)  # (the core checks the ranges before the edit: a refused value changes nothing)
    for key, value in values.items():
        setattr(probe, key, value)

    def change(s: core.DynamicSurface) -> None:
        if s.tool.name != tool:  # (the current tool keeps the settings not given)
            sculpt_state.choose_tool(s, tool)
        if falloff is not None:
            s.tool.falloff = falloff
        for key, value in values.items():
            setattr(s.tool, key, value)
    obj.Proxy.live.edit(change, f"Tool: {tool}")


def set_uniform(obj: Any, map: str, value: float) -> None:
    """Sets material map ``map`` ("mass", "damping", "stiffness", "bending", "pull") to ``value``
    everywhere (the slider panel's edit; damping, bending and pull may be 0: off; bending is a ratio
    to the stiffness, FAIR_BENDING for fair strokes: every new sculpt's; pull scales the pull
    toward the target, 1 by default). One undo step; a running session takes it at once."""
    obj = _sculpt(obj, solids=True)
    sculpt_state.map_property(map)  # validates the name
    off = map in ("damping", "bending", "pull")
    value = _finite(value, "value", nonnegative=off, positive=not off)
    obj.Proxy.live.edit(lambda s: getattr(s, map + "_map").set_uniform(value), f"Set {map}")


def scale_map(obj: Any, map: str, factor: float) -> None:
    """Multiplies material map ``map`` by ``factor`` (> 0) everywhere: what is painted on it keeps
    its pattern (the slider panel's edit of a painted map: :func:`set_uniform` would wipe it). One
    undo step ("Set <map>"); a running session takes it at once."""
    obj = _sculpt(obj, solids=True)
    sculpt_state.map_property(map)  # validates the name
    factor = _finite(factor, "factor", positive=True)

    def change(s: core.DynamicSurface) -> None:
        m = getattr(s, map + "_map")
        m.set_values(np.array(m.values) * factor)

    obj.Proxy.live.edit(change, f"Set {map}")


def fair_weights(mesh: np.ndarray, region: Any = None) -> np.ndarray:
    """Per mesh point weights in [0, 1] for :func:`fair`: all ones without a region, else
    (1 - (r / radius)^2)^2 at distance r < radius from the centre (smooth to zero at the rim)."""
    points = np.asarray(mesh, dtype=float).reshape(-1, 3)
    if region is None:
        return np.ones(len(points))
    try:
        centre, radius = region
        centre = [_finite(x, "region centre") for x in centre]
    except (TypeError, ValueError) as exc:
        raise TypeError(f"region: expected None or (centre (x, y, z), radius), got {region!r}") from exc
    if len(centre) != 3:
        raise TypeError(f"region: expected None or (centre (x, y, z), radius), got {region!r}")
    radius = _finite(radius, "region radius", positive=True)
    r2 = np.sum((points - np.array(centre)) ** 2, axis=1) / radius ** 2
    weights = np.where(r2 < 1, (1 - r2) ** 2, 0.0)
    if not weights.any():
        raise ValueError(f"region: no point of the surface lies within {radius} of {centre}")
    return weights


def fair(obj: Any, region: Any = None, strength: float = 10.0) -> dict[str, float]:
    """Relaxes the curvature variation of the sculpt's shape (Fair): where ``region`` (None: the
    whole surface; else ``(centre, radius)`` in the sculpt's coordinates, weighted smoothly to
    zero at the rim) the poles balance the change of curvature (third differences of the mesh,
    which leave planes, cylinders and spheres alone) against staying put, by ``strength`` (1 weighs
    both alike for the control net's own waves; the default 10 takes a rope stroke's creases out
    and keeps 96 % of its lift, tests/test_fairness.py; larger fairs more). Held and linked poles and the mirror
    symmetry hold exactly (penalty constraints are not part of it: they act again at the next step).
    A clay sculpt keeps the faired shape (it becomes its rest shape); an elastic one springs back
    toward its rest shape when it is next stepped, as after a stroke. One undo step; a running
    session takes the faired shape at once, at rest.

    Returns what it changed: ``moved_mm`` (the largest pole move) and the largest principal
    curvature on the mesh before and after (``peak_curvature_before``/``_after``, 1/mm), also kept
    as ``obj.Proxy.live.last_fair`` (the GUI's report line; a session commits the change later)."""
    obj = _sculpt(obj, solids=True)
    strength = _finite(strength, "strength", nonnegative=True)
    weights = fair_weights(obj.Proxy.live.snapshot().mesh, region)  # validated before the document changes

    def peak(s: core.DynamicSurface) -> float:
        return float(np.nanmax(np.abs(np.asarray(s.curvature_grid())[..., 2:4]), initial=0.0))

    def change(s: core.DynamicSurface) -> dict[str, float]:
        poles, before = np.array(s.poles, float), peak(s)
        s.fair(weights, strength)
        if s.plasticity[0]:
            s.relax()
        return {"moved_mm": float(np.abs(np.asarray(s.poles) - poles).max(initial=0.0)),
                "peak_curvature_before": before, "peak_curvature_after": peak(s)}

    report = obj.Proxy.live.edit(change, "Fair", new_shape=True)
    obj.Proxy.live.last_fair = report
    return report


def set_curvature_target(obj: Any, u: float | None = None, v: float | None = None) -> None:
    """Sets the target curvature along u and/or v (1/mm) of the newest curvature constraint (the
    slider panel's edit). One undo step; a running session takes it at once."""
    obj = _sculpt(obj, solids=True)
    curv = [c for c in obj.Proxy.live.snapshot().constraints if c["kind"] == "curvature"]
    if not curv:
        raise ValueError("obj: has no curvature constraint to set")
    ku, kv = curv[-1]["curvature"]
    ku = ku if u is None else _finite(u, "u")
    kv = kv if v is None else _finite(v, "v")
    obj.Proxy.live.edit(lambda s: s.set_constraint_curvature(curv[-1]["id"], ku, kv), "Set curvature")


def paint_dabs(material: Any, start: tuple[float, float] | None, end: tuple[float, float], radius: float,
               target: float, strength: float) -> None:
    """Airbrush dabs on a core material map from ``start`` to ``end`` (map coordinates), half a
    radius apart, so any drag speed paints a continuous line (only at ``end`` when ``start`` is None)."""
    b = np.asarray(end, float)
    a = b if start is None else np.asarray(start, float)
    n = max(1, int(np.ceil(np.linalg.norm(b - a) / (0.5 * radius))))
    for t in np.linspace(0.0, 1.0, n + 1)[1 if start is not None else n:]:
        u, v = a + t * (b - a)
        material.dab((float(u), float(v)), radius, target, "spherical", strength)


def paint(obj: Any, map: str, path: Sequence[Sequence[float]], radius: float = 0.08, factor: float = 3.0,
          strength: float = 0.25) -> None:
    """An airbrush stroke on material map ``map`` along ``path`` ((u, v) points in map coordinates,
    the unit square): dabs half a radius apart move the map toward ``factor`` times its mean at the
    stroke's start. One undo step ("Paint <map>"); the GUI's airbrush records its strokes so."""
    obj = _sculpt(obj, solids=True)
    obj.Proxy.live.edit(paint_change(map, path, radius, factor, strength), f"Paint {map}")


def paint_change(map: str, path: Sequence[Sequence[float]], radius: float = 0.08, factor: float = 3.0,
                 strength: float = 0.25) -> Callable[[core.DynamicSurface], None]:
    """The change :func:`paint` makes, its arguments checked (``ValueError`` naming the first bad
    one): for a caller that commits it itself (the GUI's airbrush keeps its long strokes in the
    StrokeLog in the same undo step)."""
    sculpt_state.map_property(map)
    points = np.asarray(path, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) == 0:
        raise ValueError("path: expected a non-empty list of (u, v) pairs")
    if not np.all(np.isfinite(points)) or points.min() < 0 or points.max() > 1:
        raise ValueError("path: (u, v) must be finite and within the unit square")
    radius = _finite(radius, "radius", positive=True)
    factor = _finite(factor, "factor", positive=True)
    strength = _finite(strength, "strength", positive=True)

    def change(s: core.DynamicSurface) -> None:
        material = getattr(s, map + "_map")
        target = factor * float(np.mean(material.values))
        previous = None
        for p in points:
            paint_dabs(material, previous, (p[0], p[1]), radius, target, strength)
            previous = (p[0], p[1])
    return change


class CursorSource(Protocol):
    """Anything with a cursor at a given time, as :class:`HapticSculpt.ReplayDevice` has."""

    def sample(self, t: float) -> Any:
        """The cursor at ``t`` seconds: ``position``, ``orientation`` and ``grab``."""


@dataclass(frozen=True)
class RunReport:
    """What :func:`run` did."""

    steps: int
    simulated_seconds: float
    wall_seconds: float
    refused_steps: int
    slept_steps: int
    max_force: float        #: largest reaction force on the cursor (mN with mm, s, kg)

    @property
    def steps_per_second(self) -> float:
        """Steps per wall-clock second."""
        return self.steps / self.wall_seconds if self.wall_seconds > 0 else math.inf


def run(obj: Any, seconds: float, device: CursorSource | None = None, tool: str | None = "rope",
        dt: float = 1e-3, integrator: str | None = None) -> RunReport:
    """Steps the sculpt synchronously and deterministically for ``seconds`` of simulated time.

    At each step of ``dt`` seconds the cursor is read from ``device`` at the simulated time (button
    1 held = grab); without a device the surface just evolves. The tool (None keeps the current
    one) releases at the end; the result is written back to the object as one undo transaction.
    """
    obj = _sculpt(obj, solids=True)
    seconds = _finite(seconds, "seconds", nonnegative=True)
    dt = _finite(dt, "dt", positive=True)
    if device is not None and not hasattr(device, "sample"):
        raise TypeError(f"device: expected a device with sample(t), got {type(device).__name__}")
    if tool is not None and tool not in core.TOOLS:
        raise ValueError(f"tool: unknown tool {tool!r} (one of {', '.join(core.TOOLS)})")
    if integrator is not None and integrator not in core.INTEGRATORS:
        raise ValueError(f"integrator: unknown integrator {integrator!r} (one of {', '.join(core.INTEGRATORS)})")
    surface = obj.Proxy.live.surface  # (raises while a session steps it)
    if tool is not None and surface.tool.name != tool:
        sculpt_state.choose_tool(surface, tool)
    if integrator is not None:
        surface.integrator = integrator
    steps = int(round(seconds / dt))
    refused = slept = 0
    max_force = 0.0
    t0 = time.perf_counter()
    for k in range(steps):
        if device is not None:
            c = device.sample(k * dt)
            surface.set_cursor(c.position, c.orientation, c.grab)
        r = surface.step(dt)
        refused += r.refused
        slept += r.slept
        max_force = max(max_force, float(np.linalg.norm(r.force)))
    wall = time.perf_counter() - t0
    if surface.tool.grabbed:
        c = device.sample(steps * dt) if device is not None else None
        surface.set_cursor(c.position if c else (0.0, 0.0, 0.0), c.orientation if c else (1.0, 0.0, 0.0, 0.0), False)
    obj.Proxy.live.commit("Sculpt stroke", strokes=1)
    return RunReport(steps, steps * dt, wall, refused, slept, max_force)


def add_constraint(obj: Any, kind: str, uv: tuple[float, float] | None = None,
                   near: Sequence[float] | None = None, **target: Any) -> int:
    """Adds a penalty constraint at parameter ``uv`` or at the mass point nearest ``near``.

    kind: "point" (``target=(x, y, z)``), "tangent" or "normal" (``normal=(nx, ny, nz)``), "curvature"
    (``curvature=(ku, kv)``); each defaults to the current value. ``stiffness=`` overrides the
    default penalty stiffness. One undo transaction; returns the constraint id.
    """
    obj = _sculpt(obj, solids=True)
    if kind not in core.CONSTRAINTS:
        raise ValueError(f"kind: unknown constraint {kind!r} (one of {', '.join(core.CONSTRAINTS)})")
    if (uv is None) == (near is None):
        raise ValueError("uv/near: give exactly one of them")
    allowed = {"point": {"target"}, "tangent": {"normal"}, "normal": {"normal"}, "curvature": {"curvature"}}[kind]
    unknown = set(target) - allowed - {"stiffness"}
    if unknown:
        raise TypeError(f"{', '.join(sorted(unknown))}: not a target of a {kind} constraint "
                        f"(use {', '.join(sorted(allowed | {'stiffness'}))})")
    kwargs: dict[str, Any] = {}
    if uv is not None:
        u, v = (_finite(x, "uv") for x in uv)
        domain = obj.Proxy.live.snapshot().surface.domain
        (u0, u1), (v0, v1) = domain
        if not (u0 <= u <= u1 and v0 <= v <= v1):
            raise ValueError(f"uv: {(u, v)} is outside the surface's domain {domain}")
        kwargs["uv"] = (u, v)
    else:
        kwargs["near"] = [_finite(x, "near") for x in near]
    if "stiffness" in target:
        kwargs["stiffness"] = _finite(target["stiffness"], "stiffness", positive=True)
    if "target" in target:
        kwargs["target"] = [_finite(x, "target") for x in target["target"]]
    if "normal" in target:
        kwargs["target"] = [_finite(x, "normal") for x in target["normal"]]
    if "curvature" in target:
        kwargs["curvature"] = tuple(_finite(x, "curvature") for x in target["curvature"])
    return obj.Proxy.live.edit(lambda s: s.add_constraint(kind, **kwargs), f"Add {kind} constraint")


def remove_constraint(obj: Any, cid: int) -> None:
    """Removes constraint ``cid``, a penalty constraint or a curve constraint (one undo transaction)."""
    obj = _sculpt(obj, solids=True)
    if curve_api.is_curve_id(cid):
        curve_api.remove_curve_constraint(obj, cid)
        return
    obj.Proxy.live.edit(lambda s: s.remove_constraint(cid), "Remove constraint")


def _edges(edges: Any) -> Any:
    """make_sculpt's ``edges``: "held" is a clamped sheet (G1), the rest as boundary_poles takes it."""
    return "G1" if isinstance(edges, str) and edges == "held" else edges


def hold_boundary(obj: Any, boundary: Any = "G0") -> list[int]:
    """Holds the sculpt's edges exactly, as hard constraints (the poles do not move at all; not
    penalties): "G0" keeps an edge where it is, "G1" its tangent planes along it too, "G2" its
    curvature across it too (a face beside it met as it does now, to second order), "G3" that
    curvature's rate too, "free" lets it move. ``boundary`` is one of those for all four edges, or a dict from edge ("u0", "u1", "v0",
    "v1": the sides of the parameter domain) to one of them, the others free. Replaces what was held
    before; curve constraints hold on top of it (ValueError naming one that cannot). One undo
    transaction (also during a session, unless the sculpt follows curves); returns the held pole indices."""
    _sculpt(obj)
    live = obj.Proxy.live
    snapshot = live.snapshot()
    held = boundary_poles(tuple(snapshot.surface.controls), boundary)  # validated before the document changes
    if not curve_api.records_of(obj):
        live.edit(lambda s: s.hold_poles(held, s.linked_poles), "Hold edges")  # (links kept)
        return held
    if live.session is not None:
        raise RuntimeError(f"{obj.Label}: stop the sculpting session before holding the edges of a sculpt that "
                           "follows curves")
    poles = np.asarray(snapshot.poles, float).reshape(-1, 3)
    moved, links, write = curve_api.rehold(obj, snapshot, held, curve_api.base_links(obj, snapshot), poles)

    def change(s: core.DynamicSurface) -> None:
        if not np.array_equal(moved, poles):
            s.set_poles(moved.reshape(np.asarray(s.poles).shape))
        s.hold_poles(held, links)
    live.edit(change, "Hold edges", inside=write)  # (the curves held again on top of the edges)
    return held


def held_boundary(obj: Any) -> dict[str, str]:
    """What each edge of the sculpt is held as ("free", "G0" to "G3"), read from its held poles."""
    _sculpt(obj)
    surface = obj.Proxy.live.snapshot()
    return kinds_held(surface.held_poles, tuple(surface.surface.controls))


def _objects(objs: Any) -> list[Any]:
    items = [objs] if hasattr(objs, "Shape") else list(objs) if isinstance(objs, Iterable) else None
    if not items:
        raise TypeError("objs: expected a document object with a Shape or a non-empty list of them")
    for o in items:
        if not hasattr(o, "Shape") or not hasattr(o, "Document"):
            raise TypeError(f"objs: {o!r} is not a document object with a Shape")
        if o.Shape.isNull():
            raise ValueError(f"objs: {o.Name} has an empty Shape")
    return items


def export_step(objs: Any, path: str | os.PathLike[str]) -> str:
    """Writes the objects' shapes to a STEP file (AP214) and returns its path."""
    items = _objects(objs)
    path = os.fspath(path)
    if not path.lower().endswith((".step", ".stp")):
        raise ValueError(f"path: expected a .step or .stp file name, got {path!r}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise ValueError(f"path: folder {folder!r} does not exist")
    import Import
    Import.export(items, path)
    if not os.path.isfile(path) or os.path.getsize(path) == 0:
        raise RuntimeError(f"export_step: FreeCAD wrote nothing to {path!r}")
    return path


def thicken(obj: Any, thickness: float, tolerance: float = 1e-6) -> Any:
    """A solid made by offsetting the sculpt face by ``thickness`` (mm; negative: the other side)
    and closing the gap; raises ``ValueError`` when OCCT cannot make a valid solid. A plain shape:
    :func:`make_thickness` makes one that follows the sculpt."""
    from .thickness import thickened
    _sculpt(obj)
    thickness = _finite(thickness, "thickness")
    if thickness == 0:
        raise ValueError("thickness: must be non-zero")
    tolerance = _finite(tolerance, "tolerance", positive=True)
    return thickened(obj.Shape.Faces[0], thickness, tolerance)


def make_thickness(obj: Any, thickness: float, name: str = "Thickness") -> Any:
    """A parametric solid of the sculpt ``obj``: its face offset by ``thickness`` mm (> 0) along its
    normal and closed, as a Thickness object that recomputes after each stroke and when its
    Thickness property is edited. One undo step; ``ValueError`` (nothing added) when the face
    cannot be thickened by that much."""
    from .thickness import ThicknessFeature, attach_view_provider, thickened
    _sculpt(obj)
    thickness = _finite(thickness, "thickness", positive=True)
    if not isinstance(name, str) or not name:
        raise TypeError("name: expected a non-empty string")
    shape = thickened(obj.Shape.Faces[0], thickness)  # (raises before anything is added)
    doc = obj.Document
    with transaction(doc, "Thicken"):
        feature = doc.addObject("Part::FeaturePython", name)
        ThicknessFeature(feature)
        feature.Source = obj
        feature.Thickness = thickness
        feature.Shape = shape
        attach_view_provider(feature)
        feature.purgeTouched()
    return feature


def to_cadquery(obj: Any) -> Any:
    """A ``cadquery.Face`` on the same B-spline (poles, knots, degrees, weights) as the sculpt.

    cadquery is imported here, only when called."""
    _sculpt(obj)
    try:
        import cadquery as cq
        from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
        from OCP.Geom import Geom_BSplineSurface
        from OCP.gp import gp_Pnt
        from OCP.TColgp import TColgp_Array2OfPnt
        from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_Array2OfReal
    except ImportError as exc:
        raise ImportError("to_cadquery: cadquery is not installed in this Python (pip install cadquery)") from exc
    from .part_surface import compress_knots
    state = sculpt_feature_state(obj)
    s, a = state.settings, state.arrays
    nu, nv = s["controls"]
    poles = a["Poles"].reshape(nu, nv, 3)
    pts = TColgp_Array2OfPnt(1, nu, 1, nv)
    for i in range(nu):
        for j in range(nv):
            pts.SetValue(i + 1, j + 1, gp_Pnt(*map(float, poles[i, j])))

    def reals(values: Sequence[float]) -> Any:
        arr = TColStd_Array1OfReal(1, len(values))
        for k, x in enumerate(values):
            arr.SetValue(k + 1, float(x))
        return arr

    def ints(values: Sequence[int]) -> Any:
        arr = TColStd_Array1OfInteger(1, len(values))
        for k, x in enumerate(values):
            arr.SetValue(k + 1, int(x))
        return arr
    uk, um = compress_knots(a["KnotsU"])
    vk, vm = compress_knots(a["KnotsV"])
    p, q = s["degree"]
    if a["Weights"].size:
        w = TColStd_Array2OfReal(1, nu, 1, nv)
        for (i, j), x in np.ndenumerate(a["Weights"].reshape(nu, nv)):
            w.SetValue(i + 1, j + 1, float(x))
        geom = Geom_BSplineSurface(pts, w, reals(uk), reals(vk), ints(um), ints(vm), p, q, False, False)
    else:
        geom = Geom_BSplineSurface(pts, reals(uk), reals(vk), ints(um), ints(vm), p, q, False, False)
    return cq.Face(BRepBuilderAPI_MakeFace(geom, 1e-6).Face())


def sculpt_feature_state(obj: Any) -> sculpt_state.SculptState:
    """The sculpt state stored in a Sculpt object's properties."""
    return read_state(_sculpt(obj))
