"""A face of a solid seen from its own parameter space, so it can be sculpted in place: its edges
as curves in (u, v), the poles that hold them (G0: the surface stays on the edge; G1: its tangent
planes along it too; G2, G3: its curvature across it and that curvature's rate), the sculpted surface bounded by the face's own wires (outer wire and holes,
mapped through (u, v): the mass points move, the parameterisation does not), and the solid sewn
back around it, with a report of how well each seam holds (gap, normal angle, and the jump of the
normal curvature across each edge).

All of it works on the face's exact B-spline form (``Face.toNurbs``), whose parameter space is the
one the sculpt surface is made in (see :mod:`source_surface`), so a trim curve in (u, v) is valid on
the sculpted surface as it is.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

#: Points per edge where the held poles are found (every basis function that is not zero at one
#: of them is held), and where the seams are measured (the issue's 100 per seam).
HOLD_SAMPLES = 400
SEAM_SAMPLES = 100
SIDES = ("u0", "u1", "v0", "v1")
#: How an edge may be held: not at all, in place (G0), in place with its tangent planes (G1), and
#: its curvature across it (G2) and that curvature's rate (G3): as the base met its neighbour.
KINDS = ("free", "G0", "G1", "G2", "G3")
TANGENT = ("G1", "G2", "G3")  # the kinds that hold the tangent planes


@dataclass(frozen=True)
class FaceEdge:
    """One edge of a face, as the face sees it."""

    name: str                    #: the solid's name for it ("Edge3")
    side: str | None             #: "u0", "u1", "v0" or "v1" when it lies on that side of the
    #:                              face's parameter rectangle; None for a trim inside it
    uv: np.ndarray               #: (n, 2) points of its curve(s) in the face's (u, v) (a seam: both)
    neighbours: tuple[str, ...]  #: the other faces of the solid on it; the face itself for a seam


def nurbs_face(face: Any) -> Any:
    """The face in its exact B-spline form, with its pcurves (the parameter space sculpted in)."""
    return face.toNurbs().Faces[0]


def edge_name(shape: Any, edge: Any) -> str:
    """The solid's name of one of its edges."""
    for k, e in enumerate(shape.Edges):
        if e.isSame(edge):
            return f"Edge{k + 1}"
    raise ValueError("the edge is not part of the shape")


def _matching_edge(edges: list[Any], converted: Any) -> Any:
    """The original edge the B-spline conversion made ``converted`` from (same points)."""
    a, b = converted.ParameterRange
    probe = [converted.valueAt(a + (b - a) * t) for t in (0.0, 0.37, 1.0)]
    best, err = None, np.inf
    for e in edges:
        d = max(e.distToShape(_vertex(p))[0] for p in probe)
        if d < err:
            best, err = e, d
    return best


def _vertex(p: Any) -> Any:
    import Part
    return Part.Vertex(p)


def named_occurrences(shape: Any, face_name: str, nface: Any) -> list[tuple[str, Any]]:
    """Every edge occurrence of the converted face's wires, oriented as in the face (a seam
    appears twice), with the solid's name of the edge it was converted from."""
    originals = list(shape.getElement(face_name).Edges)
    return [(edge_name(shape, _matching_edge(originals, occ)), occ) for w in nface.Wires for occ in w.OrderedEdges]


