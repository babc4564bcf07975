"""Which edges of the base a designer picked on a SculptedSolid: FreeCAD names the rebuilt solid's
edges in its own order, and a sculpt's holds are kept by the base's names (its Boundary). An edge
of the sculpted faces is found by where it runs now (the continuity check's samples along every
edge and seam as sculpted); other edges of the solid are not the sculpt's to hold."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from . import continuity_check
from .sculpted_solid import sculpt_of

#: Points of each sculpted edge compared with a picked edge (at these shares of its samples).
PROBES = (0.1, 0.3, 0.5, 0.7, 0.9)


def base_edge_names(solid: Any, picked: Sequence[str]) -> list[str]:
    """The base's names of the SculptedSolid's edges ``picked`` (its own names: "Edge7"), in order;
    ValueError naming a picked edge that is no edge or seam of the sculpted faces."""
    profiles = [p for p in continuity_check.profiles(sculpt_of(solid)) if p.edge.startswith("Edge")]
    tolerance = _tolerance(solid)
    names = []
    for sub in picked:
        try:
            edge = solid.Shape.getElement(sub)
        except Exception:  # noqa: BLE001 - FreeCAD raises several types for a missing element
            raise ValueError(f"{solid.Label} has no {sub}") from None
        best, distance = None, np.inf
        for p in profiles:
            d = max(edge.distToShape(q)[0] for q in _probes(p))
            if d < distance:
                best, distance = p.edge, d
        if best is None or distance > tolerance:
            raise ValueError(f"{solid.Label}'s {sub} is not an edge of its sculpted faces "
                             f"({', '.join(solid.SculptFaces)}): pick one of their edges or seams")
        if best not in names:
            names.append(best)
    return names


def own_edge_names(solid: Any, profiles: Sequence[Any] | None = None) -> dict[str, str]:
    """The SculptedSolid's own names ("Edge15") of its sculpted faces' edges and seams, keyed by
    the base's names ("Edge8") that holds, reports and the HUD use: the edge a designer picks in
    the view under each name said (the reverse of :func:`base_edge_names`). ``profiles``: the
    continuity check's (measured again if not given). An edge not found on the solid is left out."""
    if profiles is None:
        profiles = continuity_check.profiles(sculpt_of(solid))
    tolerance = _tolerance(solid)
    own: dict[str, str] = {}
    for p in profiles:
        if not p.edge.startswith("Edge"):
            continue
        probes = _probes(p)
        for k, edge in enumerate(solid.Shape.Edges):
            # (the middle probe first: most edges are far from it)
            if edge.distToShape(probes[len(probes) // 2])[0] <= tolerance and \
                    max(edge.distToShape(q)[0] for q in probes) <= tolerance:
                own[p.edge] = f"Edge{k + 1}"
                break
    return own


def edge_said(name: str, solid: Any | None, own: dict[str, str]) -> str:
    """How a message names the base's edge ``name`` on ``solid`` (a SculptedSolid, or None): with
    the solid's own name beside it where that differs ("Edge8 (SculptedSolid Edge15)"): the Report
    view named the Fillet's Edge8 where the view picks SculptedSolid.Edge15."""
    if solid is None or own.get(name, name) == name:
        return name
    return f"{name} ({solid.Label} {own[name]})"


def _tolerance(solid: Any) -> float:
    """How near (mm) a solid's edge runs to a sculpted edge's samples to be that edge."""
    return 1e-6 * max(solid.Shape.BoundBox.DiagonalLength, 1.0) + 1e-4


def _probes(profile: Any) -> list[Any]:
    """Vertices at PROBES of a sculpted edge's samples (a continuity-check profile)."""
    import Part
    return [Part.Vertex(*profile.points[int(round(share * (len(profile.points) - 1)))]) for share in PROBES]
