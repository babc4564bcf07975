"""Curves a sculpt must follow: exact linear conditions on its poles, held like held poles.

A curve is bound to the surface along its preimage ``(u_k, v_k)``, k = 1..K, the parameters of its
samples' closest points when it is added. With the weights fixed (the core never changes them) the
surface at a fixed parameter is linear in the poles, ``S(u_k, v_k) = a_k . P``, and so is its
derivative in a fixed direction ``S_d = d_k . P``. The constraint is then ``A P = B``:

- **G0**: ``a_k . P = C_k``, the curve's samples;
- **G1**: also ``S_d = D`` there, ``d`` the parameter direction across the curve and ``D`` the
  surface's derivative in it turned into the plane perpendicular to the normal asked for. The whole
  cross derivative is held (not only its normal part, which would tie x, y and z together), so the
  normal along the curve stays what it is (a designer's G1 edge holds its second row the same way).
  The derivative along the curve is left to G0: a curve a little off the surface's tangent does
  not conflict with it.

Adding one moves the poles as little as possible (least squares, minimal norm over the free poles)
so the conditions hold. Then ``r`` of the free poles near the curve follow the others:
``P_s = o + sum w P_m`` (:class:`core.DynamicSurface` links with an offset), chosen by column
pivoting among the poles that no other link depends on, so every stroke keeps the conditions in
every integrator: ``r`` is the number of pole moves that take the curve's samples away (measured
against the bending energy of the move, :data:`STIFF_SHARE`); the smooth moves that barely touch
them stay free, so the surface can rise right beside a curve across the net. Held poles and other links are substituted first. With more samples
than the surface has freedom along the curve (at least degree_u + degree_v + 1 per knot cell it
crosses), the surface keeps the whole curve, not only the samples, where the curve's restriction
is in its space (a line of the domain), and within the check's tolerance elsewhere.

Plain numpy, no FreeCAD but for reading a curve from a shape or a document object.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import core
from .thin_plate import bending_matrix

CONTINUITIES = ("G0", "G1")
#: The Sculpt's document property that holds its curve constraints (JSON).
PROPERTY = "CurveConstraints"
#: Curve constraint ids start here (penalty constraints count from 0 in the core).
FIRST_ID = 1_000_000
#: Points along the curve the surface is checked at (and the fewest conditions).
SAMPLES = 200
#: A curve farther than this share of the surface's size is refused rather than pulled onto.
MAX_DISTANCE_SHARE = 0.25
#: A curve that runs past the face's edge by more than this share of its size is off the face
#: (refused: following it would drag the edge out to it).
OFF_FACE_SHARE = 1e-4
#: G0 holds when the surface passes within this share of its size of the curve.
G0_SHARE = 1e-6
#: G1 holds when the normal along the curve is within this angle of the one asked for (degrees).
G1_DEGREES = 0.01
#: Link weights below this are rounding (dropped; the offsets absorb them).
_WEIGHT_FLOOR = 1e-12


class NetTooCoarse(ValueError):
    """The net cannot follow a curve within its tolerance where it runs (``uv``: the curve's
    preimage): knots inserted there give it the freedom (:func:`refinement_knots`)."""

    def __init__(self, curve: str, why: str, advice: str, uv: np.ndarray) -> None:
        super().__init__(f"curve: the surface cannot follow {curve}: {why}; {advice}")
        #: The curve named (its label and continuity), what keeps the net from it, its preimage.
        self.curve, self.why, self.uv = curve, why, uv
        #: The net holds the curve, but a finer one would do better beside it (room to move, a pull
        #: that stays local): curve_follow refines it too, and holds it on this one where none does.
        self.held_anyway = False
        #: How far the pull onto it reaches beside it (reach_beside), where that is what a finer net is for.
        self.reach: float | None = None


@dataclass
class CurveConstraint:
    """One curve constraint as the document stores it (JSON): its conditions and the poles that
    follow (``slaves``)."""

    id: int
    continuity: str
    label: str
    uv: np.ndarray                 # (K, 2) the preimage
    points: np.ndarray             # (K, 3) where the surface passes there
    tangents: np.ndarray | None = None     # (K, 3) G1: the curve's unit tangents there
    across: np.ndarray | None = None       # (K, 2) G1: the parameter direction across the curve
    derivatives: np.ndarray | None = None  # (K, 3) G1: the derivative held in it
    normal: list[float] | None = None      # G1: the normal asked for (None: the surface's own)
    slaves: list[int] = field(default_factory=list)
    tolerance: float | None = None         # mm, G0, asked for (None: G0_SHARE of the size, as before it was asked)

    def to_json(self) -> dict[str, Any]:
        """The JSON form (floats round-trip exactly)."""
        out: dict[str, Any] = {"id": self.id, "continuity": self.continuity, "label": self.label,
                               "uv": self.uv.tolist(), "points": self.points.tolist(), "slaves": list(self.slaves)}
        if self.tolerance is not None:
            out["tolerance"] = self.tolerance
        if self.continuity == "G1":
            out.update(tangents=self.tangents.tolist(), across=self.across.tolist(),
                       derivatives=self.derivatives.tolist(), normal=self.normal)
        return out

    @classmethod
    def from_json(cls, item: dict[str, Any]) -> "CurveConstraint":
        """From :meth:`to_json`'s form; ValueError naming what is malformed."""
        try:
            made = cls(int(item["id"]), str(item["continuity"]), str(item.get("label", "")),
                       _array(item["uv"], 2), _array(item["points"], 3), slaves=[int(i) for i in item["slaves"]],
                       tolerance=None if item.get("tolerance") is None else float(item["tolerance"]))
            if made.continuity == "G1":
                made.tangents, made.across = _array(item["tangents"], 3), _array(item["across"], 2)
                made.derivatives = _array(item["derivatives"], 3)
                made.normal = None if item.get("normal") is None else [float(x) for x in item["normal"]]
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"CurveConstraints: malformed curve constraint: {exc}") from exc
        if made.continuity not in CONTINUITIES or len(made.uv) != len(made.points):
            raise ValueError(f"CurveConstraints: malformed curve constraint {made.id}")
        return made


def _array(values: Any, width: int) -> np.ndarray:
    a = np.asarray(values, dtype=float)
    if a.ndim != 2 or a.shape[1] != width or not np.all(np.isfinite(a)):
        raise ValueError(f"expected finite rows of {width} numbers")
    return a