def _pcurve_points(nface: Any, edge: Any, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(n, 2) points of the edge's curve in the face's (u, v), and the curve parameters they are at."""
    c2d, a, b = nface.curveOnSurface(edge)
    ts = np.linspace(a, b, n)
    points = [c2d.value(t) for t in ts]
    return np.array([(p.x, p.y) for p in points], float), ts


def face_edges(shape: Any, face_name: str) -> list[FaceEdge]:
    """The edges of ``shape``'s face ``face_name``, in (u, v), with the faces on their other side."""
    nface = nurbs_face(shape.getElement(face_name))
    u0, u1, v0, v1 = nface.ParameterRange
    tol_u, tol_v = 1e-9 * max(1.0, u1 - u0), 1e-9 * max(1.0, v1 - v0)
    found: dict[str, list[np.ndarray]] = {}
    for name, occ in named_occurrences(shape, face_name, nface):
        found.setdefault(name, []).append(_pcurve_points(nface, occ, HOLD_SAMPLES)[0])
    edges = []
    faces = [(f"Face{k + 1}", f) for k, f in enumerate(shape.Faces)]
    for name, parts in found.items():
        uv = np.concatenate(parts)
        side = None
        if len(parts) == 1:
            for s, col, at, tol in (("u0", 0, u0, tol_u), ("u1", 0, u1, tol_u), ("v0", 1, v0, tol_v), ("v1", 1, v1, tol_v)):
                if np.all(np.abs(uv[:, col] - at) <= tol):
                    side = s
        edge = shape.getElement(name)
        others = tuple(n for n, f in faces if n != face_name and any(e.isSame(edge) for e in f.Edges))
        edges.append(FaceEdge(name, side, uv, others if others else (face_name,)))
    return sorted(edges, key=lambda e: int(e.name[4:]))


# --- the poles that hold an edge -------------------------------------------------------------------
def basis_derivatives(knots: np.ndarray, p: int, x: float, k: int, n: int) -> np.ndarray:
    """The values and derivatives up to order n of the p + 1 basis functions N_{k-p..k} of span k
    at x, as an (n + 1, p + 1) array (Piegl & Tiller, The NURBS Book, A2.3)."""
    ndu = np.zeros((p + 1, p + 1))  # ndu[j][r]: degree-j values; ndu[r][j] (r > j): knot differences
    ndu[0, 0] = 1.0
    left, right = np.zeros(p + 1), np.zeros(p + 1)
    for j in range(1, p + 1):
        left[j] = x - knots[k + 1 - j]
        right[j] = knots[k + j] - x
        saved = 0.0
        for r in range(j):
            ndu[j, r] = right[r + 1] + left[j - r]
            temp = ndu[r, j - 1] / ndu[j, r] if ndu[j, r] else 0.0
            ndu[r, j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j, j] = saved
    n = min(n, p)
    ders = np.zeros((n + 1, p + 1))
    ders[0] = ndu[:, p]

    def over(a: float, b: float) -> float:
        return a / b if b else 0.0
    for r in range(p + 1):
        a = np.zeros((2, p + 1))
        s1, s2 = 0, 1
        a[0, 0] = 1.0
        for kk in range(1, n + 1):
            d = 0.0
            rk, pk = r - kk, p - kk
            if r >= kk:
                a[s2, 0] = over(a[s1, 0], ndu[pk + 1, rk])
                d = a[s2, 0] * ndu[rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = kk - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[s2, j] = over(a[s1, j] - a[s1, j - 1], ndu[pk + 1, rk + j])
                d += a[s2, j] * ndu[rk + j, pk]
            if r <= pk:
                a[s2, kk] = over(-a[s1, kk - 1], ndu[pk + 1, r])
                d += a[s2, kk] * ndu[r, pk]
            ders[kk, r] = d
            s1, s2 = s2, s1
    factor = p
    for kk in range(1, n + 1):
        ders[kk] *= factor
        factor *= p - kk
    return ders


def _active(knots: np.ndarray, p: int, x: float, order: int) -> set[int]:
    """Basis functions that are not zero at x, or whose derivatives up to ``order`` are not (the
    surface's value, tangent plane, curvature and its rate there depend on those alone); at an
    interior knot from both sides (a derivative may jump there)."""
    n = len(knots) - p - 1
    right = min(max(int(np.searchsorted(knots, x, side="right") - 1), p), n - 1)
    spans = {right}
    left = int(np.searchsorted(knots, x, side="left") - 1)
    if p <= left < right:
        spans.add(left)
    out: set[int] = set()
    for k in spans:
        ders = basis_derivatives(knots, p, x, k, order)
        for d in range(len(ders)):
            scale = max(1.0, float(np.max(np.abs(ders[d]))))
            out.update(k - p + r for r in range(p + 1) if abs(ders[d, r]) > 1e-12 * scale)
    return out


def held_poles(knots_u: np.ndarray, knots_v: np.ndarray, degree: tuple[int, int], controls: tuple[int, int],
               edges: list[FaceEdge], kinds: dict[str, str]) -> list[int]:
    """The pole indices (i * nv + j) to hold so that each edge keeps its kind exactly: G0 holds every
    pole whose basis function is not zero somewhere on the edge (the surface there depends on those
    alone), G1 also those whose derivative is not zero there (the tangent plane along it), G2 and
    G3 those whose second and third derivatives are not (the curvature along it and its rate)."""
    nv = controls[1]
    p, q = degree
    held: set[int] = set()
    found: dict[tuple[int, float, int], frozenset[int]] = {}  # (an edge on a side: one of u, v the same throughout)

    def active(direction: int, x: float, order: int) -> frozenset[int]:
        key = (direction, x, order)
        if key not in found:
            found[key] = frozenset(_active(knots_v if direction else knots_u, q if direction else p, x, order))
        return found[key]

    for e in edges:
        kind = kinds[e.name]
        if kind == "free":
            continue
        order = KINDS.index(kind) - 1
        pairs: set[tuple[frozenset[int], frozenset[int]]] = set()
        for u, v in e.uv:
            pairs.add((active(0, float(u), order), active(1, float(v), order)))
        for iu, jv in pairs:
            held.update(i * nv + j for i in iu for j in jv)
    return sorted(held)


# --- the sculpted face and the solid around it --------------------------------------------------
def trimmed_face(surface: Any, nface: Any) -> Any:
    """A face on ``surface`` (a Part.BSplineSurface in ``nface``'s parameter space) bounded by
    ``nface``'s wires: each edge rebuilt from its curve in (u, v), holes kept, orientation kept."""
    import Part
    wires = []
    for w in nface.Wires:
        edges = []
        for occ in w.OrderedEdges:
            c2d, a, b = nface.curveOnSurface(occ)
            edge = c2d.toShape(surface, a, b)
            if occ.Orientation == "Reversed":
                edge.reverse()
            edges.append(edge)
        wires.append(Part.Wire(edges))
    outer = nface.OuterWire
    order = sorted(range(len(wires)), key=lambda k: not nface.Wires[k].isSame(outer))
    face = Part.Face(surface, wires[order[0]])
    if len(order) > 1:
        face.cutHoles([wires[k] for k in order[1:]])
    face.fix(1e-7, 1e-7, 1e-4)
    if nface.Orientation == "Reversed":
        face.reverse()
    if not face.isValid():
        raise RuntimeError("the sculpted face bounded by the original wires is not a valid face")
    return face


def solid_with(shape: Any, replaced: dict[str, Any], tolerance: float = 1e-6) -> Any:
    """``shape`` (a solid) with faces ``replaced`` ({"FaceN": new face}), sewn into one closed
    shell and made a valid solid again; raises RuntimeError saying what did not close."""
    import Part
    kept = [f for k, f in enumerate(shape.Faces) if f"Face{k + 1}" not in replaced]
    sewn = Part.Compound(kept + list(replaced.values()))
    sewn.sewShape(tolerance)
    shells = sewn.Shells
    if len(shells) != 1 or not shells[0].isClosed():
        free = [] if not shells else [e for e in shells[0].Edges if len(shells[0].ancestorsOfType(e, Part.Face)) < 2]
        raise RuntimeError(f"the sculpted faces do not close the solid: {len(shells)} shell(s), "
                           f"{len(free)} free edge(s) after sewing at {tolerance:g} mm")
    solid = Part.Solid(shells[0])
    if solid.Volume < 0:
        solid.reverse()
    if not solid.isValid():
        raise RuntimeError("the rebuilt solid is not valid")
    if len(solid.Faces) != len(shape.Faces):
        raise RuntimeError(f"the rebuilt solid has {len(solid.Faces)} faces, the base {len(shape.Faces)}")
    return solid


# --- curvature across an edge (g2_pct) --------------------------------------------------------------
#: |kappa| below 1 / (CURVATURE_FLOOR * size) (size: the base solid's bounding-box diagonal, mm)
#: counts as that floor in ``g2_pct``: two flat sides give 0 %, not 0/0.
CURVATURE_FLOOR = 1000.0
_SECOND_ORDER = ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2))  # Su, Sv, Suu, Suv, Svv


