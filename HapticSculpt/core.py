"""The C++ dynamics core: dynamic B-spline surfaces, tools, constraints and integrators.

Every call validates its arguments and raises ``ValueError`` (or ``TypeError``) naming the faulty
one. State buffers (poles, mesh, velocities, maps) are read-only numpy views of the core's memory.

Units are the caller's as long as they are consistent; the FreeCAD layer uses mm, s and kg, so
forces are in kg*mm/s^2 (mN).
"""
from __future__ import annotations

try:
    from . import _core
except ImportError as exc:  # pragma: no cover - exercised only on a broken install
    raise ImportError(
        "HapticSculpt's native core is not built: run `make build` in the HapticSculpt checkout "
        f"(it must be built for {__import__('sys').executable})") from exc

BSplineSurface = _core.BSplineSurface
DynamicSurface = _core.DynamicSurface
MaterialMap = _core.MaterialMap
StepReport = _core.StepReport
Tool = _core.Tool
RopeTool = _core.RopeTool
MagnetTool = _core.MagnetTool
OrientationTool = _core.OrientationTool
SmoothTool = _core.SmoothTool
MAX_DEGREE: int = _core.MAX_DEGREE

# The names of the core's choices, from its one table of each (native_core/src/names.hpp).
INTEGRATORS: tuple[str, ...] = _core.INTEGRATORS
TOOLS: tuple[str, ...] = _core.TOOLS
CONSTRAINTS: tuple[str, ...] = _core.CONSTRAINTS
FALLOFFS: tuple[str, ...] = _core.FALLOFFS
LAWS: tuple[str, ...] = _core.LAWS
MAPS: tuple[str, ...] = _core.MAPS


def patch(controls: tuple[int, int] = (8, 8), degree: tuple[int, int] = (3, 3),
          mesh: tuple[int, int] = (40, 40), size: tuple[float, float] = (100.0, 100.0)) -> DynamicSurface:
    """A flat dynamic patch in the XY plane, centred at the origin."""
    return DynamicSurface(BSplineSurface.plane(controls, degree, size), mesh)


__all__ = ["BSplineSurface", "DynamicSurface", "MaterialMap", "StepReport", "Tool", "RopeTool", "MagnetTool",
           "OrientationTool", "SmoothTool", "MAX_DEGREE", "INTEGRATORS", "TOOLS", "CONSTRAINTS", "FALLOFFS",
           "LAWS", "patch"]
