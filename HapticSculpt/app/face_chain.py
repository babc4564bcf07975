"""Several faces of a solid sculpted as one surface: adjacent faces in a row (each shares a whole
side of its parameter range with the next, as the top of a box and the fillet beside it, or the
faces of a loft) are joined into one B-spline surface, sculpted as one dynamic system, and split
back into the faces, each in its own parameter space (so its trims stay valid).

Joined, the faces share the row of poles on their seam: G0 across it holds by construction. G1
(their tangent planes matched) holds by linking each pole on the seam to its two neighbours across
it (P_k = (P_k-1 + a P_k+1) / (1 + a), the core's linked poles), which keeps the derivatives from
both sides parallel wherever the net moves. A single face is a chain of one, placed as it is.

Each face's place in the joined parameter space is affine: its (u, v) optionally swapped, each
optionally reversed about the middle of its range, then scaled onto its span of the joined u (in
proportion to its length, so the mass points are spread evenly) and the chain's v range.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from . import face_in_solid
from .part_surface import part_bspline

#: Points per seam where the faces' parameterisations are compared, and the tolerance (relative to
#: the faces' size) within which they must meet and be tangent for a G1 seam.
MATCH_SAMPLES = 17
TOLERANCE = 1e-7
TANGENT_DEGREES = 1e-4


# --- a B-spline net as arrays, with the exact operations a chain needs ------------------------------
@dataclass
class Net:
    """Poles (nu, nv, 3), weights (nu, nv), full knot vectors and degrees of a B-spline surface."""

    poles: np.ndarray
    weights: np.ndarray
    knots_u: np.ndarray
    knots_v: np.ndarray
    degree: tuple[int, int]

    @staticmethod
    def of(bs: Any) -> "Net":
        def full(knots: list[float], mults: list[int]) -> np.ndarray:
            return np.array([k for k, m in zip(knots, mults) for _ in range(m)], float)
        poles = np.array([[tuple(p) for p in row] for row in bs.getPoles()], float)
        return Net(poles, np.array(bs.getWeights(), float), full(bs.getUKnots(), bs.getUMultiplicities()),
                   full(bs.getVKnots(), bs.getVMultiplicities()), (bs.UDegree, bs.VDegree))

    def part(self) -> Any:
        rational = bool(np.any(self.weights != self.weights.flat[0]))
        return part_bspline(self.poles, self.knots_u, self.knots_v, self.degree, self.weights if rational else None)

    def swapped(self) -> "Net":
        return Net(self.poles.transpose(1, 0, 2).copy(), self.weights.T.copy(), self.knots_v, self.knots_u,
                   (self.degree[1], self.degree[0]))

    def reversed(self, direction: int) -> "Net":
        k = self.knots_u if direction == 0 else self.knots_v
        flipped = (k[0] + k[-1] - k)[::-1].copy()
        flipped[k[::-1] == k[-1]], flipped[k[::-1] == k[0]] = k[0], k[-1]  # (the ends exactly)
        if direction == 0:
            return Net(self.poles[::-1].copy(), self.weights[::-1].copy(), flipped, self.knots_v, self.degree)
        return Net(self.poles[:, ::-1].copy(), self.weights[:, ::-1].copy(), self.knots_u, flipped, self.degree)

    def rescaled(self, u_range: tuple[float, float], v_range: tuple[float, float]) -> "Net":
        def onto(k: np.ndarray, lo: float, hi: float) -> np.ndarray:
            out = lo + (k - k[0]) / (k[-1] - k[0]) * (hi - lo)
            out[k == k[0]], out[k == k[-1]] = lo, hi  # (the ends exactly)
            return out
        return Net(self.poles, self.weights, onto(self.knots_u, *u_range), onto(self.knots_v, *v_range), self.degree)


# --- where each face sits in the joined parameter space ---------------------------------------------
@dataclass(frozen=True)
class Placement:
    """One face's place in the joined parameter space (see the module docstring)."""

    face: str
    swap: bool
    reverse_u: bool
    reverse_v: bool
    own: tuple[float, float, float, float]  #: the face's (u0, u1, v0, v1)
    span: tuple[float, float]               #: its range of the joined u

    def identity(self, v_range: tuple[float, float]) -> bool:
        """Placed as it is (a chain of one face): its parameters are the joined ones."""
        return (not (self.swap or self.reverse_u or self.reverse_v) and self.span == self.own[:2]
                and tuple(v_range) == self.own[2:])

    def _ranges(self) -> tuple[tuple[float, float], tuple[float, float]]:
        u0, u1, v0, v1 = self.own
        return ((v0, v1), (u0, u1)) if self.swap else ((u0, u1), (v0, v1))

    def to_joined(self, uv: np.ndarray, v_range: tuple[float, float]) -> np.ndarray:
        """(n, 2) points of the face's (u, v) in the joined (u, v)."""
        uv = np.asarray(uv, float)
        if self.identity(v_range):
            return uv
        a, b = (uv[:, 1], uv[:, 0]) if self.swap else (uv[:, 0], uv[:, 1])
        (a0, a1), (b0, b1) = self._ranges()
        if self.reverse_u:
            a = a0 + a1 - a
        if self.reverse_v:
            b = b0 + b1 - b
        s0, s1 = self.span
        return np.column_stack([s0 + (a - a0) / (a1 - a0) * (s1 - s0),
                                v_range[0] + (b - b0) / (b1 - b0) * (v_range[1] - v_range[0])])

    def to_face(self, uv: np.ndarray, v_range: tuple[float, float]) -> np.ndarray:
        """(n, 2) points of the joined (u, v) in the face's (u, v)."""
        uv = np.asarray(uv, float)
        if self.identity(v_range):
            return uv
        (a0, a1), (b0, b1) = self._ranges()
        s0, s1 = self.span
        a = a0 + (uv[:, 0] - s0) / (s1 - s0) * (a1 - a0)
        b = b0 + (uv[:, 1] - v_range[0]) / (v_range[1] - v_range[0]) * (b1 - b0)
        if self.reverse_u:
            a = a0 + a1 - a
        if self.reverse_v:
            b = b0 + b1 - b
        return np.column_stack([b, a]) if self.swap else np.column_stack([a, b])

    def net_to_joined(self, net: Net, v_range: tuple[float, float]) -> Net:
        """The face's net (in its own parameters) placed in the joined parameter space."""
        if self.swap:
            net = net.swapped()
        if self.reverse_u:
            net = net.reversed(0)
        if self.reverse_v:
            net = net.reversed(1)
        return net.rescaled(self.span, v_range)

    def net_to_face(self, net: Net) -> Net:
        """A piece of the joined net over this face's span, back in the face's own parameters."""
        (a0, a1), (b0, b1) = self._ranges()
        net = net.rescaled((a0, a1), (b0, b1))
        if self.reverse_v:
            net = net.reversed(1)
        if self.reverse_u:
            net = net.reversed(0)
        return net.swapped() if self.swap else net


