"""The faces next to a sculpted face, sampled for the displays (zebra, isophotes, curvature maps)
so that a seam between the sculpt and a face that is not sculpted can be judged across it: each
face of the base solid that shares an edge with a sculpted face, on an even grid over its
parameter range (its points, unit normals oriented as in the solid, normal curvatures along u and
v, mean and Gaussian curvature, which cells lie on the face). Their shapes do not change while the
sculpt does (the edges they share are held), so each is sampled once per base shape. No GUI here.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .face_in_solid import normal_curvature, surface_derivatives
from .sculpted_solid import base_solid


@dataclass
class FaceGrid:
    """A face on a g x h grid: ``points`` and ``normals`` (g, h, 3), ``curvature`` (g, h, 6) laid out
    as the core's curvature grid (k_u, k_v, -, -, mean, Gaussian), ``inside`` (g, h) the points on
    the face (its trims)."""

    name: str
    points: np.ndarray
    normals: np.ndarray
    curvature: np.ndarray
    inside: np.ndarray


_CACHE: dict[tuple[Any, ...], list[FaceGrid]] = {}


def neighbour_grids(solid: Any, samples: int = 48) -> list[FaceGrid]:
    """The faces of the SculptedSolid's base next to its sculpted faces, sampled (cached by the
    base's shape and the sculpted faces)."""
    shape = base_solid(solid.Base)
    sculpted = [shape.getElement(f) for f in solid.SculptFaces]
    key = (shape.hashCode(), tuple(solid.SculptFaces), samples)
    if key not in _CACHE:
        edges = [e for f in sculpted for e in f.Edges]
        found = []
        for k, face in enumerate(shape.Faces):
            if any(face.isSame(f) for f in sculpted) or not any(e.isSame(x) for e in face.Edges for x in edges):
                continue
            found.append(_grid(f"Face{k + 1}", face, samples))
        if len(_CACHE) > 16:
            _CACHE.pop(next(iter(_CACHE)))
        _CACHE[key] = found
    return _CACHE[key]


def _grid(name: str, face: Any, n: int) -> FaceGrid:
    u0, u1, v0, v1 = face.ParameterRange
    us, vs = np.linspace(u0, u1, n), np.linspace(v0, v1, n)
    uv = np.array([(u, v) for u in us for v in vs])
    d = surface_derivatives(face.Surface, uv)
    sign = -1.0 if face.Orientation == "Reversed" else 1.0
    cross = np.cross(d[:, 0], d[:, 1])
    length = np.linalg.norm(cross, axis=1, keepdims=True)
    normals = sign * np.divide(cross, length, out=np.zeros_like(cross), where=length > 0)
    surface = face.Surface
    points = np.array([tuple(surface.value(u, v)) for u, v in uv], float)
    ku = normal_curvature(d, normals, d[:, 0])
    kv = normal_curvature(d, normals, d[:, 1])
    su, sv, suu, suv, svv = (d[:, k] for k in range(5))
    e, f, g = (np.einsum("ij,ij->i", a, b) for a, b in ((su, su), (su, sv), (sv, sv)))
    l_, m, n_ = (np.einsum("ij,ij->i", normals, x) for x in (suu, suv, svv))
    with np.errstate(invalid="ignore", divide="ignore"):
        det = e * g - f * f
        gauss = (l_ * n_ - m * m) / det
        mean = (e * n_ - 2 * f * m + g * l_) / (2 * det)
    curvature = np.nan_to_num(np.stack([ku, kv, ku, kv, mean, gauss], axis=1))
    inside = np.array([face.isPartOfDomain(u, v) for u, v in uv], bool)
    shape = (n, n)
    return FaceGrid(name, points.reshape(shape + (3,)), normals.reshape(shape + (3,)),
                    curvature.reshape(shape + (6,)), inside.reshape(shape))