def records_from_json(text: str) -> list[CurveConstraint]:
    """The curve constraints stored in a ``CurveConstraints`` property ("" or a JSON list)."""
    if not text:
        return []
    try:
        items = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"CurveConstraints: malformed JSON ({exc})") from exc
    if not isinstance(items, list):
        raise ValueError("CurveConstraints: expected a JSON list")
    return [CurveConstraint.from_json(item) for item in items]


def records_of(sculpt: Any) -> list[CurveConstraint]:
    """The curve constraints a Sculpt holds (none for files from before them)."""
    return records_from_json(getattr(sculpt, PROPERTY, ""))


def records_to_json(records: list[CurveConstraint]) -> str:
    """The ``CurveConstraints`` property's text."""
    return json.dumps([r.to_json() for r in records], allow_nan=False) if records else ""


# --- the curve ----------------------------------------------------------------------------------

def curve_points(curve: Any, count: int) -> tuple[np.ndarray, str]:
    """``count`` points along ``curve`` and a label for it (see :func:`curve_samples`)."""
    points, _, label = curve_samples(curve, count)
    return points, label


def curve_samples(curve: Any, count: int) -> tuple[np.ndarray, np.ndarray, str]:
    """About ``count`` points along ``curve`` (by length), its unit tangents there (exact: from the
    curve, not from the points) and a label for it. ``curve`` is a document object with one edge or
    one wire (a Sketch, a Part feature, a Draft wire), one edge or wire of one as (the object,
    "Edge3" or "Wire2", as FreeCAD names a picked edge), a ``Part.Edge`` or ``Part.Wire``, or a list
    of points (the smooth curve through them)."""
    label = ""
    if isinstance(curve, tuple) and len(curve) == 2 and hasattr(curve[0], "Shape") and isinstance(curve[1], str):
        obj, name = curve
        kind, number = name.rstrip("0123456789"), name[len(name.rstrip("0123456789")):]
        elements = {"Edge": obj.Shape.Edges, "Wire": obj.Shape.Wires}.get(kind, [])
        if not number or not 1 <= int(number) <= len(elements):
            raise ValueError(f"curve: {obj.Label} has no {name!r} (it has {len(obj.Shape.Edges)} edges in "
                             f"{len(obj.Shape.Wires)} wires: give 'Edge1' to 'Edge{len(obj.Shape.Edges)}' or a wire)")
        label, curve = f"{obj.Label} {name}", elements[int(number) - 1]
    if hasattr(curve, "Shape") and hasattr(curve, "Document"):
        label = str(curve.Label)
        curve = curve.Shape
    if hasattr(curve, "ShapeType"):  # a Part shape
        shape = curve
        if shape.ShapeType not in ("Edge", "Wire"):
            wires, edges = list(getattr(shape, "Wires", [])), list(getattr(shape, "Edges", []))
            if len(wires) == 1 and len(wires[0].Edges) == len(edges):
                shape = wires[0]
            elif len(edges) == 1:
                shape = edges[0]
            else:
                raise ValueError(f"curve: {label or 'the shape'} has {len(edges)} edges in {len(wires)} wires; "
                                 "give one edge or one connected wire")
        if shape.Length <= 0:
            raise ValueError(f"curve: {label or 'the shape'} has no length")
        points, tangents = _shape_samples(shape, count)
        return points, tangents, label or shape.ShapeType
    try:
        points = np.asarray(curve, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TypeError("curve: expected a document object with one edge or wire, a Part.Edge or Part.Wire, "
                        f"or a list of points, not {type(curve).__name__}") from exc
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 2:
        raise ValueError(f"curve: expected at least two points (x, y, z), got an array of shape {points.shape}")
    if not np.all(np.isfinite(points)):
        raise ValueError("curve: the points contain NaN or Inf")
    step = np.linalg.norm(np.diff(points, axis=0), axis=1)
    points = points[np.concatenate([[True], step > 0])]  # (repeated points say nothing)
    if len(points) < 2:
        raise ValueError("curve: the points are all the same; a curve needs length")
    return (*_spline_through(points, count), "points")


def _shape_samples(shape: Any, count: int) -> tuple[np.ndarray, np.ndarray]:
    """About ``count`` points along an edge or a wire and the unit tangents there, each edge evenly
    by length and its ends among them: a corner between two edges is a point the surface passes
    through (its tangent there: the two sides' mean)."""
    edges = list(shape.OrderedEdges) if shape.ShapeType == "Wire" else [shape]
    total = sum(e.Length for e in edges)
    points: list[np.ndarray] = []
    tangents: list[np.ndarray] = []
    for e in edges:
        n = max(2, int(round((count - 1) * e.Length / total)) + 1)
        params = [e.FirstParameter] + [e.getParameterByLength(e.Length * k / (n - 1)) for k in range(1, n - 1)] \
            + [e.LastParameter]
        pts = np.array([tuple(e.valueAt(t)) for t in params], dtype=float)
        tan = np.array([tuple(e.tangentAt(t)) for t in params], dtype=float)
        if points:
            last = points[-1][-1]
            if np.linalg.norm(pts[-1] - last) < np.linalg.norm(pts[0] - last):
                pts, tan = pts[::-1], -tan[::-1]  # (an edge the wire runs through backwards)
            corner = tangents[-1][-1] + tan[0]
            tangents[-1][-1] = corner / max(float(np.linalg.norm(corner)), 1e-300)
            pts, tan = pts[1:], tan[1:]
        points.append(pts)
        tangents.append(tan)
    t = np.vstack(tangents)
    return np.vstack(points), t / np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-300)


