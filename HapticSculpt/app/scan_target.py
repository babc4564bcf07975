"""The target a sculpt is measured against (issue 30): a scan in the document, read once.

The target is a document object the Sculpt links to (its ``Target`` property): a ``Mesh::Feature``
the user has, or one made from an STL, OBJ or PLY file, or a ``Points::Feature`` made from a file
with vertices only or from an N x 3 array. FreeCAD saves both compactly (binary) in the file; their
``Placement`` positions the scan. Its points (the mesh's vertices, placed) and their k-d tree are
kept on the Sculpt's proxy and read again only when the object changes.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import core

#: Most points a target may have (a 2-million-point scan fits with room).
MAX_POINTS = 20_000_000
#: How far (a share of the surface's size, its bounding-box diagonal) a scan point may be from the
#: mesh and still pull it: a patch placed near a scan finds it, another part of the scan does not.
PULL_REACH = 0.1
#: What :func:`add_target_object` reads.
SUFFIXES = (".stl", ".obj", ".ply")


@dataclass
class Target:
    """A target's points (placed, (n, 3)), their k-d tree and their typical spacing (mm)."""

    source: Any
    points: np.ndarray
    tree: Any
    signature: tuple[Any, ...]
    spacing: float


#: Points a scan's spacing is estimated from (evenly strided: the same answer every time).
SPACING_SAMPLE = 20000


