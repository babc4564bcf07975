"""The complete sculpt state of a core surface as flat float arrays plus one JSON document.

This is what a FreeCAD document stores (float lists are saved as binary doubles, JSON floats are
written with ``repr``), so ``restore(capture(s))`` reproduces ``s`` bit for bit: poles, velocities,
knots, weights, sampling, rest lengths, the bending reference, material maps, constraints (with their ids), held and
linked poles, walls, mirror symmetry, laws, plasticity, the pull toward a scan (on, strength; its target is the
``Target`` link, see :mod:`scan_target`), tool and integrator settings. No FreeCAD import here.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import core

FORMAT_VERSION = 1
#: The float arrays of a state, by the name of the document property that holds each.
ARRAY_NAMES = ("Poles", "Velocities", "KnotsU", "KnotsV", "Weights", "RestLengths",
               "MassMap", "DampingMap", "StiffnessMap", "BendingMap", "BendingReference", "PullMap")
_MAPS = {"MassMap": "mass_map", "DampingMap": "damping_map", "StiffnessMap": "stiffness_map",
         "BendingMap": "bending_map", "PullMap": "pull_map"}
#: Arrays documents from before the bending energy or the pull do not have (empty there: the core's default).
_OPTIONAL = ("BendingMap", "BendingReference", "PullMap")


def map_property(name: str) -> str:
    """The document property of material map ``name`` ("mass", "damping", "stiffness", "bending" or "pull")."""
    for prop, attr in _MAPS.items():
        if attr == name + "_map":
            return prop
    raise ValueError(f"map: one of mass, damping, stiffness, bending, pull, not {name!r}")


@dataclass
class SculptState:
    """Arrays (flat float64) and settings (JSON-compatible) that fully describe a surface."""

    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    settings: dict[str, Any] = field(default_factory=dict)

    def settings_json(self) -> str:
        """Settings as JSON; floats round-trip exactly (``repr``), non-finite values are refused."""
        return json.dumps(self.settings, allow_nan=False, sort_keys=True)


def tool_settings(surface: core.DynamicSurface) -> dict[str, Any]:
    """The current tool's name and parameters."""
    tool = surface.tool
    return {"name": tool.name, "params": {k: getattr(tool, k) for k in core.tool_settings_of(tool.name)}}


#: The diagonal of the part a tool's lengths (a rope's slack, a brush's radius: ``length`` in
#: ``core.TOOL_INFO``) are declared for: a 100 mm square patch. On a smaller sculpt they shrink with
#: it, so a 10 mm part's rope turns taut and its brush covers a tenth of it, as on the patch (with
#: the patch's 5 mm slack, a rope on the top of a 10 mm cube stayed slack: the top rose a third as
#: far). A larger sculpt keeps them.
TOOL_PART_DIAGONAL = 100.0 * math.sqrt(2.0)


def tool_scale(surface: core.DynamicSurface) -> float:
    """What a tool's lengths are scaled by on ``surface``: its size over ``TOOL_PART_DIAGONAL``, at most 1."""
    ratio = float(surface.size) / TOOL_PART_DIAGONAL
    return 1.0 if ratio >= 1.0 - 1e-9 else max(ratio, 1e-3)


def tool_defaults(name: str, scale: float = 1.0) -> dict[str, float]:
    """Tool ``name``'s default settings, its lengths times ``scale``."""
    return {k: p["default"] * (scale if p.get("length") else 1.0)
            for k, p in core.TOOL_INFO[name]["parameters"].items()}


def choose_tool(surface: core.DynamicSurface, name: str) -> None:
    """Selects tool ``name`` with its defaults, its lengths fitted to the surface's size."""
    surface.set_tool(name)
    scale = tool_scale(surface)
    if scale != 1.0:
        for key, value in tool_defaults(name, scale).items():
            setattr(surface.tool, key, value)


