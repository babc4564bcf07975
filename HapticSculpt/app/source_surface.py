"""Turn what a user points at (nothing, a face, a ``Part.BSplineSurface``, ``(object, "FaceN")``)
into a core B-spline surface at the requested control resolution, and measure how far it is from
the source.

Conversion is exact wherever OCCT has an exact B-spline form (``toNurbs``: planes, cylinders,
cones, spheres, tori, surfaces of revolution and extrusion, all rational with fixed weights); the
result is then refined exactly, by degree elevation and knot insertion, up to the requested degree
and control count, so a box face becomes a sculptable 8x8 patch without changing its shape. Only
surfaces with no exact form (or a degree above the core's limit) are approximated by a least-squares
fit at the requested resolution. A trimmed face contributes its rectangular parameter range.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import core


@dataclass(frozen=True)
class SourceSurface:
    """A core surface made from a source, with how it was made and how far it is from the source."""

    surface: core.BSplineSurface
    method: str       #: "plane", "exact" or "approximated"
    error: float      #: largest distance from the source surface (model units) at the check points
    description: str  #: what the source was, for the document


def resolve_face(source: Any, doc: Any = None) -> tuple[Any, str]:
    """The ``Part.Face`` or ``Part.BSplineSurface`` a source names, and a description of it."""
    import Part
    if isinstance(source, Part.BSplineSurface):
        return source, "Part.BSplineSurface"
    if isinstance(source, Part.Face):
        return source, f"Part.Face ({type(source.Surface).__name__})"
    if isinstance(source, tuple) and len(source) == 2:
        obj, sub = source
        if not hasattr(obj, "Shape") or not hasattr(obj, "Document"):
            raise TypeError("source: (document_object, 'FaceN') needs a document object with a Shape")
        if doc is not None and obj.Document is not doc:
            raise ValueError(f"source: {obj.Name} belongs to document {obj.Document.Name}, not {doc.Name}")
        if not isinstance(sub, str) or not sub.startswith("Face"):
            raise ValueError(f"source: expected a face name like 'Face1', got {sub!r}")
        try:
            face = obj.Shape.getElement(sub)
        except Exception as exc:  # OCCT/FreeCAD raise several types for a missing element
            raise ValueError(f"source: {obj.Name} has no {sub}") from exc
        return face, f"{obj.Name}.{sub} ({type(face.Surface).__name__})"
    raise TypeError("source: expected None, a Part.Face, a Part.BSplineSurface or (document_object, 'FaceN'), "
                    f"got {type(source).__name__}")


def _exact_bspline(geom: Any) -> Any | None:
    """An exact, clamped Part.BSplineSurface for a face or surface, restricted to its parameter range."""
    import Part
    if isinstance(geom, Part.BSplineSurface):
        bs = geom.copy()
        u0, u1, v0, v1 = bs.bounds()
    else:
        face = geom
        if not isinstance(face.Surface, Part.BSplineSurface):
            try:
                face = face.toNurbs().Faces[0]
            except Exception:  # no exact B-spline form
                return None
            if not isinstance(face.Surface, Part.BSplineSurface):
                return None
        bs = face.Surface.copy()
        u0, u1, v0, v1 = face.ParameterRange
    if bs.isUPeriodic():
        bs.setUNotPeriodic()
    if bs.isVPeriodic():
        bs.setVNotPeriodic()
    b = bs.bounds()
    # segment() both trims to the face's range and clamps the ends (an unperiodised surface is not)
    bs.segment(max(u0, b[0]), min(u1, b[1]), max(v0, b[2]), min(v1, b[3]))
    return bs


def _refine(bs: Any, controls: tuple[int, int], degree: tuple[int, int]) -> None:
    """Exact refinement in place: raise the degree to ``degree`` and insert knots (midpoints of the
    widest spans) until there are at least ``controls`` poles in each direction."""
    du, dv = max(0, degree[0] - bs.UDegree), max(0, degree[1] - bs.VDegree)
    if du or dv:
        bs.increaseDegree(bs.UDegree + du, bs.VDegree + dv)
    for direction in (0, 1):
        while (bs.NbUPoles if direction == 0 else bs.NbVPoles) < controls[direction]:
            knots = bs.getUKnots() if direction == 0 else bs.getVKnots()
            k = int(np.argmax(np.diff(knots)))
            mid = 0.5 * (knots[k] + knots[k + 1])
            if direction == 0:
                bs.insertUKnot(mid, 1, 0.0)
            else:
                bs.insertVKnot(mid, 1, 0.0)


def insert_knots(bs: Any, extra: tuple[Any, Any]) -> None:
    """Exact refinement in place: one more knot at each of ``extra`` = (u values, v values) inside
    the domain that is not (within a millionth of a span) a knot already."""
    for direction, values in enumerate(extra):
        for x in sorted(float(x) for x in values):
            knots = np.asarray(bs.getUKnots() if direction == 0 else bs.getVKnots())
            close = 1e-6 * float(np.min(np.diff(knots)))
            if not knots[0] + close < x < knots[-1] - close or np.min(np.abs(knots - x)) <= close:
                continue
            if direction == 0:
                bs.insertUKnot(x, 1, 0.0)
            else:
                bs.insertVKnot(x, 1, 0.0)


def refined(surface: core.BSplineSurface, extra: tuple[Any, Any]) -> core.BSplineSurface:
    """``surface`` with knots ``extra`` inserted as :func:`insert_knots` does (exactly: the same
    shape on a finer net; two surfaces on the same knots refined with the same ``extra`` end on
    the same knots)."""
    from .part_surface import part_bspline
    nu, nv = surface.controls
    weights = None if surface.weights is None else np.asarray(surface.weights, float).reshape(nu, nv)
    bs = part_bspline(np.asarray(surface.poles, float).reshape(nu, nv, 3), np.asarray(surface.knots_u),
                      np.asarray(surface.knots_v), tuple(surface.degree), weights)
    insert_knots(bs, extra)
    return to_core(bs)


def to_core(bs: Any) -> core.BSplineSurface:
    nu, nv = bs.NbUPoles, bs.NbVPoles
    poles = np.array([[tuple(p) for p in row] for row in bs.getPoles()], dtype=float).reshape(nu, nv, 3)
    weights = np.array(bs.getWeights(), dtype=float).reshape(nu, nv)
    rational = bool(np.any(weights != weights.flat[0]))

    def full(knots: list[float], mults: list[int]) -> list[float]:
        return [k for k, m in zip(knots, mults) for _ in range(m)]
    return core.BSplineSurface(poles, (bs.UDegree, bs.VDegree),
                               full(bs.getUKnots(), bs.getUMultiplicities()),
                               full(bs.getVKnots(), bs.getVMultiplicities()),
                               weights if rational else None)


def _check_points(surface: core.BSplineSurface, n: int = 12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    (u0, u1), (v0, v1) = surface.domain
    us = u0 + (u1 - u0) * (np.arange(n) + 0.37) / n
    vs = v0 + (v1 - v0) * (np.arange(n) + 0.61) / n
    pts = np.array([[surface.evaluate(u, v)["point"] for v in vs] for u in us], dtype=float)
    return us, vs, pts


def _distance_to(geom: Any, points: np.ndarray) -> float:
    """Largest distance from points to the source's underlying surface (projection onto it)."""
    import FreeCAD
    import Part
    surf = geom if isinstance(geom, Part.BSplineSurface) else geom.Surface
    worst = 0.0
    for p in points.reshape(-1, 3):
        v = FreeCAD.Vector(*p)
        u, w = surf.parameter(v)
        worst = max(worst, (surf.value(u, w) - v).Length)
    return worst


