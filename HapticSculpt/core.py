"""The C++ dynamics core: dynamic B-spline surfaces, tools, constraints and integrators.

Every call validates its arguments and raises ``ValueError`` (or ``TypeError``) naming the faulty
one. State buffers (poles, mesh, velocities, maps) are read-only numpy views of the core's memory.

Units are the caller's as long as they are consistent; the FreeCAD layer uses mm, s and kg, so
forces are in kg*mm/s^2 (mN).
"""
from __future__ import annotations

import os
import sys
from typing import Any
from types import ModuleType

from .version import __version__

#: Which native core to prefer: "installed" (the default: the hapticsculpt_core package, e.g. from
#: the wheel in FreeCAD's AdditionalPythonPackages, then the in-tree build) or "in-tree" (a
#: developer's fresh `make build` first).
PREFERENCE_VARIABLE = "HAPTICSCULPT_CORE"


def _installed() -> ModuleType:
    import hapticsculpt_core
    return hapticsculpt_core


def _in_tree() -> ModuleType:
    from . import _core
    return _core


def _load_native() -> tuple[ModuleType, str]:
    """The native module and a sentence saying which one it is and where it was found."""
    tried: list[str] = []
    passed_over: list[str] = []
    order = [("installed package", "hapticsculpt_core", _installed), ("in-tree build", "HapticSculpt._core", _in_tree)]
    preference = os.environ.get(PREFERENCE_VARIABLE, "installed")
    if preference not in ("installed", "in-tree"):
        raise ImportError(f"{PREFERENCE_VARIABLE}={preference!r}: give 'installed' or 'in-tree'")
    if preference == "in-tree":
        order.reverse()
    for kind, name, load in order:
        try:
            module = load()
        except ImportError as exc:
            tried.append(f"{name}: {exc}")
            continue
        version = getattr(module, "__version__", "unknown")
        if version != __version__:
            passed_over.append(f"{name} at {module.__file__} is version {version}, this addon is {__version__}")
            continue
        note = f"; passed over: {'; '.join(passed_over)}" if passed_over else ""
        return module, f"{kind} {name} {version} ({module.__file__}){note}"
    tried += passed_over
    raise ImportError(
        f"HapticSculpt {__version__} finds no native core it can use for Python "
        f"{sys.version_info.major}.{sys.version_info.minor} ({sys.executable}):\n  " + "\n  ".join(tried) +
        "\nEither install the hapticsculpt_core wheel for this Python into FreeCAD's "
        "AdditionalPythonPackages folder (`python3 tools/install_core.py WHEEL` in the addon's folder; "
        "the README's Install section), or build it in the checkout with `make build`.")


#: The native module in use, and which one it is (FreeCAD's log shows it when the workbench loads).
native, NATIVE_ORIGIN = _load_native()

BSplineSurface = native.BSplineSurface
DynamicSurface = native.DynamicSurface
MaterialMap = native.MaterialMap
#: Nearest-point queries over a fixed cloud (a scan): ``PointTree(points).nearest(queries)``.
PointTree = native.PointTree
StepReport = native.StepReport
Tool = native.Tool
#: A tool by name, on its own (its settings checked as on a surface's tool): ``make_tool("flatten")``.
make_tool = native.make_tool
MAX_DEGREE: int = native.MAX_DEGREE
#: How much harder the rope pulls per unit of the bending ratio where it is tied (the rope's ``gain``).
ROPE_PLATE_GAIN: float = native.ROPE_PLATE_GAIN

# The core's choices, each declared once in C++ (the table beside each enum; each tool's ToolInfo in
# native_core/src/tools_and_constraints/tools/): nothing here repeats them.
INTEGRATORS: tuple[str, ...] = native.INTEGRATORS
#: The tools in menu order.
TOOLS: tuple[str, ...] = native.TOOLS
#: Per tool: ``title``, ``tip``, ``order``, ``falloff`` (whether it takes one), ``parameters``
#: (name -> ``default``, ``allow_zero``, ``doc``) and ``readouts`` (name -> doc).
TOOL_INFO: dict[str, dict[str, Any]] = native.TOOL_INFO
CONSTRAINTS: tuple[str, ...] = native.CONSTRAINTS
FALLOFFS: tuple[str, ...] = native.FALLOFFS
LAWS: tuple[str, ...] = native.LAWS
MAPS: tuple[str, ...] = native.MAPS
#: The session defaults: ``haptic_rate`` (Hz), ``sim_dt`` (s) and ``realtime`` (ask for SCHED_FIFO).
DEFAULTS: dict[str, Any] = native.DEFAULTS


def tool_settings_of(tool: str) -> tuple[str, ...]:
    """The settings ``tool`` takes: its parameters, ``falloff`` if it has one, and the limits every
    tool has (``max_force``, ``ramp_time``). ``ValueError`` for an unknown tool."""
    if tool not in TOOL_INFO:
        raise ValueError(f"tool: unknown tool {tool!r} (one of {', '.join(TOOLS)})")
    info = TOOL_INFO[tool]
    return tuple(info["parameters"]) + (("falloff",) if info["falloff"] else ()) + ("max_force", "ramp_time")


def patch(controls: tuple[int, int] = (8, 8), degree: tuple[int, int] = (3, 3),
          mesh: tuple[int, int] = (40, 40), size: tuple[float, float] = (100.0, 100.0)) -> DynamicSurface:
    """A flat dynamic patch in the XY plane, centred at the origin."""
    return DynamicSurface(BSplineSurface.plane(controls, degree, size), mesh)


__all__ = ["BSplineSurface", "DynamicSurface", "MaterialMap", "PointTree", "StepReport", "Tool", "MAX_DEGREE", "ROPE_PLATE_GAIN",
           "INTEGRATORS", "TOOLS", "TOOL_INFO", "make_tool", "CONSTRAINTS", "FALLOFFS", "LAWS", "MAPS", "DEFAULTS", "tool_settings_of",
           "patch"]