@dataclass(frozen=True)
class Seam:
    """An edge two faces of the chain share, at joined u = ``u``, between faces ``faces``."""

    edge: str
    u: float
    faces: tuple[str, str]


@dataclass(frozen=True)
class FaceChain:
    """Faces joined into one surface: where each sits, the joined v range, the seams between them."""

    placements: tuple[Placement, ...]
    v_range: tuple[float, float]
    seams: tuple[Seam, ...]

    @property
    def faces(self) -> list[str]:
        return [p.face for p in self.placements]

    def dumps(self) -> str:
        return json.dumps({"placements": [dict(p.__dict__) for p in self.placements], "v_range": list(self.v_range),
                           "seams": [dict(s.__dict__) for s in self.seams]})

    @staticmethod
    def loads(text: str) -> "FaceChain":
        d = json.loads(text)
        return FaceChain(tuple(Placement(p["face"], bool(p["swap"]), bool(p["reverse_u"]), bool(p["reverse_v"]),
                                         tuple(p["own"]), tuple(p["span"])) for p in d["placements"]),
                         tuple(d["v_range"]), tuple(Seam(s["edge"], float(s["u"]), tuple(s["faces"])) for s in d["seams"]))

    def seam_edges(self) -> set[str]:
        return {s.edge for s in self.seams}

    def edges(self, shape: Any) -> list[face_in_solid.FaceEdge]:
        """Every edge of the chain's faces but the seams, with its points in the joined (u, v)."""
        seams = self.seam_edges()
        out = []
        for p in self.placements:
            for e in face_in_solid.face_edges(shape, p.face):
                if e.name not in seams:
                    out.append(face_in_solid.FaceEdge(e.name, e.side, p.to_joined(e.uv, self.v_range), e.neighbours))
        return out

    def split(self, surface: Any) -> dict[str, Any]:
        """The joined surface (a Part.BSplineSurface) cut back into the faces, each a
        Part.BSplineSurface in the face's own parameters."""
        if len(self.placements) == 1:
            return {self.placements[0].face: surface}
        out = {}
        for p in self.placements:
            piece = surface.copy()
            piece.segment(p.span[0], p.span[1], self.v_range[0], self.v_range[1])
            out[p.face] = p.net_to_face(Net.of(piece)).part()
        return out

    def on_faces(self, shape: Any, us: np.ndarray, vs: np.ndarray) -> np.ndarray:
        """Which points of the joined (us x vs) grid lie on their face (inside its outer wire and
        outside its holes): a (len(us), len(vs)) bool array."""
        mask = np.zeros((len(us), len(vs)), dtype=bool)
        for p in self.placements:
            nface = face_in_solid.nurbs_face(shape.getElement(p.face))
            lo, hi = min(p.span), max(p.span)
            for i, u in enumerate(us):
                if not lo - 1e-12 * abs(hi - lo) <= u <= hi + 1e-12 * abs(hi - lo):
                    continue
                uv = p.to_face(np.column_stack([np.full(len(vs), u), vs]), self.v_range)
                for j, (a, b) in enumerate(uv):
                    mask[i, j] = mask[i, j] or bool(nface.isPartOfDomain(float(a), float(b)))
        return mask