def surface_derivatives(surface: Any, uv: np.ndarray) -> np.ndarray:
    """Su, Sv, Suu, Suv and Svv of ``surface`` (any Part surface) at the (n, 2) points ``uv``, as an
    (n, 5, 3) array (``getDN``: FreeCAD evaluates one point at a time)."""
    uv = np.asarray(uv, float).reshape(-1, 2)
    dn = surface.getDN
    flat = np.fromiter((x for u, v in uv.tolist() for a, b in _SECOND_ORDER for d in (dn(u, v, a, b),)
                        for x in (d.x, d.y, d.z)), float, count=15 * len(uv))  # (a third faster than tuples)
    return flat.reshape(len(uv), 5, 3)


def _unit(vectors: np.ndarray) -> np.ndarray:
    """Rows scaled to length 1 (NaN where a row is zero: a singular point, left out later)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)


def normal_curvature(derivatives: np.ndarray, normal: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """The normal curvature of a surface in the tangent direction ``direction`` at n points:
    ``direction`` = Su a + Sv b solved for (a, b) by least squares (the curve through the point
    along the straight (u, v) line (a, b) has that tangent, and second derivative Suu a^2 +
    2 Suv a b + Svv b^2, Meusnier), then kappa = normal . (Suu a^2 + 2 Suv a b + Svv b^2) /
    |direction|^2.

    ``derivatives``: (n, 5, 3) Su, Sv, Suu, Suv, Svv (see :func:`surface_derivatives`);
    ``normal``: (n, 3) unit normals, oriented as the caller wants the sign (a sphere of radius r
    with its outward normal gives -1/r: the surface bends away from it); ``direction``: (n, 3),
    not zero. Returns (n,) curvatures (1/mm); NaN where the first derivatives are parallel."""
    d = np.asarray(derivatives, float)
    n = np.asarray(normal, float)
    t = np.asarray(direction, float)
    if d.ndim != 3 or d.shape[1:] != (5, 3) or n.shape != (len(d), 3) or t.shape != (len(d), 3):
        raise ValueError(f"normal_curvature: derivatives (n, 5, 3), normal and direction (n, 3); got "
                         f"{d.shape}, {n.shape}, {t.shape}")
    su, sv, suu, suv, svv = (d[:, k] for k in range(5))
    g11, g12, g22 = (np.einsum("ij,ij->i", x, y) for x, y in ((su, su), (su, sv), (sv, sv)))
    r1, r2 = np.einsum("ij,ij->i", su, t), np.einsum("ij,ij->i", sv, t)
    with np.errstate(invalid="ignore", divide="ignore"):
        det = g11 * g22 - g12 * g12  # (the 2 x 2 normal equations, solved in closed form)
        a = (g22 * r1 - g12 * r2) / det
        b = (g11 * r2 - g12 * r1) / det
        second = suu * (a * a)[:, None] + 2.0 * suv * (a * b)[:, None] + svv * (b * b)[:, None]
        return np.einsum("ij,ij->i", n, second) / np.einsum("ij,ij->i", t, t)


def curvature_across(surface: Any, uv: np.ndarray, sign: float, tangents: np.ndarray,
                     derivatives: np.ndarray | None = None) -> np.ndarray:
    """The normal curvature of ``surface`` at the (n, 2) points ``uv`` across an edge with the (n, 3)
    unit ``tangents``: in the direction normal x tangent, the normal oriented by ``sign`` (-1 for a
    Reversed face). Oriented so, two faces meeting smoothly on a closed solid have the same normal
    there, hence the same direction across and curvatures of the same sign. ``derivatives``: the
    surface's at ``uv`` when the caller has them already (see :func:`surface_derivatives`)."""
    d = surface_derivatives(surface, uv) if derivatives is None else derivatives
    normal = sign * _unit(np.cross(d[:, 0], d[:, 1]))
    return normal_curvature(d, normal, np.cross(normal, tangents))


