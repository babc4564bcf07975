"""Scripting API of scan targets (issue 30): give a sculpt a scan to be measured against, and read
how far the scan lies from it.

The target is a document object the Sculpt's ``Target`` property links to (:mod:`scan_target`);
``TargetWeight`` and ``TargetTolerance`` are numbers beside it and ``Deviation`` is the report
(JSON, read-only) kept up to date at each recompute (:mod:`scan_deviation`).
"""
from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from . import scan_deviation, scan_target
from .sculpt_feature import is_sculpt
from .sculpt_properties import read_state
from .sculpted_solid import is_sculpted_solid, sculpt_of, solid_of
from .undo import transaction

GROUP = "Scan"


def _sculpt(obj: Any) -> Any:
    if is_sculpted_solid(obj):
        return sculpt_of(obj)
    if not is_sculpt(obj):
        raise TypeError(f"obj: expected a HapticSculpt Sculpt or SculptedSolid object, got "
                        f"{getattr(obj, 'TypeId', type(obj).__name__)}")
    return obj


def _number(value: Any, name: str, low: float, high: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    x = float(value)
    if not (math.isfinite(x) and low <= x <= high):
        raise ValueError(f"{name}: must be in [{low:g}, {high:g}], got {value!r}")
    return x


def _ensure_properties(sculpt: Any) -> None:
    props = sculpt.PropertiesList
    if "Target" not in props:
        sculpt.addProperty("App::PropertyLink", "Target", GROUP, "The scan the surface is measured against "
                           "(a mesh or point cloud in the document)")
    if "TargetWeight" not in props:
        sculpt.addProperty("App::PropertyFloat", "TargetWeight", GROUP, "How strongly the target pulls the "
                           "surface (0: not at all)")
    if "TargetTolerance" not in props:
        sculpt.addProperty("App::PropertyFloat", "TargetTolerance", GROUP, "Deviation (mm) a point may have "
                           "and count as within")
    if "TargetSide" not in props:
        sculpt.addProperty("App::PropertyInteger", "TargetSide", GROUP, "+1 or -1: the sign that makes a "
                           "deviation positive outside a sculpted solid; 0 on a sheet (along its normal)")
        sculpt.setEditorMode("TargetSide", 2)
    if scan_deviation.PROPERTY not in props:
        sculpt.addProperty("App::PropertyString", scan_deviation.PROPERTY, GROUP, "How far the target lies from "
                           "the surface (JSON: max_mm, mean_mm, p95_mm, within_pct, tolerance_mm, points)")
        sculpt.setEditorMode(scan_deviation.PROPERTY, 1)


def _outward_side(sculpt: Any) -> int:
    """+1 or -1 so that a deviation is positive outside the part on a sculpted solid's face (the
    surface's normal turned outwards); 0 on a sheet, whose sign follows its normal du x dv."""
    solid = solid_of(sculpt)
    if solid is None or solid.Shape.isNull() or not solid.Shape.Solids:
        return 0
    import FreeCAD
    surface = scan_deviation.core_surface(read_state(sculpt))
    (u0, u1), (v0, v1) = surface.domain
    u, v = (u0 + u1) / 2, (v0 + v1) / 2
    step = 1e-3 * solid.Shape.BoundBox.DiagonalLength
    probe = np.asarray(surface.evaluate(u, v)["point"]) + step * np.asarray(surface.normal(u, v))
    return -1 if solid.Shape.isInside(FreeCAD.Vector(*probe), step * 1e-3, True) else 1


def set_target(obj: Any, target: Any, weight: float = 1.0, tolerance: float = 0.1) -> Any:
    """Sets the scan ``obj`` (a Sculpt or SculptedSolid) is measured against, and returns its
    document object. ``target``: a ``Mesh::Feature`` or ``Points::Feature`` of the document
    (linked), a path to an STL, OBJ or PLY file (read into a new Mesh or Points object), or an
    (n, 3) array of points (up to 20 million; kept in a new Points object). The target's
    ``Placement`` positions it. ``weight`` (0..1e6) is how strongly it pulls the surface;
    ``tolerance`` (mm, > 0) is the deviation a point may have to count as within.

    One undo step (the new object and the link together); saved with the document. ValueError or
    TypeError naming the argument for an empty, non-finite, missing or unreadable target, and
    nothing changes. Returns the target object."""
    sculpt = _sculpt(obj)
    weight = _number(weight, "weight", 0.0, 1e6)
    tolerance = _number(tolerance, "tolerance", 1e-9, 1e6)
    doc = sculpt.Document
    if hasattr(target, "isDerivedFrom"):
        if not scan_target.is_target_object(target):
            raise TypeError(f"target: expected a mesh or point cloud, got {getattr(target, 'TypeId', '?')}")
        if target.Document is not doc:
            raise ValueError("target: is in another document")
        scan_target.points_of(target)  # empty or not finite: refused before anything changes
        made = None
    elif isinstance(target, (str, os.PathLike)) or hasattr(target, "__len__") or hasattr(target, "__array__"):
        made = target
    else:
        raise TypeError(f"target: expected a mesh or point cloud object, a file path or an (n, 3) array, got "
                        f"{type(target).__name__}")
    if made is not None and not isinstance(made, (str, os.PathLike)):
        scan_target.checked_points(made)  # validated before the transaction opens
    # The properties are added outside the undo step: FreeCAD's redo of a link added and set in one
    # transaction with the object it links to restores a link to the deleted object.
    _ensure_properties(sculpt)
    with transaction(doc, "Set target"):
        if made is not None:
            target = scan_target.add_target_object(doc, made, f"{sculpt.Name}Target")
        sculpt.Target = target
        sculpt.TargetWeight = weight
        sculpt.TargetTolerance = tolerance
        sculpt.TargetSide = _outward_side(sculpt)
        scan_deviation.refresh_property(sculpt)
    return target


def clear_target(obj: Any) -> None:
    """Removes the target link (the target object stays in the document). One undo step."""
    sculpt = _sculpt(obj)
    if "Target" not in sculpt.PropertiesList or sculpt.Target is None:
        return
    with transaction(sculpt.Document, "Clear target"):
        sculpt.Target = None
        scan_deviation.refresh_property(sculpt)


def target_object(obj: Any) -> Any:
    """The document object ``obj``'s target is, or None."""
    sculpt = _sculpt(obj)
    return sculpt.Target if "Target" in sculpt.PropertiesList else None


def deviation_of(obj: Any, tolerance: float | None = None) -> dict[str, Any]:
    """How far the target's points lie from the surface, on all of them: ``max_mm``, ``mean_mm``,
    ``p95_mm`` (of |distance|), ``within_pct`` (share within ``tolerance``; default the sculpt's
    ``TargetTolerance``), ``tolerance_mm``, ``points`` (measured: over the surface), plus
    ``beyond_edge`` (points past its edges, not measured), ``signed`` and the signed
    ``min_signed_mm``, ``max_signed_mm``, ``mean_signed_mm``: positive outside a sculpted solid,
    along the normal (du x dv) of a sheet. ValueError if ``obj`` has no target or no point lies
    over the surface."""
    sculpt = _sculpt(obj)
    target = scan_target.target_of(sculpt)
    if target is None:
        raise ValueError(f"obj: {sculpt.Label} has no target (hs.set_target)")
    tol = float(sculpt.TargetTolerance) if tolerance is None else _number(tolerance, "tolerance", 1e-9, 1e6)
    try:
        return scan_deviation.measure(sculpt, target.points, tol)
    except ValueError as exc:
        raise ValueError(f"{sculpt.Label}: {exc}") from None