def single(shape: Any, face: str) -> FaceChain:
    """One face, placed as it is."""
    u0, u1, v0, v1 = (float(x) for x in face_in_solid.nurbs_face(shape.getElement(face)).ParameterRange)
    return FaceChain((Placement(face, False, False, False, (u0, u1, v0, v1), (u0, u1)),), (v0, v1), ())


# --- finding the chain ------------------------------------------------------------------------------
def _order(edges_of: dict[str, list[face_in_solid.FaceEdge]],
           faces: Sequence[str]) -> tuple[list[str], dict[frozenset[str], str]]:
    """The faces in chain order and the edge each neighbouring pair shares; ValueError otherwise."""
    shared: dict[frozenset[str], str] = {}
    for f in faces:
        for e in edges_of[f]:
            for n in e.neighbours:
                if n in faces and n != f:
                    key = frozenset((f, n))
                    if key in shared and shared[key] != e.name:
                        raise ValueError(f"faces: {f} and {n} share more than one edge ({shared[key]}, {e.name}); "
                                         f"they cannot be joined into one surface")
                    shared[key] = e.name
    neighbours = {f: [n for n in faces if frozenset((f, n)) in shared] for f in faces}
    for f, ns in neighbours.items():
        if not ns:
            raise ValueError(f"faces: {f} shares no edge with the other faces ({', '.join(x for x in faces if x != f)})")
        if len(ns) > 2:
            raise ValueError(f"faces: {f} borders {len(ns)} of the others; faces are sculpted together in a row "
                             f"(each next to at most two). Sculpt {f} alone: its edges are then held as the part "
                             f"meets the others (tangent where it is tangent)")
    ends = [f for f, ns in neighbours.items() if len(ns) == 1]
    if len(ends) != 2:
        raise ValueError(f"faces: {', '.join(faces)} close into a ring; faces are sculpted together in an open row. "
                         f"Leave one of them out, or sculpt one alone: its edges are then held as the part meets "
                         f"the others")
    order = [ends[0]]
    while len(order) < len(faces):
        order.append(next(n for n in neighbours[order[-1]] if n not in order))
    return order, shared


def _side_of(edges: list[face_in_solid.FaceEdge], face: str, edge: str) -> str:
    """The side of the face's parameter range the edge covers whole ("u0", "u1", "v0" or "v1")."""
    e = next(x for x in edges if x.name == edge)
    if e.side is None:
        raise ValueError(f"faces: {edge} is not a side of {face}'s parameter range; the faces cannot be joined "
                         f"into one surface")
    others = [x.name for x in edges if x.side == e.side and x.name != edge]
    if others:
        raise ValueError(f"faces: {edge} covers only part of {face}'s side (with {', '.join(others)}); the faces "
                         f"cannot be joined into one surface")
    return e.side


def _length(surface: Any, own: tuple[float, float, float, float], along_u: bool, n: int = 64) -> float:
    """Length of the face's middle iso-curve along u (or v), from n points."""
    u0, u1, v0, v1 = own
    t = np.linspace(0.0, 1.0, n)
    uv = [(u0 + (u1 - u0) * x, 0.5 * (v0 + v1)) if along_u else (0.5 * (u0 + u1), v0 + (v1 - v0) * x) for x in t]
    pts = np.array([tuple(surface.value(a, b)) for a, b in uv])
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