def apply_tool(surface: core.DynamicSurface, settings: dict[str, Any]) -> None:
    """Select a tool and set its parameters (unknown names raise ``ValueError``; those not given
    take their defaults, fitted to the surface's size)."""
    name = settings.get("name")
    if name not in core.TOOLS:
        raise ValueError(f"tool: unknown tool {name!r} (one of {', '.join(core.TOOLS)})")
    params = dict(settings.get("params", {}))
    allowed = set(core.tool_settings_of(name))
    unknown = set(params) - allowed
    if unknown:
        raise ValueError(f"tool: {name} has no parameter(s) {', '.join(sorted(unknown))}")
    choose_tool(surface, name)
    for key, value in params.items():
        setattr(surface.tool, key, value)


def capture(surface: core.DynamicSurface) -> SculptState:
    """Everything needed to rebuild ``surface`` exactly."""
    bs = surface.surface
    weights = bs.weights
    arrays = {
        "Poles": np.array(surface.poles, dtype=float).ravel(),
        "Velocities": np.array(surface.velocities, dtype=float).ravel(),
        "KnotsU": np.array(bs.knots_u, dtype=float),
        "KnotsV": np.array(bs.knots_v, dtype=float),
        "Weights": np.zeros(0) if weights is None else np.array(weights, dtype=float).ravel(),
        "RestLengths": np.array(surface.rest_lengths, dtype=float),
        "BendingReference": np.array(surface.bending_reference, dtype=float).ravel(),
    }
    maps = {}
    for prop, attr in _MAPS.items():
        m = getattr(surface, attr)
        arrays[prop] = np.array(m.values, dtype=float).ravel()
        maps[prop] = list(m.shape)
    constraints = []
    for c in surface.constraints:
        item = {k: c[k] for k in ("id", "kind", "index", "stiffness")}
        for k in ("target", "curvature", "offsets"):
            if k in c:
                item[k] = list(c[k])
        constraints.append(item)
    settings = {
        "format": FORMAT_VERSION,
        "controls": list(bs.controls),
        "degree": list(bs.degree),
        "mesh": list(surface.mesh_shape),
        "reference": list(surface.reference),
        "maps": maps,
        "integrator": surface.integrator,
        "iterations": surface.iterations,
        "time_order": surface.time_order,
        "explicit_when_stable": surface.explicit_when_stable,
        "regional": surface.regional,
        "region_margin": surface.region_margin,
        "region_wake": surface.region_wake,
        "cg_iterations": surface.cg_iterations,
        "acceleration_limit": surface.acceleration_limit,
        "max_halvings": surface.max_halvings,
        "sleep_enabled": surface.sleep_enabled,
        "sleep_tolerance": surface.sleep_tolerance,
        "stiffness_law": list(surface.stiffness_law),
        "damping_law": list(surface.damping_law),
        "plasticity": list(surface.plasticity),
        "constraint_stiffness_factor": surface.constraint_stiffness_factor,
        "max_point_force": surface.max_point_force,
        "pull": [surface.pull["enabled"], surface.pull["strength"]],
        "tool": tool_settings(surface),
        "constraints": constraints,
        "held_poles": list(surface.held_poles),
        "linked_poles": [_link_settings(link) for link in surface.linked_poles],
        "walls": [[list(point), list(normal), list(poles)] for point, normal, poles in surface.walls],
        "symmetry": _symmetry_settings(surface),
    }
    return SculptState(arrays, settings)


def _link_settings(link: Any) -> list[Any]:
    """[pole, [[master, weight], ...]] and the offset where it is not zero (a curve's conditions)."""
    pole, masters, offset = link
    out = [pole, [[m, w] for m, w in masters]]
    if any(offset):
        out.append(list(offset))
    return out


def _link_from_settings(link: Any) -> tuple[Any, ...]:
    """(pole, [(master, weight), ...][, offset]) from its JSON form (files before curves have no offset)."""
    if not isinstance(link, list) or len(link) not in (2, 3):
        raise ValueError(f"not a link: {link!r}")
    made = (int(link[0]), [(int(m), float(w)) for m, w in link[1]])
    return made + (tuple(float(x) for x in link[2]),) if len(link) == 3 else made


