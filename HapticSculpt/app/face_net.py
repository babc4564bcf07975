"""The net a face of a solid is sculpted on: the face converted exactly (see :mod:`source_surface`),
refined to the least net asked for, with extra knots around each trim inside the face (so holding
the trim does not freeze the face around it), and, for a symmetric sculpt, with the mirror images
of all its knots (so the net is symmetric as the face is); and the poles that hold its edges.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from . import face_in_solid, face_symmetry, seam_continuity
from .face_chain import FaceChain, g1_links, joined_surface, seam_row
from .source_surface import SourceSurface, source_surface

#: Extra knots around a trim inside the face (a hole, an edge cut by a fillet), per direction, over
#: the trim's extent: poles whose support crosses the trim are held for G0, so on the coarse net
#: a hole freezes most of a face (54 % of a 40 x 30 plate's area with a 10 mm hole on 8 x 8 poles);
#: two more spans across the trim and two on each side bring that to 1 %.
TRIM_SPANS = 2


@dataclass(frozen=True)
class Mirror:
    """A mirror plane and the parameter direction (0: u, 1: v) the face's mirror image reverses."""

    direction: int
    point: np.ndarray
    normal: np.ndarray

    def settings(self) -> dict[str, Any]:
        return {"direction": self.direction, "point": [float(x) for x in self.point],
                "normal": [float(x) for x in self.normal]}


def mirror_of(obj: Any) -> Mirror | None:
    """A SculptedSolid's mirror symmetry (its ``Symmetry`` property), or None."""
    import json
    data = json.loads(obj.Symmetry) if getattr(obj, "Symmetry", "") else None
    if not data:
        return None
    return Mirror(int(data["direction"]), np.asarray(data["point"], float), np.asarray(data["normal"], float))


def trim_knots(edges: list[face_in_solid.FaceEdge], spans: int) -> tuple[list[float], list[float]]:
    """Knots that refine the net around each trim inside the face: ``spans`` spans across its
    extent and two on each side (see TRIM_SPANS)."""
    extra: tuple[list[float], list[float]] = ([], [])
    for e in edges:
        if e.side is not None:
            continue
        for d in (0, 1):
            lo, hi = float(e.uv[:, d].min()), float(e.uv[:, d].max())
            if hi - lo <= 0:
                continue
            h = (hi - lo) / spans
            extra[d].extend(lo + h * k for k in range(-2, spans + 3))
    return extra


def face_source(base: Any, chain: FaceChain, edges: list[face_in_solid.FaceEdge], controls: tuple[int, int],
                degree: tuple[int, int], trim_spans: int, mirror: Mirror | None) -> SourceSurface:
    """The chain's faces (one face, or several joined) in exact B-spline form on their sculpting
    net, in the joined parameters; ``edges`` (in them too) give the trims. ValueError if a face
    has no exact form."""
    extra = trim_knots(edges, trim_spans)
    if len(chain.placements) == 1:
        source: Any = (base, chain.faces[0])
    else:
        source = joined_surface(base.Shape, chain, degree)
    made = source_surface(source, controls, degree, (1.0, 1.0), base.Document, extra)
    if made.method == "exact" and mirror is not None:
        knots = made.surface.knots_u if mirror.direction == 0 else made.surface.knots_v
        missing = face_symmetry.mirrored_knots(knots)
        if missing:
            extra[mirror.direction].extend(list(knots) + missing)
            made = source_surface(source, controls, degree, (1.0, 1.0), base.Document, extra)
    if made.method != "exact":
        raise ValueError(f"faces: {', '.join(chain.faces)} has no exact B-spline form (its trims could not be kept "
                         f"on a fitted surface); sculpt it as a separate patch with make_sculpt")
    return made


def face_held(made: SourceSurface, edges: list[face_in_solid.FaceEdge], kinds: dict[str, str],
              mirror: Mirror | None) -> list[int]:
    """The poles that hold the edges as ``kinds`` says (symmetric with the mirror)."""
    s = made.surface
    held = face_in_solid.held_poles(np.asarray(s.knots_u), np.asarray(s.knots_v), tuple(s.degree),
                                    tuple(s.controls), edges, kinds)
    if mirror is not None:
        held = face_symmetry.symmetric_held(held, mirror.direction, tuple(s.controls))
    return held


def _net(surface: Any) -> tuple[np.ndarray, np.ndarray | None]:
    nu, nv = surface.controls
    poles = np.asarray(surface.poles, float).reshape(nu, nv, 3)
    weights = np.asarray(surface.weights, float).reshape(nu, nv) if surface.weights is not None else None
    return poles, weights


def seam_links(made: SourceSurface, chain: FaceChain, kinds: dict[str, str], held: list[int]) -> list[Any]:
    """The linked poles that keep the tangent planes matched across each G1 seam of the chain, and
    the curvature across each G2 seam too (its net made G2 first: :func:`g2_net`)."""
    s = made.surface
    poles, weights = _net(s)
    knots = np.asarray(s.knots_u)
    links: list[Any] = []
    for seam in chain.seams:
        kind = kinds.get(seam.edge)
        if kind == "G3":
            raise ValueError(f"boundary: {seam.edge} is a seam between faces sculpted together, and holding it "
                             f"G3 there is not available: hold it G2, G1 or G0")
        row = seam_row(knots, seam.u)
        if kind == "G1":
            links += g1_links(poles, weights, row, set(held), seam.edge)
        elif kind == "G2":
            links += seam_continuity.links(poles, weights, knots, s.degree[0], row, seam.u, set(held), seam.edge)
    return links


def g2_net(surface: Any, chain: FaceChain, kinds: dict[str, str], held: list[int]) -> np.ndarray | None:
    """The poles (nu, nv, 3) moved as little as possible so that every G2 seam of the chain is
    curvature-continuous (seam_continuity.project), or None when there is no G2 seam."""
    seams = [seam for seam in chain.seams if kinds.get(seam.edge) == "G2"]
    if not seams:
        return None
    poles, weights = _net(surface)
    knots = np.asarray(surface.knots_u)
    for seam in seams:
        poles = seam_continuity.project(poles, weights, knots, surface.degree[0], seam_row(knots, seam.u),
                                        seam.u, set(held), seam.edge)
    return poles


def seam_kinds(made: SourceSurface, chain: FaceChain, kinds: dict[str, str], asked: set[str]) -> dict[str, str]:
    """``kinds`` with each seam not ``asked`` about made G2 where its faces meet curvature-
    continuously already (the jump of normal curvature across it within seam_continuity.G2_SHARE),
    G1 where they meet tangentially (so G1 can hold there) and G0 where they meet at an angle."""
    out = dict(kinds)
    poles, weights = _net(made.surface)
    knots = np.asarray(made.surface.knots_u)
    size = float(np.linalg.norm(np.ptp(poles.reshape(-1, 3), axis=0))) or 1.0
    for seam in chain.seams:
        if seam.edge in asked:
            continue
        try:
            seam_links(made, chain, {seam.edge: "G1"}, [])
            out[seam.edge] = "G1"
        except ValueError:
            out[seam.edge] = "G0"
            continue
        try:
            share = seam_continuity.jump_share(poles, weights, knots, made.surface.degree[0],
                                               seam_row(knots, seam.u), seam.u, seam.edge, 1 / (1000 * size))
        except ValueError:
            continue
        if share <= seam_continuity.G2_SHARE:
            out[seam.edge] = "G2"
    return out