def chain_of(shape: Any, faces: Sequence[str]) -> FaceChain:
    """The faces of ``shape`` placed in one parameter space (ValueError saying why they cannot be)."""
    if len(faces) == 1:
        return single(shape, faces[0])
    edges_of = {f: face_in_solid.face_edges(shape, f) for f in faces}  # (found once: each costs a conversion)
    order, shared = _order(edges_of, faces)
    nfaces = {f: face_in_solid.nurbs_face(shape.getElement(f)) for f in order}
    size = max(float(np.linalg.norm(np.ptp(np.array([tuple(v.Point) for v in shape.getElement(f).Vertexes]), axis=0)))
               for f in order) or 1.0
    placements: list[Placement] = []
    seams: list[Seam] = []
    v_range: tuple[float, float] = (0.0, 1.0)
    start = 0.0
    for k, f in enumerate(order):
        prev = shared[frozenset((f, order[k - 1]))] if k > 0 else None
        nxt = shared[frozenset((f, order[k + 1]))] if k + 1 < len(order) else None
        # the edge with the previous face goes to u0, the one with the next to u1
        want = {}
        if prev:
            want[_side_of(edges_of[f], f, prev)] = "u0"
        if nxt:
            want[_side_of(edges_of[f], f, nxt)] = "u1"
        sides = list(want)
        if len(sides) == 2 and sides[0][0] != sides[1][0]:
            raise ValueError(f"faces: {f} meets its neighbours on two adjacent sides ({prev}, {nxt}), not opposite "
                             f"ones; the faces cannot be joined into one surface. Sculpt {f} alone: its edges are "
                             f"then held as the part meets the others")
        side, target = sides[0], want[sides[0]]
        swap = side[0] == "v"
        reverse_u = (side[1] != target[1])
        own = tuple(float(x) for x in nfaces[f].ParameterRange)
        length = _length(nfaces[f].Surface, own, along_u=not swap)
        span = (start, start + length)
        start += length
        placement = Placement(f, swap, reverse_u, False, own, span)
        if k == 0:
            (b0, b1) = placement._ranges()[1]
            v_range = (b0, b1)
        else:
            placement = _match_v(placements[-1], placement, nfaces, v_range, size, prev)
            seams.append(Seam(prev, span[0], (order[k - 1], f)))
        placements.append(placement)
    return FaceChain(tuple(placements), v_range, tuple(seams))


def _match_v(before: Placement, after: Placement, nfaces: dict[str, Any], v_range: tuple[float, float],
             size: float, edge: str) -> Placement:
    """``after`` with v reversed if that makes the two faces meet along their seam point for point."""
    vs = np.linspace(v_range[0], v_range[1], MATCH_SAMPLES)

    def points(p: Placement, u: float) -> np.ndarray:
        uv = p.to_face(np.column_stack([np.full(len(vs), u), vs]), v_range)
        return np.array([tuple(nfaces[p.face].Surface.value(float(a), float(b))) for a, b in uv])
    here = points(before, before.span[1])
    gaps = []
    for reverse in (False, True):
        candidate = Placement(after.face, after.swap, after.reverse_u, reverse, after.own, after.span)
        gap = float(np.linalg.norm(points(candidate, after.span[0]) - here, axis=1).max())
        if gap <= TOLERANCE * size:
            return candidate
        gaps.append(gap)
    raise ValueError(f"faces: {before.face} and {after.face} are not parameterised alike along {edge} (their points "
                     f"at the same parameter are {min(gaps):.3g} mm apart); they cannot be joined into one surface. "
                     f"Sculpt {before.face} alone: its edges are then held as the part meets the others")