def _spline_through(points: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` points along the natural cubic spline through ``points`` by chord length (a
    polyline's kinks are nothing a smooth surface could pass through), evenly in chord length, and
    its unit tangents there."""
    t = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    n = len(points)
    second = np.zeros((n, 3))
    if n > 2:  # M_i: h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1} = 6 (slope_i - slope_{i-1})
        h = np.diff(t)
        slope = np.diff(points, axis=0) / h[:, None]
        system = np.diag(2 * (h[:-1] + h[1:])) + np.diag(h[1:-1], 1) + np.diag(h[1:-1], -1)
        second[1:-1] = np.linalg.solve(system, 6 * np.diff(slope, axis=0))
    at = np.linspace(0.0, t[-1], count)
    k = np.clip(np.searchsorted(t, at, side="right") - 1, 0, n - 2)
    h = (t[k + 1] - t[k])[:, None]
    a, b = ((t[k + 1] - at)[:, None] / h), ((at - t[k])[:, None] / h)
    values = (a * points[k] + b * points[k + 1]
              + ((a ** 3 - a) * second[k] + (b ** 3 - b) * second[k + 1]) * h ** 2 / 6)
    slopes = ((points[k + 1] - points[k]) / h
              + (-(3 * a ** 2 - 1) * second[k] + (3 * b ** 2 - 1) * second[k + 1]) * h / 6)
    return values, slopes / np.linalg.norm(slopes, axis=1, keepdims=True)


# --- the surface at given parameters ------------------------------------------------------------

def _basis(knots: np.ndarray, p: int, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each parameter in x: its knot span k and the values and first derivatives of the p + 1
    basis functions N_{k-p..k} there, (K,), (K, p+1), (K, p+1) (Cox-de Boor, vectorised)."""
    n = len(knots) - p - 1
    x = np.clip(np.asarray(x, float), knots[p], knots[n])
    span = np.clip(np.searchsorted(knots, x, side="right") - 1, p, n - 1)
    count = len(x)
    values = np.zeros((count, p + 1))
    values[:, 0] = 1.0
    lower = values[:, :1].copy()
    for j in range(1, p + 1):
        if j == p:
            lower = values[:, :p].copy()  # degree p - 1, for the derivatives
        left = [x - knots[span + 1 - j + r] for r in range(j)]          # x - u_{k+1-j+r}
        right = [knots[span + 1 + r] - x for r in range(j)]             # u_{k+1+r} - x
        new = np.zeros((count, p + 1))
        saved = np.zeros(count)
        for r in range(j):
            denom = right[r] + left[r]
            temp = np.divide(values[:, r], denom, out=np.zeros(count), where=denom != 0)
            new[:, r] = saved + right[r] * temp
            saved = left[r] * temp
        new[:, j] = saved
        values = new
    ders = np.zeros((count, p + 1))
    for r in range(p + 1):
        i = span - p + r
        if r >= 1:
            d = knots[i + p] - knots[i]
            ders[:, r] += p * np.divide(lower[:, r - 1], d, out=np.zeros(count), where=d != 0)
        if r <= p - 1:
            d = knots[i + p + 1] - knots[i + 1]
            ders[:, r] -= p * np.divide(lower[:, r], d, out=np.zeros(count), where=d != 0)
    return span, values, ders


@dataclass
class Rows:
    """The surface and its first derivatives at K parameters as combinations of the poles: pole
    indices (K, m) and their coefficients for S, S_u and S_v (each (K, m))."""

    index: np.ndarray
    s: np.ndarray
    su: np.ndarray
    sv: np.ndarray

    def dense(self, coefficients: np.ndarray, poles: int) -> np.ndarray:
        """One of s, su, sv (or a combination) as a dense (K, poles) matrix."""
        out = np.zeros((len(coefficients), poles))
        np.add.at(out, (np.arange(len(coefficients))[:, None], self.index), coefficients)
        return out

    def apply(self, coefficients: np.ndarray, poles: np.ndarray) -> np.ndarray:
        """The combination of ``poles`` ((n, 3)) each row gives, (K, 3)."""
        return np.einsum("km,kmc->kc", coefficients, poles[self.index])


def rows(surface: Any, uv: np.ndarray) -> Rows:
    """:class:`Rows` of the B-spline ``surface`` (a ``core.BSplineSurface``) at parameters uv (K, 2),
    rational with its fixed weights: S = A / W, S_u = (A_u - W_u S) / W."""
    p, q = surface.degree
    nu, nv = surface.controls
    su_, nu_, du_ = _basis(np.asarray(surface.knots_u, float), p, uv[:, 0])
    sv_, nv_, dv_ = _basis(np.asarray(surface.knots_v, float), q, uv[:, 1])
    iu = su_[:, None] - p + np.arange(p + 1)[None, :]
    iv = sv_[:, None] - q + np.arange(q + 1)[None, :]
    index = (iu[:, :, None] * nv + iv[:, None, :]).reshape(len(uv), -1)
    weights = surface.weights
    w = np.ones((len(uv), (p + 1) * (q + 1))) if weights is None else np.asarray(weights, float).ravel()[index]
    a = (nu_[:, :, None] * nv_[:, None, :]).reshape(len(uv), -1) * w
    au = (du_[:, :, None] * nv_[:, None, :]).reshape(len(uv), -1) * w
    av = (nu_[:, :, None] * dv_[:, None, :]).reshape(len(uv), -1) * w
    total, total_u, total_v = (x.sum(axis=1, keepdims=True) for x in (a, au, av))
    s = a / total
    return Rows(index, s, (au - total_u * s) / total, (av - total_v * s) / total)


def nearest_mesh_parameters(dynamic: core.DynamicSurface, points: np.ndarray) -> np.ndarray:
    """The parameters of the mesh points nearest ``points`` (K, 3): where closest points start."""
    flat = np.asarray(dynamic.mesh, float).reshape(-1, 3)
    us, vs = np.asarray(dynamic.mesh_parameters_u), np.asarray(dynamic.mesh_parameters_v)
    nearest = np.array([int(np.argmin(((flat - x) ** 2).sum(axis=1))) for x in points])
    return np.column_stack([us[nearest // len(vs)], vs[nearest % len(vs)]])


def _projected(surface: Any, poles: np.ndarray, points: np.ndarray, start: np.ndarray,
               flat: np.ndarray) -> np.ndarray:
    """The parameters minimising |(S(u, v) - x) flat|^2 for each of ``points`` (K, 3): Gauss-Newton
    steps from ``start`` (K, 2), kept inside the domain. ``flat`` (3, 3) is the identity for the
    closest points, a projector across a direction for the points straight across along it."""
    uv = np.array(start, dtype=float)
    (u0, u1), (v0, v1) = surface.domain
    for _ in range(50):
        r = rows(surface, uv)
        s, su, sv = (r.apply(c, poles) @ flat for c in (r.s, r.su, r.sv))
        e = points @ flat - s
        g = np.stack([(su * su).sum(1), (su * sv).sum(1), (sv * sv).sum(1)], axis=1)
        b = np.stack([(su * e).sum(1), (sv * e).sum(1)], axis=1)
        det = g[:, 0] * g[:, 2] - g[:, 1] ** 2
        det = np.where(np.abs(det) > 0, det, 1.0)
        step = np.column_stack([(g[:, 2] * b[:, 0] - g[:, 1] * b[:, 1]) / det,
                                (g[:, 0] * b[:, 1] - g[:, 1] * b[:, 0]) / det])
        new = np.column_stack([np.clip(uv[:, 0] + step[:, 0], u0, u1), np.clip(uv[:, 1] + step[:, 1], v0, v1)])
        done = np.abs(new - uv).max() <= 1e-15
        uv = new
        if done:
            break
    return uv


def closest_parameters(surface: Any, poles: np.ndarray, points: np.ndarray, start: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The parameters of the surface's closest points to ``points`` (K, 3) and their distances,
    from ``start`` (K, 2)."""
    uv = _projected(surface, poles, points, start, np.eye(3))
    r = rows(surface, uv)
    return uv, np.linalg.norm(points - r.apply(r.s, poles), axis=1)


#: Where the surface's normals under a curve are within this (degrees) of the normal of the plane
#: its net lies nearest, the curve's points are taken across to the surface along that normal, not
#: to their closest points (see make()).
ACROSS_SPREAD_DEGREES = 60.0


def across_parameters(surface: Any, poles: np.ndarray, points: np.ndarray, start: np.ndarray,
                      direction: np.ndarray) -> tuple[np.ndarray, bool]:
    """The parameters of the surface's points straight across from ``points`` along ``direction``
    (a unit vector: the gap S(u, v) - x parallel to it), from ``start``; and whether every point
    found one (no gap left across the direction)."""
    flat = np.eye(3) - np.outer(direction, direction)  # (what of a vector lies across the direction)
    uv = _projected(surface, poles, points, start, flat)
    r = rows(surface, uv)
    left = np.linalg.norm((points - r.apply(r.s, poles)) @ flat, axis=1)
    return uv, bool(left.max() <= 1e-9 * max(1.0, float(np.abs(points).max())))


def _unit(vectors: np.ndarray, what: str) -> np.ndarray:
    """The vectors scaled to length 1; ValueError saying ``what`` is missing where one is (next to)
    zero: a degenerate surface or curve there."""
    length = np.linalg.norm(vectors, axis=1, keepdims=True)
    if not np.all(np.isfinite(length)) or length.min() <= 1e-12 * max(float(length.max()), 1e-300):
        raise ValueError(f"curve: {what}")
    return vectors / length


def normals(surface: Any, poles: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Unit normals S_u x S_v at uv (K, 2); ValueError where the surface has none (degenerate)."""
    r = rows(surface, uv)
    su, sv = r.apply(r.su, poles), r.apply(r.sv, poles)
    n = np.cross(su, sv)
    scale = np.linalg.norm(su, axis=1) * np.linalg.norm(sv, axis=1)
    if not np.all(np.linalg.norm(n, axis=1) > 1e-9 * scale):  # (S_u and S_v parallel, or one of them zero)
        raise ValueError("curve: the surface has no tangent plane somewhere along the curve (it is degenerate there)")
    return n / np.linalg.norm(n, axis=1, keepdims=True)


# --- conditions, the least move and the links ---------------------------------------------------

def conditions(surface: Any, record: CurveConstraint) -> tuple[np.ndarray, np.ndarray]:
    """The record's conditions A P = B over all poles: A (m, n), B (m, 3), each row scaled to unit
    norm (so a rank is a rank whatever the units)."""
    n = surface.controls[0] * surface.controls[1]
    r = rows(surface, record.uv)
    a, b = [r.dense(r.s, n)], [record.points]
    if record.continuity == "G1":
        d = record.across
        a.append(r.dense(d[:, :1] * r.su + d[:, 1:] * r.sv, n))
        b.append(record.derivatives)
    a_all, b_all = np.vstack(a), np.vstack(b)
    scale = np.linalg.norm(a_all, axis=1, keepdims=True)
    scale[scale == 0] = 1.0
    return a_all / scale, b_all / scale


def _substituted(a: np.ndarray, b: np.ndarray, poles: np.ndarray, held: list[int],
                 links: list[tuple[Any, ...]]) -> tuple[np.ndarray, np.ndarray]:
    """A and B over the free poles alone: a linked pole's column added onto its free masters (its
    offset and held masters into B), held poles' columns into B."""
    a, b = a.copy(), b.copy()
    held_set = set(held)
    for link in links:
        pole, masters = link[0], link[1]
        column = a[:, pole].copy()
        if not column.any():
            continue
        constant = np.asarray(link[2], float) if len(link) > 2 else np.zeros(3)
        for m, w in masters:
            if m in held_set:
                constant = constant + w * poles[m]
            else:
                a[:, m] += w * column
        b -= np.outer(column, constant)
        a[:, pole] = 0.0
    for h in held:
        if a[:, h].any():
            b -= np.outer(a[:, h], poles[h])
            a[:, h] = 0.0
    return a, b


def _pivots(a: np.ndarray, tolerance: float) -> list[int]:
    """Columns of a that span its column space, the largest remaining first (Gram-Schmidt with
    column pivoting)."""
    m = a.copy()
    norms = (m * m).sum(axis=0)
    chosen: list[int] = []
    while True:
        j = int(np.argmax(norms)) if norms.size else 0
        if not norms.size or norms[j] <= tolerance ** 2:
            return chosen
        q = m[:, j] / math.sqrt(norms[j])
        m -= np.outer(q, q @ m)
        norms = (m * m).sum(axis=0)
        norms[chosen + [j]] = 0.0
        chosen.append(j)


#: The most a pull onto a curve may move a pole, in multiples of the farthest the curve is from the
#: surface: a B-spline's poles stand a few times further out than the bump they make, and past
#: this the conditions' nearly blind directions are doing the work (a line over a clamped patch's
#: bump, its ends by the held tangent planes, threw poles 700 m and the GUI's view with them).
MOVE_PER_GAP = 10.0


def _least_move(a: np.ndarray, gap: np.ndarray, tolerance: float) -> np.ndarray:
    """The smallest pole move x with a x = gap to ``tolerance`` (largest row), leaving out the
    directions the conditions barely see (singular values below 1e-4, then 1e-6 ... 1e-12 of the
    largest, the first that reaches it) and never moving a pole more than MOVE_PER_GAP times the
    largest gap, each coordinate on its own: with the conditions as ill-conditioned as they are, a
    tiny gap along those (a curve a micrometre off the surface) would throw far poles by metres.
    Where no move within that reaches the tolerance, the last one within it (the caller finds it
    misses the curve: a finer net, or held poles freed, gives the freedom)."""
    u, singular, vt = np.linalg.svd(a, full_matrices=False)
    projected = u.T @ gap
    best = np.zeros((a.shape[1], gap.shape[1]))
    for c in range(gap.shape[1]):
        limit = MOVE_PER_GAP * np.abs(gap[:, c]).max() + tolerance
        for cut in (1e-4, 1e-6, 1e-8, 1e-10, 1e-12):
            keep = singular > cut * singular[0]
            move = vt[keep].T @ (projected[keep, c] / singular[keep])
            if np.abs(move).max() > limit:
                break
            best[:, c] = move
            if np.abs(a @ move - gap[:, c]).max() <= tolerance:
                break
    return best


#: A pole move is left free when it moves the curve's samples by less than this share of the most
#: any move of the same bending energy does (squared). The conditions of a curve across the net's
#: spans have full rank on every pole whose support it crosses (their singular values fall smoothly
#: to 1e-12): held exactly, a band four spans wide beside it is locked, and a pull 2 mm beside an
#: oblique line across a clamped clay patch moved nothing (0.00 mm). Measured in bending energy,
#: the moves the samples see least are the smooth ones: this frees 4 of its 32 links and the pull
#: lifts a smooth bump (0.37 mm, curvature under 0.003 1/mm), the line drifting 9e-7 mm after it
#: and 3e-6 mm after five. (1e-10 frees 7 and lifts 0.41 mm, but a G1 curve's normal drifted
#: 0.009 degrees in bench/curve_constraints.py, against the 0.01 allowed.)
STIFF_SHARE = 1e-12


def _stiff_moves(a: np.ndarray, bending: np.ndarray | None) -> np.ndarray:
    """Orthonormal rows spanning the pole moves the links hold: the generalised eigenvectors of
    (A^T A, K) whose eigenvalue (how far a move of unit bending energy takes the curve's samples)
    is above STIFF_SHARE of the largest, as rows of K (a move m is held when v^T K m = 0 for each
    of them: it lies in the span of the smooth moves that barely touch the curve). Without a
    bending energy (a net of degree 1 in a direction bends only at its knots) the conditions' whole
    row space: the moves left free would be any the samples barely see, not smooth ones."""
    if bending is None:
        _, singular, vt = np.linalg.svd(a, full_matrices=False)
        return vt[singular > 1e-12 * singular[0]]
    k = bending + 1e-9 * max(np.trace(bending), 1e-300) / len(bending) * np.eye(len(bending))
    lower = np.linalg.cholesky(k)  # (the touch: K is positive definite on any part of the net)
    whiten = np.linalg.solve(lower, a.T).T  # A L^-T
    _, singular, vt = np.linalg.svd(whiten, full_matrices=False)
    keep = singular ** 2 > STIFF_SHARE * singular[0] ** 2
    q, _ = np.linalg.qr(lower @ vt[keep].T)  # (K v = L L^T v = L w for v = L^-T w)
    return q.T


def fit(dynamic: core.DynamicSurface, records: list[CurveConstraint], held: list[int],
        links: list[tuple[Any, ...]], poles: np.ndarray) -> tuple[np.ndarray, list[tuple[Any, ...]]]:
    """Holds ``records``, together, on top of ``held`` and ``links``: the poles moved as little as
    possible so they hold (check with :func:`misses`) and the links that keep them ((pole,
    masters, offset), slaves among the free poles no other link depends on). Curves that cross
    share their conditions there, so they are solved as one system. ValueError where the slaves
    cannot be found (the poles there are held or linked)."""
    surface = dynamic.surface
    if not records:
        return poles, []
    stacked = [conditions(surface, r) for r in records]
    a, b = np.vstack([x for x, _ in stacked]), np.vstack([y for _, y in stacked])
    a, b = _substituted(a, b, poles, held, links)
    free = np.flatnonzero(np.abs(a).max(axis=0) > 0)
    if not free.size:
        return poles, []
    af = a[:, free]
    gap = b - af @ poles[free]
    gap[:, np.abs(gap).max(axis=0) <= 1e-12 * dynamic.size] = 0.0  # (rounding: a coordinate that holds stays)
    moved = poles.copy()
    if gap.any():
        moved[free] += _least_move(af, gap, 1e-2 * G0_SHARE * dynamic.size)
    # The moves the links forbid, orthonormal rows (Q): slaves picked among its columns keep the
    # link weights bounded however weakly a pole far from the curve takes part.
    basis = _stiff_moves(af, bending_matrix(surface, free) if min(surface.degree) >= 2 else None)
    rank = len(basis)
    masters = {m for link in links for m, _ in link[1]}
    eligible = np.array([i for i, pole in enumerate(free) if int(pole) not in masters], dtype=int)
    chosen = eligible[_pivots(basis[:, eligible], 1e-6)] if eligible.size else eligible
    if len(chosen) < rank:
        raise NetTooCoarse(f"'{records[-1].label}' there", f"{rank} conditions need {rank} free poles near it and only "
                           f"{len(chosen)} are not held or linked already", "free the edges near it, or use more controls",
                           records[-1].uv)
    chosen = chosen[:rank]
    rest = np.setdiff1d(np.arange(len(free)), chosen)
    # the slaves from the masters: Q_S P_S = c - Q_M P_M
    solved = np.linalg.solve(basis[:, chosen], basis[:, rest])
    weights = -solved
    weights[np.abs(weights) < _WEIGHT_FLOOR] = 0.0
    slaves = {int(free[c]) for c in chosen}
    linked = {link[0] for link in links}
    # a pole its conditions fix alone follows nothing but its offset: its link names some free pole
    # with weight 0 (a link needs a master)
    spare = next((i for i in range(len(poles)) if i not in slaves and i not in linked and i not in set(held)), None)
    made = []
    for k, c in enumerate(chosen):
        nonzero = np.flatnonzero(weights[k])
        pole = int(free[c])
        master_poles = free[rest[nonzero]]
        offset = moved[pole] - weights[k, nonzero] @ moved[master_poles]
        masters = [(int(m), float(w)) for m, w in zip(master_poles, weights[k, nonzero])]
        if not masters:
            if spare is None:
                # (a finer net has poles to spare: refined like any net too coarse)
                raise NetTooCoarse(f"'{records[-1].label}'", "no pole is left free to move (held edges and the curves "
                                   "it follows hold them all)", "free the edges near it (Hold edges), or give it more "
                                   "controls", records[-1].uv)
            masters = [(spare, 0.0)]
        made.append((pole, masters, tuple(float(x) for x in offset)))
    return moved, made


def misses(surface: Any, record: CurveConstraint, poles: np.ndarray) -> tuple[float, float]:
    """How far the surface with ``poles`` is from holding ``record`` at its samples: the largest
    distance (mm) and, G1, the largest angle (degrees) between its normal and the one held."""
    r = rows(surface, record.uv)
    distance = float(np.linalg.norm(r.apply(r.s, poles) - record.points, axis=1).max())
    if record.continuity != "G1":
        return distance, 0.0
    held = np.cross(record.tangents, record.derivatives)
    held /= np.linalg.norm(held, axis=1, keepdims=True)
    cosine = np.abs((normals(surface, poles, record.uv) * held).sum(axis=1))
    return distance, float(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))).max())


def relink(dynamic: core.DynamicSurface, records: list[CurveConstraint], held: list[int],
           links: list[tuple[Any, ...]], poles: np.ndarray) -> tuple[np.ndarray, list[tuple[Any, ...]]]:
    """Holds every record on top of ``held`` and ``links`` (the links that are not the curves'),
    after those changed or a record was removed: the poles (moved as little as possible where a
    record no longer held) and all links, ``links`` first. The records' ``slaves`` are updated.
    ValueError naming a curve that cannot hold."""
    moved, made = fit(dynamic, records, held, links, poles)
    size = dynamic.size
    for record in records:
        distance, degrees = misses(dynamic.surface, record, moved)
        if distance > G0_SHARE * size or degrees > G1_DEGREES:
            raise ValueError(f"curve: '{record.label}' (constraint {record.id}) cannot hold there: the surface would "
                             f"miss it by {distance:.3g} mm, {degrees:.3g} degrees (free the poles near it)")
    slaves = [link[0] for link in made]
    for record in records:
        record.slaves = slaves  # (the curves' links together: removing one relinks the rest)
    return moved, list(links) + made


def make(dynamic: core.DynamicSurface, curve: Any, continuity: str, normal: Any, cid: int, held: list[int],
         links: list[tuple[Any, ...]], records: list[CurveConstraint] = (), tolerance: float | None = None,
         edge: bool = False) -> tuple[CurveConstraint, np.ndarray, list[tuple[Any, ...]]]:
    """A new curve constraint on ``dynamic``, on top of ``held``, ``links`` (those that are not the
    curves') and the curves ``records`` it holds already: the record, the poles moved onto the curve
    and all links. ``tolerance``: how near the surface must pass the curve, everywhere along it (mm;
    None: G0_SHARE of the size). ``edge``: the curve is meant to be an edge of the surface (a
    patch made through a curve network pulls its edge onto it), so it may run past the face's edge.
    ValueError saying why where it cannot hold; NetTooCoarse where the net has too little freedom
    along the curve (a finer net may follow it)."""
    if continuity not in CONTINUITIES:
        raise ValueError(f"continuity: one of {', '.join(CONTINUITIES)}, not {continuity!r}")
    if normal is not None:
        if continuity != "G1":
            raise ValueError("normal: only a G1 curve constraint holds a normal")
        normal = np.asarray(normal, dtype=float).ravel()
        if normal.shape != (3,) or not np.all(np.isfinite(normal)) or np.linalg.norm(normal) == 0:
            raise ValueError(f"normal: expected a non-zero vector (x, y, z), got {normal.tolist()}")
        normal = normal / np.linalg.norm(normal)
    if dynamic.symmetry is not None:
        raise ValueError("curve: a mirrored sculpt cannot follow a curve yet (its links would have to be mirrored "
                         "too); remove the symmetry first")
    surface = dynamic.surface
    poles = np.asarray(dynamic.poles, float).reshape(-1, 3)
    size = dynamic.size
    if np.ptp(poles, axis=0).max() <= 1e-9 * size:
        raise ValueError("curve: the surface has collapsed to a point; nothing can follow a curve")
    points, label = curve_points(curve, SAMPLES)
    uv, distance = closest_parameters(surface, poles, points, nearest_mesh_parameters(dynamic, points))
    if distance.max() > MAX_DISTANCE_SHARE * size:
        raise ValueError(f"curve: '{label}' runs up to {distance.max():.3g} mm from the surface, more than a quarter "
                         f"of the surface's size ({size:.3g} mm); move it closer, or sculpt toward it first")
    if not edge:
        _on_the_face(surface, poles, points, uv, label, OFF_FACE_SHARE * size)
    p, q = surface.degree
    cells = len({(a, b) for a, b in zip(_basis(np.asarray(surface.knots_u, float), p, uv[:, 0])[0],
                                        _basis(np.asarray(surface.knots_v, float), q, uv[:, 1])[0])})
    count = max(SAMPLES, 2 * (p + q + 1) * cells)
    points, along, _ = curve_samples(curve, count)
    uv, _ = closest_parameters(surface, poles, points, nearest_mesh_parameters(dynamic, points))
    # Where the surface under the curve faces the way its net does (the normal of the plane the
    # poles lie nearest), each point is held straight across from it that way, and the pull onto
    # the curve is across the sheet. Its closest points lie on the slopes of a bump the curve passes
    # under, and the pull to them went sideways (poles thrown past a clamped patch's edge). Where
    # the surface turns away under it (a round), the closest points.
    facing = normals(surface, poles, uv)
    across = np.linalg.svd(poles - poles.mean(axis=0), full_matrices=False)[2][-1]
    across = across if across @ facing.mean(axis=0) >= 0 else -across
    if np.degrees(np.arccos(np.clip((facing @ across).min(), -1.0, 1.0))) <= ACROSS_SPREAD_DEGREES:
        straight, found = across_parameters(surface, poles, points, uv, across)
        if found:
            uv = straight
    dense, _ = curve_points(curve, 3 * count)  # (the check's points, between the conditions' samples too)
    record = CurveConstraint(cid, continuity, label, uv, points, normal=None if normal is None else normal.tolist(),
                             tolerance=tolerance)
    tolerance = G0_SHARE * size if tolerance is None else tolerance
    if continuity == "G1":
        record.tangents = along
        record.across, record.derivatives = _held_derivatives(surface, poles, uv, points, along, normal)
    records = list(records) + [record]
    moved, made = fit(dynamic, records, held, links, poles)
    for r in records:
        r.slaves = [link[0] for link in made]
    start = uv[np.clip(np.searchsorted(np.linspace(0, 1, len(uv)), np.linspace(0, 1, len(dense))), 0, len(uv) - 1)]
    _, gap = closest_parameters(surface, moved, dense, start)
    distance, degrees = misses(surface, record, moved)
    distance = max(distance, float(gap.max()))
    for other in records[:-1]:
        d, g = misses(surface, other, moved)
        if d > G0_SHARE * size or g > G1_DEGREES:
            raise ValueError(f"curve: '{label}' and '{other.label}' (constraint {other.id}) cannot both hold: where they "
                             f"meet they ask the surface for different places or normals")
    if distance > tolerance or degrees > G1_DEGREES:
        nu, nv = surface.controls
        raise NetTooCoarse(f"'{label}' {continuity}", f"with {nu} x {nv} controls it comes no closer than {distance:.3g} mm "
                           f"(tolerance {tolerance:.3g} mm)" + (f" and {degrees:.3g} degrees off the normal (tolerance "
                                                                 f"{G1_DEGREES:g} degrees)" if continuity == "G1" else ""),
                           "use more controls, or a curve nearer the surface or smoother", uv)
    return record, moved, list(links) + made


def _on_the_face(surface: Any, poles: np.ndarray, points: np.ndarray, uv: np.ndarray, label: str,
                 tolerance: float) -> None:
    """ValueError where the curve runs off the face: its closest points lie on the face's edge and
    it is away from them along the surface (past the edge), not across it (off the surface, where
    the surface is pulled onto it), by more than ``tolerance``."""
    (u0, u1), (v0, v1) = surface.domain
    eps = 1e-12 * max(u1 - u0, v1 - v0)
    edge = (np.abs(uv[:, 0] - u0) <= eps) | (np.abs(uv[:, 0] - u1) <= eps) | \
        (np.abs(uv[:, 1] - v0) <= eps) | (np.abs(uv[:, 1] - v1) <= eps)
    if not edge.any():
        return
    r = rows(surface, uv[edge])
    gap = points[edge] - r.apply(r.s, poles)
    n = normals(surface, poles, uv[edge])
    past = np.linalg.norm(gap - (gap * n).sum(axis=1, keepdims=True) * n, axis=1)
    if past.max() > tolerance:
        k = int(np.argmax(past))
        at = points[edge][k]
        raise ValueError(f"curve: '{label}' runs off the face, {past[k]:.3g} mm past its edge at "
                         f"({', '.join(f'{x:.4g}' for x in at)}); a curve to follow lies over the face (shorten it, "
                         "or sculpt a larger face)")


#: Room beside a followed curve: at points a span either side of it, the pole moves its links
#: leave free must move the surface by at least this share of what the free poles move it by
#: without them, or the net is refined there (curve_follow). A clamped 8 x 8 patch following an
#: arc near its held edges held it exactly with no refinement and no move left beside it (0: a
#: pull 15 mm inside the arc moved nothing; a fresh-eyes GUI session). Lines that pass the fold
#: test keep 0.019 (oblique across a 10 x 10 net) and 0.81 (along it).
ROOM_SHARE = 0.005
#: Curve points at which the room beside it is measured (both sides of each).
ROOM_POINTS = 24


def room_beside(surface: Any, uv: np.ndarray, held: list[int], links: list[tuple[Any, ...]]) -> float:
    """The least share, over points a span either side of a curve whose preimage is ``uv``, of how
    far a pull there can move the surface: the sum of what each pole move the ``held`` poles and
    ``links`` leave free (its slaves following it) moves the point, against the sum without the
    links. 1 where the curve takes no freedom there, 0 where it pins the surface. Points whose
    poles are mostly held (nothing moves there anyway) and points off the face are left out."""
    nu, nv = surface.controls
    n = nu * nv
    held_set = {int(h) for h in held}
    slaves = {int(link[0]): link[1] for link in links}
    free = [i for i in range(n) if i not in held_set and i not in slaves]
    column = {pole: k for k, pole in enumerate(free)}
    moves = np.zeros((n, len(free)))  # each pole's move for each free pole's unit move
    moves[free, np.arange(len(free))] = 1.0
    for slave, masters in slaves.items():
        for master, weight in masters:
            if int(master) in column:
                moves[slave, column[int(master)]] += weight
    sampled = np.linspace(0, len(uv) - 1, min(ROOM_POINTS, len(uv))).astype(int)
    at, tangent = uv[sampled], np.gradient(uv, axis=0)[sampled]
    p, q = surface.degree
    knots = (np.asarray(surface.knots_u, float), np.asarray(surface.knots_v, float))
    width = np.empty_like(at)
    for d, k in enumerate(knots):
        breaks = np.unique(k)
        span = np.clip(np.searchsorted(breaks, at[:, d], side="right") - 1, 0, len(breaks) - 2)
        width[:, d] = breaks[span + 1] - breaks[span]
    t = tangent / width  # (in spans)
    length = np.linalg.norm(t, axis=1)
    keep = length > 0
    across = np.column_stack([-t[keep, 1], t[keep, 0]]) / length[keep, None] * width[keep]
    beside = np.vstack([at[keep] + across, at[keep] - across])
    low, high = np.array([knots[0][p], knots[1][q]]), np.array([knots[0][-p - 1], knots[1][-q - 1]])
    beside = beside[np.all((beside >= low) & (beside <= high), axis=1)]
    if not len(beside):
        return 1.0
    r = rows(surface, beside)
    basis = r.dense(r.s, n)
    unheld = np.ones(n, bool)
    unheld[list(held_set)] = False
    without = basis[:, unheld].sum(axis=1)
    inside = without > 0.5
    if not inside.any():
        return 1.0
    return float((np.abs(basis[inside] @ moves).sum(axis=1) / without[inside]).min())


#: A pull onto a curve stays local when, far beside the curve, it moves the surface at most this
#: share of the largest pull at the curve (or the tolerance, if more). Far: REACH_WIDTH_PER_PULL
#: times the pull away in mm, and two knot spans away (the least pole move leaves a constant share
#: there on every net, measured 0.045 at two spans and 0.55 at one, so a finer net pulls over less
#: of the surface) or REACH_SIZE_SHARE of the surface's size away, whatever the spans (a line along
#: a bump's crest flattened its flanks one 20 mm span beside it); where the surface stands off its
#: plane by more than REACH_SHARE of the pull (earlier work).
REACH_SHARE = 0.1
#: A finer net is kept for its reach only when it brings the reach down to this share of the net's
#: as it was: where the curve encloses the far surface (a U over a flat patch lifts its inside on
#: every net), refining does not help, and the net is kept as it was.
REACH_GAIN = 0.7
REACH_SIZE_SHARE = 0.1
#: Nearer than this many times the pull is not far: a pull steeper than that is a trench any net
#: makes, and refining for it would not end.
REACH_WIDTH_PER_PULL = 1.5
#: Samples per knot span (each direction) where the reach is measured, and at most in all.
REACH_SAMPLES_PER_SPAN, REACH_SAMPLES_MAX = 4, 64


def reach_beside(surface: Any, uv: np.ndarray, before: np.ndarray, moved: np.ndarray, tolerance: float,
                 size: float) -> float:
    """How far the pull from poles ``before`` to ``moved`` onto a curve whose preimage is ``uv``
    reaches beside the curve: the largest move of the surface far from it (see REACH_SHARE; ``size``:
    the surface's), as a share of the largest move at the curve (0 where nothing far moves more than
    ``tolerance``). More than REACH_SHARE: the pull takes earlier work far beside the curve with it
    (a bump flattened by a line across it), and a finer net keeps it local."""
    delta = np.asarray(moved, float).reshape(-1, 3) - np.asarray(before, float).reshape(-1, 3)
    uv = uv[np.linspace(0, len(uv) - 1, min(len(uv), SAMPLES)).astype(int)]
    on = rows(surface, uv)
    pull = np.linalg.norm(on.apply(on.s, delta), axis=1).max(initial=0.0)
    if pull <= tolerance:
        return 0.0
    p, q = surface.degree
    breaks = [np.unique(np.asarray(k, float)[d:len(k) - d]) for k, d in ((surface.knots_u, p), (surface.knots_v, q))]
    counts = [min(REACH_SAMPLES_MAX, REACH_SAMPLES_PER_SPAN * (len(b) - 1) + 1) for b in breaks]
    gu, gv = np.meshgrid(np.linspace(breaks[0][0], breaks[0][-1], counts[0]),
                         np.linspace(breaks[1][0], breaks[1][-1], counts[1]), indexing="ij")
    grid = np.column_stack([gu.ravel(), gv.ravel()])

    def in_spans(at: np.ndarray) -> np.ndarray:  # (parameters counted in knot spans)
        return np.column_stack([np.interp(at[:, d], breaks[d], np.arange(len(breaks[d]))) for d in (0, 1)])

    spans_away = np.min(np.linalg.norm(in_spans(grid)[:, None, :] - in_spans(uv)[None, :, :], axis=2), axis=1)
    there = rows(surface, grid)
    on_curve = on.apply(on.s, np.asarray(moved, float).reshape(-1, 3))
    was = there.apply(there.s, np.asarray(before, float).reshape(-1, 3))
    mm_away = np.min(np.linalg.norm(was[:, None, :] - on_curve[None, :, :], axis=2), axis=1)
    far = (mm_away >= REACH_WIDTH_PER_PULL * pull) & ((spans_away >= 2.0) | (mm_away >= REACH_SIZE_SHARE * size))
    # Only where there is earlier work to lose: relief off the plane the surface lies nearest (a
    # fresh flat patch lifted onto a standing arc rises broadly and fair; refined for reach, it rose
    # as a narrow, rippled ridge).
    centre = was.mean(axis=0)
    height = (was - centre) @ np.linalg.svd(was - centre, full_matrices=False)[2][-1]
    far &= np.abs(height - np.median(height)) > REACH_SHARE * pull
    if not far.any():
        return 0.0
    reach = np.linalg.norm(there.apply(there.s, delta)[far], axis=1).max()
    return float(reach / pull) if reach > tolerance else 0.0


def refinement_knots(surface: Any, uv: np.ndarray, room: tuple[int, int]) -> tuple[list[float], list[float]]:
    """Knots (u, v) that give the net freedom along a curve whose preimage is ``uv``: the midpoints
    of the spans it crosses (those with the most of its samples first) and then of their
    neighbours, at most ``room`` per direction."""
    out: tuple[list[float], list[float]] = ([], [])
    for d, knots in enumerate((surface.knots_u, surface.knots_v)):
        breaks = np.unique(np.asarray(knots, float))
        if room[d] <= 0 or len(breaks) < 2:
            continue
        spans = np.clip(np.searchsorted(breaks, uv[:, d], side="right") - 1, 0, len(breaks) - 2)
        count = np.bincount(spans, minlength=len(breaks) - 1)
        crossed = [int(k) for k in np.argsort(-count, kind="stable") if count[k] > 0]
        near = sorted({k + j for k in crossed for j in (-1, 1)} - set(crossed))
        chosen = [k for k in crossed + near if 0 <= k < len(breaks) - 1][: room[d]]
        out[d].extend(float(0.5 * (breaks[k] + breaks[k + 1])) for k in sorted(chosen))
    return out


def _held_derivatives(surface: Any, poles: np.ndarray, uv: np.ndarray, points: np.ndarray, t: np.ndarray,
                      normal: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """G1: per sample the parameter direction across the curve (K, 2) and the derivative to hold
    in it (K, 3): the surface's, turned into the plane perpendicular to the normal held (``normal``,
    or the surface's own, turned perpendicular to the curve where the curve leaves its tangent
    plane: the nearest normal a surface through the curve can have). ValueError where the curve
    leaves the plane perpendicular to ``normal``. ``t``: the curve's unit tangents."""
    current = normals(surface, poles, uv)
    if normal is None:  # (where the curve runs in the tangent plane already the normal stays as it is)
        along = (current * t).sum(axis=1, keepdims=True)
        n = current - np.where(np.abs(along) > 1e-7, along, 0.0) * t
    else:
        off = np.degrees(np.arcsin(np.clip(np.abs(t @ normal), 0.0, 1.0)))
        if off.max() > G1_DEGREES:
            k = int(np.argmax(off))
            raise ValueError(f"normal: the curve leaves the plane perpendicular to it by {off[k]:.3g} degrees at "
                             f"({', '.join(f'{x:.4g}' for x in points[k])}), so no surface along it can have that normal")
        n = np.tile(normal, (len(points), 1))
    n = _unit(n, "the curve runs along the surface's normal somewhere (it leaves the surface there)")
    n *= np.sign((n * current).sum(axis=1, keepdims=True) + 1e-300)
    r = rows(surface, uv)
    su, sv = r.apply(r.su, poles), r.apply(r.sv, poles)
    want = np.cross(n, t)  # (across the curve in the plane held)
    g = np.stack([(su * su).sum(1), (su * sv).sum(1), (sv * sv).sum(1)], axis=1)
    b = np.stack([(su * want).sum(1), (sv * want).sum(1)], axis=1)
    det = g[:, 0] * g[:, 2] - g[:, 1] ** 2  # (> 0: the normals exist)
    across = _unit(np.column_stack([g[:, 2] * b[:, 0] - g[:, 1] * b[:, 1], g[:, 0] * b[:, 1] - g[:, 1] * b[:, 0]])
                   / det[:, None], "the curve has no direction somewhere (a cusp or a point repeated)")
    now = across[:, :1] * su + across[:, 1:] * sv
    return across, now - (now * n).sum(axis=1, keepdims=True) * n
