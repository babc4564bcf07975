"""The walls a face sculpted in place stays behind (the core's ``set_walls``).

Where the face meets a neighbour at a crease (a box's top and its sides), a stroke that pushes it
sideways would fold it over the neighbour and close a self-intersecting solid. Each wall is the
plane the neighbour has at a point of the shared edge, facing out of the solid; every pole nearest
that point keeps behind it, and so does the face (it lies in the convex hull of its poles).

Walls come from the edges on the sides of the face's parameter rectangle that are held (a free
edge moves with the face) and whose neighbour is not sculpted with it, at the points where the two
meet at more than :data:`CREASE_DEG` (a tangent neighbour's plane is the face's own: it would pin
the face). A pole that starts outside a wall (a concave edge) is not held by it. Trims inside the
rectangle (a hole) give no walls in this version.

A face pushed into the part stops short of a plane on its far side (a box's bottom under its top):
:func:`floor_walls`.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from . import face_in_solid

#: Below this angle between the face and its neighbour an edge is smooth: no wall there.
CREASE_DEG = 10.0
#: Points per edge where the neighbour's plane is taken.
WALL_SAMPLES = 64
#: How far short of a face below a face pushed down stops, in parts of the part's diagonal.
FLOOR_GAP = 1e-3


def _outward_normal(face: Any, point: Any) -> np.ndarray | None:
    """The face's unit normal at ``point`` (on it), facing out of the solid (None where it is not defined)."""
    try:
        u, v = face.Surface.parameter(point)
        n = face.normalAt(u, v)
    except Exception:  # (a degenerate point: a cone's apex)
        return None
    n = np.array([n.x, n.y, n.z], float)
    length = np.linalg.norm(n)
    return n / length if length > 1e-12 else None


def face_walls(shape: Any, faces: Sequence[str], edges: list[face_in_solid.FaceEdge], kinds: dict[str, str],
               poles: np.ndarray, fixed: Sequence[int]) -> list[tuple[list[float], list[float], list[int]]]:
    """The walls (point, outward normal, [pole, ...]) of the sculpted ``faces`` of ``shape``: for
    each held edge on the rectangle's sides that meets an unsculpted neighbour at a crease, every
    pole not ``fixed`` (held or linked) behind the neighbour's plane at the edge point nearest it
    is kept behind that plane. ``poles`` is the (nu, nv, 3) net as it starts."""
    net = np.asarray(poles, float).reshape(-1, 3)
    size = float(np.ptp(net, axis=0).max()) or 1.0
    free = np.setdiff1d(np.arange(len(net)), np.asarray(list(fixed), int))
    if not free.size:
        return []
    cos_crease = np.cos(np.radians(CREASE_DEG))
    walls: list[tuple[list[float], list[float], list[int]]] = []
    for e in edges:
        if e.side is None or kinds.get(e.name, "G0") == "free":
            continue
        neighbour = next((n for n in e.neighbours if n not in faces), None)
        if neighbour is None:
            continue
        edge = shape.getElement(e.name)
        own = next(shape.getElement(f) for f in faces if any(x.isSame(edge) for x in shape.getElement(f).Edges))
        other = shape.getElement(neighbour)
        points, normals = [], []
        for p in edge.discretize(WALL_SAMPLES):
            n_other, n_own = _outward_normal(other, p), _outward_normal(own, p)
            if n_other is None or n_own is None or abs(float(n_other @ n_own)) > cos_crease:
                continue
            points.append((p.x, p.y, p.z))
            normals.append(n_other)
        if not points:
            continue
        points_a, normals_a = np.array(points), np.array(normals)
        nearest = np.argmin(np.linalg.norm(net[free, None, :] - points_a[None, :, :], axis=2), axis=1)
        behind = np.einsum("ij,ij->i", net[free] - points_a[nearest], normals_a[nearest]) <= 1e-7 * size
        for k in np.unique(nearest[behind]):
            held_by = free[behind & (nearest == k)]
            walls.append((points_a[k].tolist(), normals_a[k].tolist(), [int(i) for i in held_by]))
    return walls + floor_walls(shape, faces, net, free)


def _plane(face: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """A planar face's (point, outward unit normal), else None."""
    if "Plane" not in type(face.Surface).__name__:
        return None
    u0, u1, v0, v1 = face.ParameterRange
    normal = _outward_normal(face, face.valueAt((u0 + u1) / 2, (v0 + v1) / 2))
    c = face.CenterOfMass
    return (np.array([c.x, c.y, c.z]), normal) if normal is not None else None


def floor_walls(shape: Any, faces: Sequence[str], net: np.ndarray,
                free: np.ndarray) -> list[tuple[list[float], list[float], list[int]]]:
    """Walls on the far side: each planar face of the solid that faces away from the sculpted ones
    (a box's bottom under its top) and has every free pole behind it, moved :data:`FLOOR_GAP` of the
    part's size inwards, so a face pushed down stops short of the face below instead of passing
    through it. A plane facing another way (a boss's top beside a sculpted top) is no wall: it is
    not in the way of a push into the part."""
    sculpted = [shape.getElement(f) for f in faces]
    normals = [_outward_normal(f, f.CenterOfMass) for f in sculpted]
    facing = [n for n in normals if n is not None]
    if not facing:
        return []
    own = np.mean(facing, axis=0)
    own /= np.linalg.norm(own) or 1.0
    gap = FLOOR_GAP * shape.BoundBox.DiagonalLength
    walls = []
    for k, face in enumerate(shape.Faces):
        if f"Face{k + 1}" in faces:
            continue
        plane = _plane(face)
        if plane is None or float(plane[1] @ own) > -0.5:
            continue
        point = plane[0] - gap * plane[1]
        if np.all((net[free] - point) @ plane[1] <= 0):
            walls.append((point.tolist(), plane[1].tolist(), [int(i) for i in free]))
    return walls
