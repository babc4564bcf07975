"""How a face of a solid meets its neighbours in the base, edge by edge: the hold a sculpt of it
starts with, so that sculpting a face in place keeps the part's continuity (a rounded block's top
stays tangent to its rounds) unless the designer asks for another.

An edge is G2 where the faces meet curvature-continuously (the jump of normal curvature across it
within :data:`seam_continuity.G2_SHARE`, as a seam between sculpted faces is judged), G1 where
they meet tangentially (normals within :data:`TANGENT_DEG`), G0 at a crease, and G0 where no other
face is there to meet.
"""
from __future__ import annotations

from typing import Any, Sequence

from . import face_in_solid, seam_continuity

#: Faces whose normals along an edge are within this angle meet tangentially (Alias's usual G1
#: tolerance is 0.1 degrees; a fillet in FreeCAD meets its faces within 1e-6 degrees).
TANGENT_DEG = 0.1
#: What :func:`sculpt_solid` and :func:`set_boundary` take as "hold each edge as the base has it".
AS_BASE = "base"


def edge_kind(profile: face_in_solid.EdgeProfile) -> str:
    """G2, G1 or G0: how the two sides of an edge meet (a profile of the base's own surface)."""
    if profile.base_deg is None or profile.base_deg > TANGENT_DEG:
        return "G0"
    if profile.g2_pct is not None and profile.g2_pct <= 100.0 * seam_continuity.G2_SHARE:
        return "G2"
    return "G1"


#: What :func:`base_kinds` found, by the base's shape, faces and skipped seams: a base does not
#: change under a sculpt, and Hold edges asks again at every press (0.3 s a face).
_FOUND: dict[tuple[Any, ...], dict[str, str]] = {}
_FOUND_SIZE = 64


def base_kinds(shape: Any, faces: Sequence[str], skip: frozenset[str] = frozenset()) -> dict[str, str]:
    """Every edge of ``shape``'s ``faces`` but those in ``skip`` (the seams between them, which
    :func:`face_net.seam_kinds` judges on the net) to how the base meets its neighbour there."""
    key = (shape.hashCode(), tuple(faces), skip)
    if key not in _FOUND:
        if len(_FOUND) >= _FOUND_SIZE:
            _FOUND.pop(next(iter(_FOUND)))  # (the oldest)
        _FOUND[key] = _measured(shape, faces, skip)
    return dict(_FOUND[key])


def _measured(shape: Any, faces: Sequence[str], skip: frozenset[str]) -> dict[str, str]:
    kinds: dict[str, str] = {}
    for face in faces:
        surface = face_in_solid.nurbs_face(shape.getElement(face)).Surface
        for profile in face_in_solid.edge_profiles(surface, shape, face, {}, skip):
            # (an edge two of the faces share but not as a seam: the looser of the two)
            kind = edge_kind(profile)
            kinds[profile.edge] = min(kinds.get(profile.edge, kind), kind)
    return kinds