# --- the joined surface -----------------------------------------------------------------------------
def joined_surface(shape: Any, chain: FaceChain, degree: tuple[int, int]) -> Any:
    """The chain's faces joined into one Part.BSplineSurface (exact: each face's exact B-spline
    form, degrees raised to a common one, v knots merged, joined at their seams with a knot of full
    multiplicity)."""
    from .source_surface import _exact_bspline
    nets = []
    for p in chain.placements:
        bs = _exact_bspline(shape.getElement(p.face))
        if bs is None:
            raise ValueError(f"faces: {p.face} has no exact B-spline form; it cannot be sculpted in place")
        nets.append(p.net_to_joined(Net.of(bs), chain.v_range))
    pu = max([degree[0]] + [n.degree[0] for n in nets])
    pv = max([degree[1]] + [n.degree[1] for n in nets])
    parts = []
    for n in nets:
        bs = n.part()
        bs.increaseDegree(pu, pv)
        parts.append(bs)
    # the union of the v knots (with the highest multiplicity each has anywhere)
    span = chain.v_range[1] - chain.v_range[0]
    wanted: dict[float, int] = {}
    for bs in parts:
        for k, m in zip(bs.getVKnots()[1:-1], bs.getVMultiplicities()[1:-1]):
            key = next((x for x in wanted if abs(x - k) <= 1e-9 * span), k)
            wanted[key] = max(wanted.get(key, 0), m)
    for bs in parts:
        for k, m in wanted.items():
            have = next((mm for kk, mm in zip(bs.getVKnots(), bs.getVMultiplicities()) if abs(kk - k) <= 1e-9 * span), 0)
            for _ in range(m - have):
                bs.insertVKnot(k, 1, 1e-9 * span)
    nets = [Net.of(bs) for bs in parts]
    poles, weights = [nets[0].poles], [nets[0].weights]
    knots = list(nets[0].knots_u[:-1])
    for k in range(1, len(nets)):
        a, b = nets[k - 1], nets[k]
        seam = chain.seams[k - 1]
        scale_pts = float(np.abs(np.concatenate([a.poles.reshape(-1, 3), b.poles.reshape(-1, 3)])).max()) or 1.0
        gap = float(np.abs(a.poles[-1] - b.poles[0]).max())
        if gap > TOLERANCE * scale_pts:
            raise ValueError(f"faces: {seam.faces[0]} and {seam.faces[1]} do not share their poles along {seam.edge} "
                             f"({gap:.3g} apart); they cannot be joined into one surface")
        ratio = a.weights[-1] / b.weights[0]
        if np.ptp(ratio) > 1e-12 * float(np.abs(ratio).max()):
            raise ValueError(f"faces: the weights of {seam.faces[0]} and {seam.faces[1]} along {seam.edge} differ by "
                             f"more than a factor; they cannot be joined into one surface")
        poles.append(b.poles[1:])
        weights.append(b.weights[1:] * float(ratio[0]))
        knots = knots[:len(knots) - pu] + [seam.u] * pu + list(b.knots_u[pu + 1:-1])
    knots.append(nets[-1].knots_u[-1])
    joined = Net(np.concatenate(poles), np.concatenate(weights), np.array(knots), nets[0].knots_v, (pu, pv))
    return joined.part()


def seam_row(knots_u: np.ndarray, u: float) -> int:
    """The row of poles the joined surface passes through at the seam u (a knot of multiplicity p)."""
    k = np.asarray(knots_u, float)
    first = int(np.argmin(np.abs(k - u)))
    return first - 1


def g1_links(poles: np.ndarray, weights: np.ndarray | None, row: int, held: set[int], edge: str) -> list[tuple[int, list[tuple[int, float]]]]:
    """Links that keep the tangent planes matched across the seam at pole ``row`` of a (nu, nv, 3)
    net: each pole on it not held stays at (P_k-1 + a P_k+1) / (1 + a), with the one ratio a the
    faces meet with now; ValueError when they do not meet tangentially (or not with one ratio)."""
    nu, nv = poles.shape[:2]
    before, on, after = poles[row - 1], poles[row], poles[row + 1]
    d0, d1 = on - before, after - on
    n0, n1 = np.linalg.norm(d0, axis=1), np.linalg.norm(d1, axis=1)
    if np.any(n0 <= 0) or np.any(n1 <= 0):
        raise ValueError(f"boundary: {edge} has coincident poles across it; G1 cannot be held there")
    angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(d0, d1), axis=1), np.einsum("ij,ij->i", d0, d1)))
    if angle.max() > TANGENT_DEGREES:
        raise ValueError(f"boundary: the faces meet at {angle.max():.3g} degrees along {edge}, not tangentially: "
                         f"hold it G0 (G1 cannot hold there)")
    ratio = n0 / n1
    if weights is not None:
        w = np.asarray(weights)
        for r in (row - 1, row + 1):
            q = w[r] / w[row]
            if np.ptp(q) > 1e-9 * q.max():
                raise ValueError(f"boundary: the weights across {edge} vary along it; G1 cannot be held there")
    if np.ptp(ratio) > 1e-6 * ratio.max():
        raise ValueError(f"boundary: the faces meet tangentially along {edge} but with speeds in no fixed ratio; "
                         f"G1 cannot be held there by the net (hold it G0)")
    a = float(np.mean(ratio))
    links = []
    for j in range(nv):
        pole = row * nv + j
        if pole in held:
            continue
        links.append((pole, [((row - 1) * nv + j, 1.0 / (1.0 + a)), ((row + 1) * nv + j, a / (1.0 + a))]))
    return links
