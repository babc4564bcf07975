"""Coin3D building blocks for the overlay, the HUD and the slider panel (GUI only): each function
returns a new node; nothing is retained. No Qt: everything is pivy."""
from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np


def material(colour: tuple[float, float, float]) -> Any:
    from pivy import coin
    m = coin.SoMaterial()
    m.diffuseColor = colour
    m.emissiveColor = colour
    return m


def lines(segments: np.ndarray, colour: tuple[float, float, float], width: float) -> Any:
    from pivy import coin
    sep = coin.SoSeparator()
    style = coin.SoDrawStyle()
    style.lineWidth = width
    sep.addChild(style)
    sep.addChild(material(colour))
    coords = coin.SoCoordinate3()
    pts = np.asarray(segments, float).reshape(-1, 3)
    coords.point.setValues(0, len(pts), pts.tolist())
    sep.addChild(coords)
    lines = coin.SoLineSet()
    lines.numVertices.setValues(0, len(segments), [2] * len(segments))
    sep.addChild(lines)
    return sep


def sphere(centre: np.ndarray, radius: float, colour: tuple[float, float, float]) -> Any:
    from pivy import coin
    sep = coin.SoSeparator()
    sep.addChild(material(colour))
    t = coin.SoTranslation()
    t.translation = tuple(float(x) for x in centre)
    sep.addChild(t)
    sphere = coin.SoSphere()
    sphere.radius = radius
    sep.addChild(sphere)
    return sep


def axes(origin: np.ndarray, rotation: np.ndarray, length: float) -> Any:
    from pivy import coin
    sep = coin.SoSeparator()
    for k, colour in enumerate(((1.0, 0.0, 0.0), (0.0, 0.8, 0.0), (0.0, 0.3, 1.0))):
        sep.addChild(lines(np.array([[origin, origin + length * rotation[:, k]]]), colour, 2.0))
    return sep


def circle(centre: np.ndarray, normal: np.ndarray, radius: float, colour: tuple[float, float, float]) -> Any:
    a = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(a) < 1e-6:
        a = np.cross(normal, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(normal, a)
    t = np.linspace(0, 2 * math.pi, 33)
    pts = centre + radius * (np.cos(t)[:, None] * a + np.sin(t)[:, None] * b)
    return lines(np.stack([pts[:-1], pts[1:]], axis=1), colour, 3.0)


def rotation(quat: np.ndarray) -> np.ndarray:
    w, x, y, z = quat / (np.linalg.norm(quat) or 1.0)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def tangents(mesh: np.ndarray, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
    """Mesh tangents along u and v at point (i, j) by differences (one-sided at the border)."""
    g, h = mesh.shape[:2]
    du = mesh[min(i + 1, g - 1), j] - mesh[max(i - 1, 0), j]
    dv = mesh[i, min(j + 1, h - 1)] - mesh[i, max(j - 1, 0)]
    return du, dv


def frame(du: np.ndarray, dv: np.ndarray) -> np.ndarray:
    u = du / (np.linalg.norm(du) or 1.0)
    n = np.cross(du, dv)
    n = n / (np.linalg.norm(n) or 1.0)
    v = np.cross(n, u)
    return np.column_stack([u, v, n])


def coloured_mesh(mesh: np.ndarray, colours: np.ndarray, quads: list[int] | None = None, lit: bool = False) -> Any:
    """The mesh as triangles with per-vertex colours, pulled a hair toward the viewer so it covers
    the shaded face (``quads``: the grid's cells to draw, all when None). Unlit, the colours are
    exact (a legend's); ``lit``, the view's light shades them on both sides as it does the face, so
    the shape shows through (a bump under a uniform material map vanished unlit)."""
    from pivy import coin
    g, h = mesh.shape[:2]
    sep = coin.SoSeparator()
    if lit:
        hints = coin.SoShapeHints()  # smooth normals, lit on both sides
        hints.vertexOrdering = coin.SoShapeHints.UNKNOWN_ORDERING
        hints.creaseAngle = math.pi
        sep.addChild(hints)
    else:
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        sep.addChild(light)
    offset = coin.SoPolygonOffset()
    offset.factor = -1.0
    offset.units = -1.0
    sep.addChild(offset)
    mat = coin.SoMaterial()
    mat.diffuseColor.setValues(0, g * h, np.asarray(colours, float).reshape(-1, 3).tolist())
    sep.addChild(mat)
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.PER_VERTEX_INDEXED
    sep.addChild(binding)
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, g * h, mesh.reshape(-1, 3).tolist())
    sep.addChild(coords)
    quads = quad_indices(g, h) if quads is None else quads
    faces = coin.SoIndexedFaceSet()
    faces.coordIndex.setValues(0, len(quads), quads)  # (materialIndex empty: colours follow coordIndex)
    sep.addChild(faces)
    return sep


def coloured_points(points: np.ndarray, colours: np.ndarray, size: float) -> Any:
    """Points ((n, 3)) drawn ``size`` pixels wide, each in its colour ((n, 3))."""
    from pivy import coin
    sep = coin.SoSeparator()
    style = coin.SoDrawStyle()
    style.pointSize = size
    sep.addChild(style)
    mat = coin.SoMaterial()
    mat.diffuseColor.setValues(0, len(colours), np.asarray(colours, float).tolist())
    sep.addChild(mat)
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.PER_VERTEX
    sep.addChild(binding)
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, len(points), np.asarray(points, float).tolist())
    sep.addChild(coords)
    cloud = coin.SoPointSet()
    cloud.numPoints = len(points)
    sep.addChild(cloud)
    return sep


def masked_quad_indices(inside: np.ndarray) -> list[int]:
    """Face indices (as :func:`quad_indices`) of the cells of a grid whose four corners are all
    ``inside`` (a g x h bool array: the points on a trimmed face)."""
    g, h = inside.shape
    keep = (inside[:-1, :-1] & inside[1:, :-1] & inside[1:, 1:] & inside[:-1, 1:]).ravel()
    return np.asarray(quad_indices(g, h)).reshape(-1, 5)[keep].ravel().tolist()


@functools.lru_cache(maxsize=8)
def quad_indices(g: int, h: int) -> list[int]:
    """Face indices of a g x h grid as quads (-1 separated); the same every frame, so made once."""
    i, j = np.meshgrid(np.arange(g - 1), np.arange(h - 1), indexing="ij")
    a = (i * h + j).ravel()
    return np.stack([a, a + h, a + h + 1, a + 1, np.full_like(a, -1)], axis=1).ravel().tolist()