def _symmetry_settings(surface: core.DynamicSurface) -> dict[str, Any] | None:
    sym = surface.symmetry
    if sym is None:
        return None
    direction, point, normal = sym
    return {"direction": direction, "point": list(point), "normal": list(normal)}


def parse_settings(text: str) -> dict[str, Any]:
    """Settings from JSON, refusing malformed text and non-finite numbers with a clear message."""
    def no_constants(name: str) -> float:
        raise ValueError(f"SculptSettings: non-finite number {name} in the JSON")
    try:
        settings = json.loads(text, parse_constant=no_constants)
    except json.JSONDecodeError as exc:
        raise ValueError(f"SculptSettings: malformed JSON ({exc})") from exc
    if not isinstance(settings, dict):
        raise ValueError("SculptSettings: expected a JSON object")
    return settings


def _pair(settings: dict[str, Any], key: str) -> tuple[int, int]:
    value = settings.get(key)
    if (not isinstance(value, list) or len(value) != 2
            or not all(isinstance(x, int) and not isinstance(x, bool) and x > 0 for x in value)):
        raise ValueError(f"SculptSettings.{key}: expected two positive integers, got {value!r}")
    return value[0], value[1]


def _array(arrays: dict[str, np.ndarray], name: str, size: int | None) -> np.ndarray:
    if name not in arrays:
        raise ValueError(f"{name}: missing")
    a = np.asarray(arrays[name], dtype=float).ravel()
    if size is not None and a.size != size:
        raise ValueError(f"{name}: expected {size} numbers, got {a.size}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: contains NaN or Inf")
    return a


def restore(state: SculptState) -> core.DynamicSurface:
    """Rebuild a surface from a state; any inconsistency raises ``ValueError`` naming the property."""
    s, arrays = state.settings, state.arrays
    if s.get("format") != FORMAT_VERSION:
        raise ValueError(f"SculptSettings.format: unsupported version {s.get('format')!r}")
    nu, nv = _pair(s, "controls")
    degree = _pair(s, "degree")
    mesh = _pair(s, "mesh")
    poles = _array(arrays, "Poles", nu * nv * 3).reshape(nu, nv, 3)
    weights = _array(arrays, "Weights", None)
    if weights.size not in (0, nu * nv):
        raise ValueError(f"Weights: expected 0 or {nu * nv} numbers, got {weights.size}")
    try:
        bs = core.BSplineSurface(poles, degree, list(_array(arrays, "KnotsU", None)),
                                 list(_array(arrays, "KnotsV", None)),
                                 weights.reshape(nu, nv) if weights.size else None)
        surface = core.DynamicSurface(bs, mesh)
    except ValueError as exc:
        raise ValueError(f"SculptSettings: the stored surface is invalid: {exc}") from exc
    surface.set_velocities(_array(arrays, "Velocities", nu * nv * 3).reshape(nu, nv, 3))
    surface.set_rest_lengths(list(_array(arrays, "RestLengths", surface.spring_count)))
    if np.asarray(arrays.get("BendingReference", ())).size:
        g, h = mesh
        surface.set_bending_reference(_array(arrays, "BendingReference", g * h * 3).reshape(g * h, 3))
    surface.reference = tuple(_float_list(s, "reference", 3))
    maps = s.get("maps", {})
    for prop, attr in _MAPS.items():
        if prop in _OPTIONAL and not np.asarray(arrays.get(prop, ())).size:
            continue
        rows, cols = _pair(maps, prop) if prop in maps else (1, 1)
        values = _array(arrays, prop, rows * cols).reshape(rows, cols)
        getattr(surface, attr).set_values(values)
    _apply_settings(surface, s)
    for c in s.get("constraints", []):
        try:
            surface.restore_constraint(c["id"], c["kind"], c["index"], c["stiffness"], c.get("target"),
                                       tuple(c["curvature"]) if "curvature" in c else None, c.get("offsets"))
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"SculptSettings.constraints: invalid constraint {c!r}: {exc}") from exc
    held = s.get("held_poles", [])
    if not isinstance(held, list) or not all(isinstance(i, int) and not isinstance(i, bool) for i in held):
        raise ValueError(f"SculptSettings.held_poles: expected a list of pole indices, got {held!r}")
    links = s.get("linked_poles", [])
    try:
        links = [_link_from_settings(link) for link in links]
    except (TypeError, ValueError, IndexError) as exc:
        raise ValueError(f"SculptSettings.linked_poles: expected [[pole, [[master, weight], ...], offset?], ...], "
                         f"got {links!r}") from exc
    try:
        surface.hold_poles(held, links)
    except ValueError as exc:
        raise ValueError(f"SculptSettings.held_poles: {exc}") from exc
    walls = s.get("walls", [])
    try:
        surface.set_walls([(list(point), list(normal), [int(p) for p in poles]) for point, normal, poles in walls])
    except (TypeError, ValueError) as exc:
        raise ValueError(f"SculptSettings.walls: expected [[point, normal, [pole, ...]], ...]: {exc}") from exc
    sym = s.get("symmetry")
    if sym is not None:
        if not isinstance(sym, dict) or sym.get("direction") not in (0, 1):
            raise ValueError(f"SculptSettings.symmetry: expected null or {{direction: 0 | 1, point, normal}}, got {sym!r}")
        try:
            surface.set_symmetry(sym["direction"], _float_list(sym, "point", 3), _float_list(sym, "normal", 3))
        except ValueError as exc:
            raise ValueError(f"SculptSettings.symmetry: {exc}") from exc
    return surface


