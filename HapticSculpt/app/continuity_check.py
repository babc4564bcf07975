"""The continuity check: how a sculpt meets what is around it, along every edge that matters, as a
designer judges it with curvature combs (the GUI draws them, coloured by what holds).

- A face sculpted in its solid: every edge of it, the sculpted face on one side and the face the
  base has on the other (or the other sculpted face, across a seam), as the seam report measures
  them (:func:`face_in_solid.edge_profiles`).
- A sculpt on its own: its held edges (one side: nothing meets them) and the curves it follows.
- Both: the curves the surface follows, the surface on both sides of them.

Each :class:`face_in_solid.EdgeProfile` gets a level: "G2" where the sides meet in position, tangent
plane and normal curvature within the tolerances (G0 1e-7 mm, G1 0.01 degrees, G2 1 %), "G1", "G0",
or "none" where even the position does not hold. No FreeCAD GUI here.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from . import curve_constraint, face_in_solid
from .api import BOUNDARIES, held_boundary
from .sculpt_properties import read_state, surface_of
from .sculpted_solid import _pieces, base_solid, boundary_of, solid_of

G0_MM, G1_DEG, G2_PCT = face_in_solid.G0_MM, face_in_solid.G1_DEG, face_in_solid.G2_PCT
#: Samples along a held edge of a sculpt on its own, and at most along a curve.
SAMPLES = 50


def level(profile: face_in_solid.EdgeProfile) -> str:
    """"G2", "G1", "G0" or "none": what holds between the profile's sides (one side: its ``level``
    is what the edge is held as, set by :func:`profiles`)."""
    if profile.held is not None:
        return profile.held
    if profile.g0_mm > G0_MM:
        return "none"
    angle = profile.g1_deg_sides
    if angle is None or angle > G1_DEG:
        return "G0"
    if profile.g2_pct is None or profile.g2_pct > G2_PCT:
        return "G1"
    return "G2"


#: The levels in order, weakest first (what :func:`sample_levels` numbers them by).
LEVELS = ("none", "G0", "G1", "G2")


def sample_levels(profile: face_in_solid.EdgeProfile) -> np.ndarray:
    """The level at each of the profile's samples (indices into :data:`LEVELS`), as :func:`level`
    judges the whole edge: where a seam is G2 in its middle and only G1 toward its ends, the
    samples say so (the edge's level is its worst point)."""
    n = len(profile.points)
    if profile.held is not None or len(profile.sides) < 2:
        return np.full(n, LEVELS.index(level(profile)), int)
    if profile.g0_mm > G0_MM:
        return np.zeros(n, int)
    tangent, curvature = face_in_solid.sample_tolerances(profile)
    return np.where(tangent, np.where(curvature, 3, 2), 1)


def shares(found: list[face_in_solid.EdgeProfile], kinds: dict[str, str]) -> list[dict[str, Any]]:
    """For each edge with two sides held G1 or more (``kinds``: its hold; a seam's, as the Boundary
    says), the share of its length that meets that hold (G3 judged as G2): ``{"edge", "kind",
    "share"}`` (0..1), the least first."""
    out = []
    for p in found:
        kind = kinds.get(p.edge)
        if len(p.sides) < 2 or kind not in ("G1", "G2", "G3"):
            continue
        target = LEVELS.index(min(kind, "G2"))
        out.append({"edge": p.edge, "kind": LEVELS[target], "share": float(np.mean(sample_levels(p) >= target))})
    return sorted(out, key=lambda r: (r["share"], int(r["edge"][4:]) if r["edge"][4:].isdigit() else 0))


def holds(sculpt: Any) -> dict[str, str]:
    """How the edges and seams of the sculpt's SculptedSolid are held (its Boundary), {} for a
    sculpt on its own (its held edges hold by construction)."""
    solid = solid_of(sculpt)
    return boundary_of(solid) if solid is not None else {}


def profiles(sculpt: Any, state: Any = None) -> list[face_in_solid.EdgeProfile]:
    """The profiles of the sculpt (a Sculpt; its SculptedSolid's edges if it is the face of one),
    with the poles of ``state`` (a SculptState: a session's newest frame) or the stored ones."""
    state = state if state is not None else read_state(sculpt)
    solid = solid_of(sculpt)
    out = _solid_profiles(solid, state) if solid is not None else _held_edge_profiles(sculpt, state)
    return out + _curve_profiles(sculpt, state)


#: An edge whose sides' normals differ by more than this in the base is a crease the design has (a
#: box's edge), not a smooth edge gone wrong: it counts for g0 only.
CREASE_DEG = 5.0


def worst(found: list[face_in_solid.EdgeProfile]) -> dict[str, Any]:
    """The largest g0 (mm) over the profiles with two sides, and the largest g1 (degrees, between
    the sides) and g2 (%) over the smooth ones among them (smooth in the base, however far a
    stroke has bent them since; not creases); None where there is none; ``smooth``: how many."""
    two = [p for p in found if len(p.sides) == 2]
    smooth = [p for p in two if p.g1_deg_sides is not None
              and (p.base_deg if p.base_deg is not None else p.g1_deg_sides) <= CREASE_DEG]
    g2 = [p.g2_pct for p in smooth if p.g2_pct is not None]
    return {"g0_mm": max((p.g0_mm for p in two), default=None),
            "g1_deg": max((p.g1_deg_sides for p in smooth), default=None),
            "g2_pct": max(g2, default=None), "smooth": len(smooth), "edges": len(two)}


def _solid_profiles(solid: Any, state: Any) -> list[face_in_solid.EdgeProfile]:
    shape = base_solid(solid.Base)
    kinds = boundary_of(solid)
    chain, pieces = _pieces(solid, shape, state)
    seams = frozenset(chain.seam_edges())
    out = []
    for face_name in chain.faces:
        out += face_in_solid.edge_profiles(pieces[face_name], shape, face_name, kinds, seams)
    for seam in chain.seams:
        out.append(face_in_solid.seam_profile(pieces, shape, seam.faces, seam.edge, kinds.get(seam.edge, "G0")))
    return out


def _edge_parameters(domain: Any, edge: str, n: int) -> np.ndarray:
    (u0, u1), (v0, v1) = domain
    t = np.linspace(0.0, 1.0, n)
    fixed = {"u0": u0, "u1": u1, "v0": v0, "v1": v1}[edge]
    if edge[0] == "u":
        return np.column_stack([np.full(n, fixed), v0 + (v1 - v0) * t])
    return np.column_stack([u0 + (u1 - u0) * t, np.full(n, fixed)])


def _side(surface: Any, uv: np.ndarray, tangents: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = face_in_solid.surface_derivatives(surface, uv)
    normals = face_in_solid._unit(np.cross(d[:, 0], d[:, 1]))
    return normals, face_in_solid.curvature_across(surface, uv, 1.0, tangents, d)


def _along(surface: Any, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points and unit tangents of the surface along the (u, v) polyline ``uv``."""
    points = np.array([tuple(surface.value(u, v)) for u, v in uv], float)
    return points, face_in_solid._unit(np.gradient(points, axis=0))


def _held_edge_profiles(sculpt: Any, state: Any) -> list[face_in_solid.EdgeProfile]:
    """A sculpt on its own: each held edge, the sculpt's side of it, at the level it is held as
    (hard constraints: it holds by construction; G3 shows as G2)."""
    surface = surface_of(state)
    u0, u1, v0, v1 = surface.bounds()
    out = []
    for edge, kind in held_boundary(sculpt).items():
        if kind == "free":
            continue
        uv = _edge_parameters(((u0, u1), (v0, v1)), edge, SAMPLES)
        points, tangents = _along(surface, uv)
        profile = face_in_solid.EdgeProfile(f"edge {edge}", points, [_side(surface, uv, tangents)], 0.0, None, None)
        profile.held = BOUNDARIES[min(BOUNDARIES.index(kind), 3)]  # (G3 holds G2 too)
        out.append(profile)
    return out


def _curve_profiles(sculpt: Any, state: Any) -> list[face_in_solid.EdgeProfile]:
    """The curves the surface follows: the surface on both sides of each (one surface: the same
    curvature), at the level the curve holds (G1: its normal kept, G0: passes through it)."""
    records = curve_constraint.records_of(sculpt)
    if not records:
        return []
    surface = surface_of(state)
    poles = np.asarray(state.arrays["Poles"], float).reshape(-1, 3)
    tolerance = curve_constraint.G0_SHARE * float(state.settings["reference"][0])
    net = _Net(state)
    out = []
    for r in records:
        pick = np.unique(np.linspace(0, len(r.uv) - 1, min(SAMPLES, len(r.uv))).astype(int))
        uv = r.uv[pick]
        points, tangents = _along(surface, uv)
        distance, degrees = curve_constraint.misses(net, r, poles)
        profile = face_in_solid.EdgeProfile(f"curve {r.label}", points, [_side(surface, uv, tangents)], distance,
                                            degrees if r.continuity == "G1" else None, None)
        profile.held = "none" if distance > tolerance else \
            "G1" if r.continuity == "G1" and degrees <= G1_DEG else "G0"
        out.append(profile)
    return out


class _Net:
    """A sculpt state's knots, degrees and weights as :func:`curve_constraint.rows` reads them."""

    def __init__(self, state: Any) -> None:
        s, a = state.settings, state.arrays
        self.degree, self.controls = tuple(s["degree"]), tuple(s["controls"])
        self.knots_u, self.knots_v = a["KnotsU"], a["KnotsV"]
        self.weights = a["Weights"].reshape(self.controls) if a["Weights"].size else None