def _fit(geom: Any, controls: tuple[int, int], degree: tuple[int, int]) -> core.BSplineSurface:
    """Least-squares fit with clamped uniform knots over the source's parameter rectangle."""
    import Part
    surf = geom if isinstance(geom, Part.BSplineSurface) else geom.Surface
    u0, u1, v0, v1 = geom.bounds() if isinstance(geom, Part.BSplineSurface) else geom.ParameterRange
    plane = core.BSplineSurface.plane(controls, degree, (1.0, 1.0))
    samples = (max(4 * controls[0], 16), max(4 * controls[1], 16))
    ds = core.DynamicSurface(plane, samples)
    indptr, indices, data, shape = ds.sampling_matrix()
    a = np.zeros(shape)
    rows = np.repeat(np.arange(shape[0]), np.diff(indptr))
    a[rows, indices] = data
    (pu0, pu1), (pv0, pv1) = plane.domain
    su = u0 + (np.asarray(ds.mesh_parameters_u) - pu0) / (pu1 - pu0) * (u1 - u0)
    sv = v0 + (np.asarray(ds.mesh_parameters_v) - pv0) / (pv1 - pv0) * (v1 - v0)
    target = np.array([tuple(surf.value(u, v)) for u in su for v in sv], dtype=float)
    poles, *_ = np.linalg.lstsq(a, target, rcond=None)
    knots_u, knots_v = plane.knots_u, plane.knots_v
    scale = lambda k, a0, a1, b0, b1: [b0 + (x - a0) / (a1 - a0) * (b1 - b0) for x in k]  # noqa: E731
    return core.BSplineSurface(poles.reshape(controls[0], controls[1], 3), degree,
                               scale(knots_u, pu0, pu1, u0, u1), scale(knots_v, pv0, pv1, v0, v1))


def source_surface(source: Any, controls: tuple[int, int], degree: tuple[int, int],
                   size: tuple[float, float], doc: Any = None, extra_knots: tuple[Any, Any] = ((), ()),
                   centre: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> SourceSurface:
    """The core surface for ``source`` (None: a flat ``size`` patch in XY centred at ``centre``) at
    the requested resolution; ``extra_knots`` (u values, v values) refine an exactly converted
    source further where asked."""
    if source is None:
        plane = core.BSplineSurface.plane(controls, degree, size)
        if any(centre):
            plane = core.BSplineSurface(np.asarray(plane.poles, float) + np.asarray(centre, float), plane.degree,
                                        plane.knots_u, plane.knots_v, plane.weights)
        return SourceSurface(plane, "plane", 0.0, f"plane {size[0]:g} x {size[1]:g}")
    geom, description = resolve_face(source, doc)
    bs = _exact_bspline(geom)
    if bs is not None and max(bs.UDegree, bs.VDegree) <= core.MAX_DEGREE:
        _refine(bs, controls, degree)
        insert_knots(bs, extra_knots)
        if max(bs.UDegree, bs.VDegree) <= core.MAX_DEGREE:
            surface = to_core(bs)
            _, _, pts = _check_points(surface)
            return SourceSurface(surface, "exact", _distance_to(geom, pts), description)
    surface = _fit(geom, controls, degree)
    _, _, pts = _check_points(surface)
    return SourceSurface(surface, "approximated", _distance_to(geom, pts), description)