def point_spacing(points: np.ndarray) -> float:
    """The typical distance (mm) between neighbouring points of a scan of a surface: the square root
    of the area it spans over its point count. The area is 12 times the product of the standard
    deviations along its two widest principal axes (a rectangle's exactly, a disc's within 5 %;
    a curved scan spans more: its spacing is, if anything, underestimated)."""
    sample = points[:: max(1, len(points) // SPACING_SAMPLE)]
    spread = np.linalg.svd(sample - sample.mean(axis=0), compute_uv=False) / np.sqrt(len(sample))
    area = 12.0 * spread[0] * max(spread[1], 1e-6 * spread[0])
    return float(np.sqrt(area / len(points)))


def is_target_object(obj: Any) -> bool:
    """True for the objects a target can be: a mesh or a point cloud."""
    return hasattr(obj, "isDerivedFrom") and (obj.isDerivedFrom("Mesh::Feature") or obj.isDerivedFrom("Points::Feature"))


def checked_points(points: Any, name: str = "target") -> np.ndarray:
    """``points`` as a float (n, 3) array: ValueError naming ``name`` if empty, not (n, 3), too many
    or not finite."""
    try:
        a = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected an (n, 3) array of numbers") from None
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected an (n, 3) array of points, got shape {a.shape}")
    if len(a) == 0:
        raise ValueError(f"{name}: has no points")
    if len(a) > MAX_POINTS:
        raise ValueError(f"{name}: at most {MAX_POINTS} points, got {len(a)}")
    bad = ~np.isfinite(a).all(axis=1)
    if bad.any():
        raise ValueError(f"{name}: point {int(np.argmax(bad))} is not finite ({int(bad.sum())} such points)")
    if np.abs(a).max() > 1e9:
        raise ValueError(f"{name}: coordinates must be within +-1e9 mm")
    return np.ascontiguousarray(a)


def _obj_vertices(path: str) -> np.ndarray:
    """The ``v`` lines of an OBJ file (one without faces, which FreeCAD's mesh reader drops)."""
    rows = []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith("v "):
                rows.append(line.split()[1:4])
    try:
        return np.asarray(rows, dtype=float).reshape(-1, 3)
    except ValueError:
        raise ValueError(f"target: {path} has a vertex line that is not three numbers") from None


def add_target_object(doc: Any, source: Any, name: str) -> Any:
    """A new document object holding ``source``: a path to an STL, OBJ or PLY file (a
    ``Mesh::Feature``, or a ``Points::Feature`` if the file has vertices only) or an (n, 3) array
    (a ``Points::Feature``). ValueError naming ``target`` for a missing, unreadable or empty file,
    or points that are not finite."""
    if isinstance(source, (str, os.PathLike)):
        path = os.fspath(source)
        suffix = os.path.splitext(path)[1].lower()
        if suffix not in SUFFIXES:
            raise ValueError(f"target: {path!r} is not an STL, OBJ or PLY file")
        if not os.path.isfile(path):
            raise ValueError(f"target: no file {path!r}")
        import Mesh
        try:
            mesh = Mesh.Mesh(path)
        except Exception as exc:  # FreeCAD raises its own Base.FreeCADError / RuntimeError
            raise ValueError(f"target: cannot read {path!r} as a mesh: {exc}") from None
        label = os.path.splitext(os.path.basename(path))[0] or name
        if mesh.CountFacets > 0:
            checked_points([(p.x, p.y, p.z) for p in mesh.Points], f"target {path!r}")
            obj = doc.addObject("Mesh::Feature", name)
            obj.Mesh = mesh
            obj.Label = label
            return obj
        points = _obj_vertices(path) if suffix == ".obj" else _ply_vertices(path)
        return _points_object(doc, checked_points(points, f"target {path!r}"), name, label)
    points = checked_points(source)
    return _points_object(doc, points, name, name)


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def _ply_vertices(path: str) -> np.ndarray:
    """The vertices of a PLY file (ASCII or binary; a scan's point cloud, which FreeCAD's mesh
    reader drops when it has no faces): the x, y, z of its first element, ``vertex``."""
    def bad(why: str) -> ValueError:
        return ValueError(f"target: cannot read {path!r} as PLY: {why}")
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            raise bad("no 'ply' line")
        fmt, count, props, in_vertex = None, None, [], False
        while True:
            line = f.readline()
            if not line:
                raise bad("no end_header")
            words = line.decode("ascii", "replace").split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "end_header":
                break
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":  # later elements (faces) are not read
                if count is None and words[1] != "vertex":
                    raise bad("its first element is not 'vertex'")
                in_vertex = count is None
                if in_vertex:
                    count = int(words[2])
            elif words[0] == "property" and in_vertex:
                if words[1] == "list":
                    raise bad("a list property in 'vertex'")
                if words[1] not in _PLY_TYPES:
                    raise bad(f"unknown type {words[1]!r}")
                props.append((words[2], _PLY_TYPES[words[1]]))
        names = [n for n, _ in props]
        if count is None or not all(c in names for c in "xyz"):
            raise bad("no vertex x, y and z")
        if fmt == "ascii":
            rows = [f.readline().split() for _ in range(count)]
            try:
                table = np.asarray([r[: len(props)] for r in rows], dtype=float).reshape(count, len(props))
            except ValueError:
                raise bad("a vertex line is not numbers") from None
            return table[:, [names.index(c) for c in "xyz"]]
        if fmt not in ("binary_little_endian", "binary_big_endian"):
            raise bad(f"unknown format {fmt!r}")
        order = "<" if fmt == "binary_little_endian" else ">"
        dtype = np.dtype([(n, order + t) for n, t in props])
        data = np.frombuffer(f.read(dtype.itemsize * count), dtype=dtype)
        if len(data) != count:
            raise bad(f"{len(data)} of {count} vertices")
        return np.stack([data[c].astype(float) for c in "xyz"], axis=1)


def _points_object(doc: Any, points: np.ndarray, name: str, label: str) -> Any:
    import FreeCAD
    import Points
    cloud = Points.Points()
    cloud.addPoints([FreeCAD.Vector(*p) for p in points.tolist()])
    obj = doc.addObject("Points::Feature", name)
    obj.Points = cloud
    obj.Label = label
    return obj


def _signature(obj: Any) -> tuple[Any, ...]:
    """What changes when the object's points do (counts, bounds, placement)."""
    data = obj.Mesh if obj.isDerivedFrom("Mesh::Feature") else obj.Points
    box = data.BoundBox
    counts = (data.CountPoints, getattr(data, "CountFacets", 0))
    return (obj.Name, counts, (box.XMin, box.YMin, box.ZMin, box.XMax, box.YMax, box.ZMax), str(obj.Placement))


def points_of(obj: Any) -> np.ndarray:
    """The target object's points, placed: a mesh's vertices or a cloud's points ((n, 3))."""
    if obj.isDerivedFrom("Mesh::Feature"):
        pts = [(p.x, p.y, p.z) for p in obj.Mesh.Points]
    else:
        pts = [(v.x, v.y, v.z) for v in obj.Points.Points]
    return checked_points(np.array(pts, dtype=float).reshape(-1, 3), f"target {obj.Label}")


def target_of(sculpt: Any) -> Target | None:
    """The Sculpt's target (None if it has none), read again only if its object changed. A target
    object deleted from the document or emptied raises ValueError naming it."""
    obj = getattr(sculpt, "Target", None) if "Target" in sculpt.PropertiesList else None
    if obj is None:
        return None
    if not is_target_object(obj):
        raise ValueError(f"{sculpt.Label}: its target is not a mesh or point cloud")
    signature = _signature(obj)
    cached = getattr(sculpt.Proxy, "target_cache", None)
    if cached is not None and cached.source is obj and cached.signature == signature:
        return cached
    points = points_of(obj)
    target = Target(obj, points, core.PointTree(points), signature, point_spacing(points))
    sculpt.Proxy.target_cache = target
    return target