def curvature_jump_pct(kappa_a: np.ndarray, kappa_b: np.ndarray, floor: float) -> float | None:
    """The largest |kappa_a - kappa_b| as a percentage of the larger |kappa| of the two at that
    point, |kappa| below ``floor`` counting as ``floor``; None when no point could be measured."""
    ka, kb = np.asarray(kappa_a, float), np.asarray(kappa_b, float)
    scale = np.maximum(np.maximum(np.abs(ka), np.abs(kb)), floor)
    jump = 100.0 * np.abs(ka - kb) / scale
    jump = jump[np.isfinite(jump)]
    return float(jump.max()) if jump.size else None


def _curvature_floor(shape: Any) -> float:
    return 1.0 / (CURVATURE_FLOOR * max(shape.BoundBox.DiagonalLength, 1e-300))


def _edge_samples(occ: Any, ts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) points and unit tangents of an edge at its parameters ``ts``."""
    points = np.array([tuple(occ.valueAt(t)) for t in ts], float)
    tangents = _unit(np.array([tuple(occ.tangentAt(t)) for t in ts], float))
    return points, tangents


def _other_face(shape: Any, face_name: str, edge: Any) -> Any:
    """The face of ``shape`` (oriented as in it) on the other side of ``edge`` from ``face_name``;
    None if there is none."""
    own = shape.getElement(face_name)
    return next((f for f in shape.Faces if not f.isSame(own) and any(e.isSame(edge) for e in f.Edges)), None)


def _uv_on(face: Any, edge: Any, occ: Any, ts: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(n, 2) points of ``face``'s own (u, v) on ``edge`` where the converted edge ``occ`` is at its
    parameters ``ts`` (``points``): through the face's pcurve of the edge, at the same parameter when
    the conversion kept it (lines, B-splines), else at the edge's parameter of each point (a circle
    converted to a rational B-spline is parameterised differently)."""
    c2d, a, b = face.curveOnSurface(edge)
    probe = ts[[0, len(ts) // 2, -1]]
    kept = np.allclose((a, b), occ.ParameterRange, rtol=0.0, atol=1e-12 * max(1.0, abs(b - a))) and \
        max((edge.valueAt(t) - occ.valueAt(t)).Length for t in probe) <= 1e-9 * max(1.0, edge.Length)
    if kept:
        params = ts
    else:
        import FreeCAD
        curve = edge.Curve
        params = np.array([curve.parameter(FreeCAD.Vector(*p)) for p in points], float)
        if curve.isPeriodic():  # (into the edge's own range)
            params = a + np.mod(params - a, curve.period())
    points2d = [c2d.value(t) for t in params]
    return np.array([(q.x, q.y) for q in points2d], float)


#: The normals and curvature across an edge of a face that is not sculpted, by the face and the edge's samples:
#: they are the same after every stroke (the report is remade at each one), so they are computed once.
_NEIGHBOUR_SIDES: dict[tuple[Any, ...], tuple[np.ndarray, np.ndarray]] = {}
_NEIGHBOUR_CACHE_SIZE = 256


def _neighbour_side(other: Any, edge: Any, occ: Any, ts: np.ndarray, points: np.ndarray,
                    tangents: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The unit normals and the curvature across ``edge`` of the unsculpted face ``other`` at the
    edge's samples."""
    key = (other.hashCode(), other.Orientation, points.tobytes(), tangents.tobytes())
    side = _NEIGHBOUR_SIDES.get(key)
    if side is None:
        uv = _uv_on(other, edge, occ, ts, points)
        sign = -1.0 if other.Orientation == "Reversed" else 1.0
        d = surface_derivatives(other.Surface, uv)
        side = (sign * _unit(np.cross(d[:, 0], d[:, 1])), curvature_across(other.Surface, uv, sign, tangents, d))
        if len(_NEIGHBOUR_SIDES) >= _NEIGHBOUR_CACHE_SIZE:
            _NEIGHBOUR_SIDES.pop(next(iter(_NEIGHBOUR_SIDES)))  # (the oldest)
        _NEIGHBOUR_SIDES[key] = side
    return side


@dataclass
class EdgeProfile:
    """An edge of a sculpted face as the continuity check draws it: its points (on the sculpted
    side), and per side of it (one, or two where another face meets it) the unit normals, oriented
    alike on a closed solid, and the normal curvature across it; the report's numbers and
    ``g1_deg_sides``, the largest angle between the sides' normals (None with one side), and
    ``base_deg`` that angle as the base has it (a crease by design, or a smooth edge); ``held``:
    what an edge with one side holds by construction (a held edge, a curve followed), else None."""

    edge: str
    points: np.ndarray
    sides: list[tuple[np.ndarray, np.ndarray]]
    g0_mm: float
    g1_deg: float | None
    g2_pct: float | None
    g1_deg_sides: float | None = None
    held: str | None = None
    base_deg: float | None = None  # the largest angle between the sides' normals as the base has them
    floor: float = 0.0  # |kappa| below it counts as it in g2_pct (see curvature_jump_pct)


def _angle_between(a: np.ndarray, b: np.ndarray) -> float:
    cosine = np.einsum("ij,ij->i", a, b)
    cosine = cosine[np.isfinite(cosine)]
    return float(np.degrees(np.arccos(np.clip(cosine.min(), -1.0, 1.0)))) if cosine.size else 0.0


#: What an edge meets at a point: G0 within G0_MM (mm), G1 within G1_DEG (degrees between the
#: sides' normals), G2 with a jump of the normal curvature across it within G2_PCT (percent).
G0_MM, G1_DEG, G2_PCT = 1e-7, 0.01, 1.0


def sample_tolerances(profile: EdgeProfile) -> tuple[np.ndarray, np.ndarray] | None:
    """Per sample of an edge with two sides: whether their normals agree within G1_DEG, and
    whether the normal curvature jumps across it by at most G2_PCT; None for an edge with one side."""
    if len(profile.sides) < 2:
        return None
    (na, ka), (nb, kb) = profile.sides
    cosine = np.clip(np.einsum("ij,ij->i", na, nb), -1.0, 1.0)
    scale = np.maximum(np.maximum(np.abs(ka), np.abs(kb)), profile.floor)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.degrees(np.arccos(cosine)) <= G1_DEG, 100.0 * np.abs(ka - kb) / scale <= G2_PCT


def _with_shares(report: dict[str, Any], profile: EdgeProfile) -> dict[str, Any]:
    """``report`` with the share of the edge's samples (percent) within G1 and within G2
    (``g1_within_pct``, ``g2_within_pct``; None for an edge with one side): a seam whose worst
    point says 100 % at its ends can be G2 over most of its length."""
    within = sample_tolerances(profile)
    g1, g2 = (None, None) if within is None else (100.0 * float(np.mean(within[0])),
                                                  100.0 * float(np.mean(within[0] & within[1])))
    return {**report, "g1_within_pct": g1, "g2_within_pct": g2}


def seam_report(surface: Any, shape: Any, face_name: str, kinds: dict[str, str],
                skip: frozenset[str] = frozenset()) -> list[dict[str, Any]]:
    """For each edge of ``shape``'s face ``face_name`` sculpted to ``surface``: the largest distance
    (mm) between the sculpted surface along the edge's (u, v) curve and the edge itself (``g0_mm``:
    the neighbours still meet the edge), for G1 edges the largest angle (degrees) between the
    sculpted and the original normal there (``g1_deg``; None for the others), and for every edge
    the largest jump of the normal curvature across it between the sculpted face and the face on
    its other side as the base has it (``g2_pct``: percent of the larger |kappa|, see
    :func:`curvature_jump_pct`; the face's own seam: the sculpted surface on both sides; None on a
    degenerate edge), and the share of its samples within G1 and G2 (:func:`_with_shares`), at
    SEAM_SAMPLES points per edge (per side of a seam). Edges in ``skip`` (seams between sculpted
    faces, see :func:`seam_between`) are left out."""
    return [_with_shares({"edge": p.edge, "g0_mm": p.g0_mm, "g1_deg": p.g1_deg, "g2_pct": p.g2_pct}, p)
            for p in edge_profiles(surface, shape, face_name, kinds, skip)]


def edge_profiles(surface: Any, shape: Any, face_name: str, kinds: dict[str, str],
                  skip: frozenset[str] = frozenset()) -> list[EdgeProfile]:
    """What :func:`seam_report` measures, with the samples it measures at (:class:`EdgeProfile`)."""
    nface = nurbs_face(shape.getElement(face_name))
    original = nface.Surface
    sign = -1.0 if nface.Orientation == "Reversed" else 1.0
    floor = _curvature_floor(shape)
    occurrences: dict[str, list[Any]] = {}
    for name, occ in named_occurrences(shape, face_name, nface):
        if name not in skip:
            occurrences.setdefault(name, []).append(occ)
    profiles = []
    for name, occs in occurrences.items():
        g0, g1 = 0.0, None
        sampled = []
        for occ in occs:
            uv, ts = _pcurve_points(nface, occ, SEAM_SAMPLES)
            points, tangents = _edge_samples(occ, ts)
            values = np.array([tuple(surface.value(u, v)) for u, v in uv], float)
            g0 = max(g0, float(np.linalg.norm(values - points, axis=1).max()))
            derivatives = surface_derivatives(surface, uv)  # (its normals for G1, its curvature for g2_pct)
            normals = sign * _unit(np.cross(derivatives[:, 0], derivatives[:, 1]))
            was = sign * np.array([tuple(original.normal(u, v)) for u, v in uv], float)
            if kinds.get(name) in TANGENT:
                g1 = max(g1 or 0.0, _angle_between(normals, was))
            sampled.append((occ, uv, ts, points, tangents, derivatives, normals, values, was))
        profile = EdgeProfile(name, sampled[0][7], [], g0, g1, None, floor=floor)
        edge = shape.getElement(name)
        if not edge.Degenerated:
            occ, uv, ts, points, tangents, derivatives, normals, _, was = sampled[0]
            here = curvature_across(surface, uv, sign, tangents, derivatives)
            profile.sides.append((normals, here))
            if len(sampled) == 2:  # the face's own seam: the sculpted surface on both sides
                there = curvature_across(surface, sampled[1][1], sign, tangents, sampled[1][5])
                profile.sides.append((sampled[1][6], there))
                profile.base_deg = _angle_between(was, sampled[1][8])
            else:
                other = _other_face(shape, face_name, edge)
                if other is not None:
                    profile.sides.append(_neighbour_side(other, edge, occ, ts, points, tangents))
                    profile.base_deg = _angle_between(was, profile.sides[1][0])
            if len(profile.sides) == 2:
                profile.g2_pct = curvature_jump_pct(profile.sides[0][1], profile.sides[1][1], floor)
                profile.g1_deg_sides = _angle_between(profile.sides[0][0], profile.sides[1][0])
        profiles.append(profile)
    return sorted(profiles, key=lambda p: int(p.edge[4:]))


def seam_between(surfaces: dict[str, Any], shape: Any, faces: tuple[str, str], edge: str, kind: str) -> dict[str, Any]:
    """The seam ``edge`` between two sculpted faces (``surfaces``: face name to its sculpted surface
    in its own parameters): the largest distance between the two surfaces along it (``g0_mm``),
    for G1 the largest angle (degrees) between their normals there (``g1_deg``), and the largest
    jump of the normal curvature across it between them (``g2_pct``, see :func:`curvature_jump_pct`),
    at SEAM_SAMPLES points (the edge's pcurves on both faces share its parameter), and the share of
    them within G1 and G2 (:func:`_with_shares`)."""
    p = seam_profile(surfaces, shape, faces, edge, kind)
    return _with_shares({"edge": p.edge, "g0_mm": p.g0_mm, "g1_deg": p.g1_deg, "g2_pct": p.g2_pct}, p)


def seam_profile(surfaces: dict[str, Any], shape: Any, faces: tuple[str, str], edge: str, kind: str) -> EdgeProfile:
    """What :func:`seam_between` measures, with the samples it measures at (:class:`EdgeProfile`)."""
    values, sides, originals, bases = [], [], [], []
    tangents = None
    for f in faces:
        nface = nurbs_face(shape.getElement(f))
        occ = next(o for n, o in named_occurrences(shape, f, nface) if n == edge)
        uv, ts = _pcurve_points(nface, occ, SEAM_SAMPLES)
        sign = -1.0 if nface.Orientation == "Reversed" else 1.0
        surface = surfaces[f]
        points, along = _edge_samples(occ, ts)
        tangents = along if tangents is None else tangents  # (one tangent for both: the same direction across)
        d = surface_derivatives(surface, uv)
        bases.append(sign * np.array([tuple(nface.Surface.normal(u, v)) for u, v in uv], float))
        values.append(np.array([tuple(surface.value(u, v)) for u, v in uv], float))
        sides.append((sign * _unit(np.cross(d[:, 0], d[:, 1])), curvature_across(surface, uv, sign, tangents, d)))
        originals.append(points)
    drift = float(np.linalg.norm(originals[0] - originals[1], axis=1).max())
    if drift > 1e-7:  # (both faces' conversions keep the edge's parameter; this says if one did not)
        raise RuntimeError(f"{edge}: the two faces' curves of it are parameterised differently ({drift:.3g} mm apart)")
    gap = float(np.linalg.norm(values[0] - values[1], axis=1).max())
    between = _angle_between(sides[0][0], sides[1][0])
    return EdgeProfile(edge, values[0], sides, gap, between if kind in TANGENT else None,
                       curvature_jump_pct(sides[0][1], sides[1][1], _curvature_floor(shape)), between,
                       base_deg=_angle_between(bases[0], bases[1]), floor=_curvature_floor(shape))
