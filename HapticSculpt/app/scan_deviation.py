"""How far a scan lies from a sculpt (issue 30): each target point's distance to its closest point
on the sculpt's surface, signed where a side is known, and the report of them.

Points whose closest point is on the surface's edge with the point beyond it (scan that runs past
the patch) are not over the surface: they are counted apart (``beyond_edge``), not measured. The
sign: positive along the surface's normal (du x dv) for a sheet; for a sculpted solid's face,
positive outside the part, so a positive deviation is material the part lacks.
"""
from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from .. import core
from . import sculpt_state

#: Points the ``Deviation`` property is measured on (evenly taken from the target, so a recompute
#: stays well under a second); :func:`report` on all of them is ``hs.deviation_of``.
PROPERTY_POINTS = 50_000
#: The property the report is kept in (JSON, read-only).
PROPERTY = "Deviation"
#: A nearest scan point this many times farther to the side than along the normal (tan 60 degrees)
#: is not over this mesh point (as the pull's springs judge it).
SIDEWAYS = 3.0 ** 0.5


def core_surface(state: sculpt_state.SculptState) -> core.BSplineSurface:
    """The core B-spline surface a sculpt state holds."""
    s, a = state.settings, state.arrays
    nu, nv = s["controls"]
    weights = a["Weights"].reshape(nu, nv) if a["Weights"].size else None
    return core.BSplineSurface(a["Poles"].reshape(nu, nv, 3), tuple(s["degree"]), list(a["KnotsU"]),
                               list(a["KnotsV"]), weights)


def signed_distances(surface: core.BSplineSurface, points: np.ndarray, sign: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Each point's signed distance to the surface, and which points lie over it (not beyond an edge)."""
    r = surface.project(points)
    return sign * r["distance"], ~r["beyond_edge"]


def report(distances: np.ndarray, over: np.ndarray, tolerance: float, signed: bool) -> dict[str, Any]:
    """The deviation report of signed distances (those ``over`` the surface measured)."""
    d = distances[over]
    if d.size == 0:
        raise ValueError("no target point lies over the surface (all are beyond its edges)")
    a = np.abs(d)
    return {
        "max_mm": float(a.max()),
        "mean_mm": float(a.mean()),
        "p95_mm": float(np.percentile(a, 95)),
        "within_pct": float(100.0 * np.count_nonzero(a <= tolerance) / a.size),
        "tolerance_mm": float(tolerance),
        "points": int(a.size),
        "beyond_edge": int(over.size - a.size),
        "signed": bool(signed),
        "min_signed_mm": float(d.min()),
        "max_signed_mm": float(d.max()),
        "mean_signed_mm": float(d.mean()),
    }


def measure(sculpt: Any, points: np.ndarray, tolerance: float) -> dict[str, Any]:
    """The report of ``points`` against the sculpt's surface as its properties hold it."""
    from .sculpt_properties import read_state
    side = int(getattr(sculpt, "TargetSide", 0))  # +-1 on a sculpted solid's face (scan_api), 0 on a sheet
    distances, over = signed_distances(core_surface(read_state(sculpt)), points, float(side or 1))
    return report(distances, over, tolerance, side != 0)


def thinned(points: np.ndarray, count: int = PROPERTY_POINTS) -> np.ndarray:
    """At most ``count`` of the points, evenly taken."""
    return points[::max(1, math.ceil(len(points) / count))]


def refresh_property(sculpt: Any) -> None:
    """Writes the sculpt's ``Deviation`` property (on :data:`PROPERTY_POINTS` of the target's
    points) if it has a target; a target that cannot be read writes why instead."""
    if PROPERTY not in sculpt.PropertiesList:
        return
    from .scan_target import target_of
    try:
        target = target_of(sculpt)
        if target is None:
            text = ""
        else:
            result = measure(sculpt, thinned(target.points), float(sculpt.TargetTolerance))
            result["measured_on"] = f"{result['points'] + result['beyond_edge']} of {len(target.points)} points"
            text = json.dumps(result, sort_keys=True)
    except ValueError as exc:
        text = json.dumps({"error": str(exc)})
    if sculpt.Deviation != text:
        sculpt.Deviation = text


def mesh_deviation(mesh: np.ndarray, normals: np.ndarray, tree: Any, points: np.ndarray, side: int,
                   reach: float) -> np.ndarray:
    """The scan's signed distance at each point of a surface's mesh ((g, h, 3), its unit normals
    alike): how far the nearest scan point lies along the normal (its offset along the surface is a
    scan's sampling, not a deviation), times ``side`` as in :func:`measure`. NaN where the nearest
    scan point lies to the side by more than ``reach`` (about the scan's spacing) and by more than
    SIDEWAYS times its distance along the normal: a hole in the scan, or past its edge (a surface
    tilted to the scan and off it finds its nearest points to the side: they still count)."""
    flat = mesh.reshape(-1, 3)
    index, distance = tree.nearest(flat)
    offset = points[index] - flat
    n = normals.reshape(-1, 3)
    along = np.einsum("ij,ij->i", offset, n)
    across = np.sqrt(np.maximum(distance ** 2 - along ** 2, 0.0))
    signed = along * float(side or 1)
    signed[across > np.maximum(reach, SIDEWAYS * np.abs(along))] = np.nan
    return signed.reshape(mesh.shape[:2])