def _float_list(s: dict[str, Any], key: str, n: int) -> list[float]:
    value = s.get(key)
    if not isinstance(value, list) or len(value) != n or not all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in value):
        raise ValueError(f"SculptSettings.{key}: expected {n} finite numbers, got {value!r}")
    return [float(x) for x in value]


def _apply_settings(surface: core.DynamicSurface, s: dict[str, Any]) -> None:
    """Solver, laws, plasticity and tool; a missing key keeps the core's default (older files)."""
    try:
        for key in ("integrator", "iterations", "time_order", "explicit_when_stable", "regional", "region_margin",
                    "region_wake", "cg_iterations",
                    "acceleration_limit", "max_halvings",
                    "sleep_enabled", "sleep_tolerance", "constraint_stiffness_factor", "max_point_force"):
            if key in s:
                setattr(surface, key, s[key])
        if "stiffness_law" in s:
            surface.set_stiffness_law(*s["stiffness_law"])
        if "damping_law" in s:
            surface.set_damping_law(*s["damping_law"])
        if "plasticity" in s:
            surface.set_plasticity(*s["plasticity"])
        if "pull" in s:
            enabled, strength = s["pull"]
            if not isinstance(enabled, bool):
                raise TypeError(f"pull: expected [on, strength], got {s['pull']!r}")
            surface.set_pull(enabled, strength)
        if "tool" in s:
            apply_tool(surface, s["tool"])
    except (TypeError, ValueError) as exc:
        raise ValueError(f"SculptSettings: {exc}") from exc


def on_net(surface: core.DynamicSurface, net: core.BSplineSurface) -> core.DynamicSurface:
    """A working copy of ``surface`` (its material, mesh, maps and tool) on ``net`` (its knots
    inserted: the same shape on a finer net), at rest and holding nothing (the caller holds it)."""
    state = capture(surface)
    state.settings.update(controls=list(net.controls), held_poles=[], linked_poles=[], walls=[])
    state.arrays.update(Poles=np.asarray(net.poles, float).ravel(), Velocities=np.zeros(np.asarray(net.poles).size),
                        KnotsU=np.asarray(net.knots_u, float), KnotsV=np.asarray(net.knots_v, float),
                        Weights=np.zeros(0) if net.weights is None else np.asarray(net.weights, float).ravel())
    return restore(state)
