"""Mirror symmetry of a face to be sculpted: the plane a user gives (a point and a normal, or a
plane of the document), and which parameter direction the mirror image reverses. A face is
symmetric in a plane when its mirror image is itself with u (or v) reversed about the middle of its
parameter range; the sculpt's net is then refined with the mirror images of its knots, so the core
can hold it exactly symmetric (see native_core/src/dynamics/mirror_symmetry.hpp).
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

#: Sample grid (per direction) on which a face's symmetry is checked, and the tolerance, relative
#: to the face's size: OCCT's own precision on a part of 10-100 mm.
CHECK_SAMPLES = 9
TOLERANCE = 1e-7


def _vector(value: Any, what: str) -> np.ndarray:
    try:
        v = np.array([float(value[0]), float(value[1]), float(value[2])])
        if len(value) != 3:
            raise TypeError
    except (TypeError, ValueError, IndexError, AttributeError):
        raise TypeError(f"symmetry: the plane's {what} must be three numbers or a FreeCAD.Vector, got {value!r}") from None
    if not np.all(np.isfinite(v)):
        raise ValueError(f"symmetry: the plane's {what} must be finite, got {value!r}")
    return v


def _planar_face(obj: Any) -> Any:
    shape = getattr(obj, "Shape", None)
    faces = shape.Faces if shape is not None and not shape.isNull() else []
    return faces[0] if len(faces) == 1 and type(faces[0].Surface).__name__ == "Plane" else None


def is_plane(obj: Any) -> bool:
    """Whether a document object is a plane a sculpt can be mirrored in: an origin or datum plane,
    or any object whose shape is one planar face."""
    return getattr(obj, "TypeId", "") in ("App::Plane", "PartDesign::Plane") or _planar_face(obj) is not None


def plane_of(symmetry: Any, doc: Any) -> tuple[np.ndarray, np.ndarray]:
    """(point, unit normal) of ``symmetry``: a ``(point, normal)`` pair, or a plane of ``doc`` (see
    :func:`is_plane`)."""
    if hasattr(symmetry, "Document"):
        if symmetry.Document is not doc:
            raise ValueError(f"symmetry: {symmetry.Label} is not in document {doc.Name}")
        face = _planar_face(symmetry)
        if face is not None:
            u0, u1, v0, v1 = face.ParameterRange
            point = face.valueAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))
            return np.array(tuple(point)), np.array(tuple(face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))))
        if is_plane(symmetry):
            import FreeCAD
            placement = symmetry.getGlobalPlacement() if hasattr(symmetry, "getGlobalPlacement") else symmetry.Placement
            normal = placement.Rotation.multVec(FreeCAD.Vector(0, 0, 1))
            return np.array(tuple(placement.Base)), np.array(tuple(normal))
        raise ValueError(f"symmetry: {symmetry.Label} is not a plane")
    if isinstance(symmetry, str) or not isinstance(symmetry, Sequence) or len(symmetry) != 2:
        raise TypeError(f"symmetry: expected None, (point, normal) or a plane of the document, got {symmetry!r}")
    point, normal = _vector(symmetry[0], "point"), _vector(symmetry[1], "normal")
    length = float(np.linalg.norm(normal))
    if not length > 0:
        raise ValueError("symmetry: the plane's normal must not be zero")
    return point, normal / length


def reflect(points: np.ndarray, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Mirror images of (..., 3) points in the plane."""
    return points - 2.0 * ((points - point) @ normal)[..., None] * normal


def mirror_direction(nface: Any, point: np.ndarray, normal: np.ndarray, name: str) -> int:
    """0 if the face (in its exact B-spline form) is its own mirror image with u reversed about
    the middle of its range, 1 with v reversed; ValueError saying how far it is from either."""
    surface = nface.Surface
    u0, u1, v0, v1 = nface.ParameterRange
    us = np.linspace(u0, u1, CHECK_SAMPLES)
    vs = np.linspace(v0, v1, CHECK_SAMPLES)
    grid = np.array([[tuple(surface.value(u, v)) for v in vs] for u in us])
    size = float(np.linalg.norm(np.ptp(grid.reshape(-1, 3), axis=0)))
    mirrored = reflect(grid, point, normal)
    gaps = [float(np.abs(mirrored[::-1, :] - grid).max()), float(np.abs(mirrored[:, ::-1] - grid).max())]
    direction = int(np.argmin(gaps))
    if gaps[direction] > TOLERANCE * max(size, 1e-300):
        raise ValueError(f"symmetry: {name} is not symmetric in the plane through {tuple(np.round(point, 9))} "
                         f"with normal {tuple(np.round(normal, 9))} (its mirror image is {gaps[direction]:.3g} from "
                         f"itself with u or v reversed, {gaps[direction] / max(size, 1e-300):.2g} of its size)")
    return direction


def mirrored_knots(knots: Sequence[float]) -> list[float]:
    """The mirror images (about the middle of the range) of ``knots`` that are not knots already,
    within a millionth of a span: inserted, they make the knot vector symmetric."""
    k = np.asarray(knots, float)
    lo, hi = float(k[0]), float(k[-1])
    close = 1e-6 * float(np.min(np.diff(np.unique(k))))
    return [float(lo + hi - x) for x in np.unique(k) if np.min(np.abs(k - (lo + hi - x))) > close]


def symmetric_held(held: Sequence[int], direction: int, controls: tuple[int, int]) -> list[int]:
    """``held`` with the mirror partner of each pole added (the held set must be symmetric)."""
    nu, nv = controls
    out = set(held)
    for i in held:
        a, b = divmod(int(i), nv)
        out.add((nu - 1 - a) * nv + b if direction == 0 else a * nv + (nv - 1 - b))
    return sorted(out)
