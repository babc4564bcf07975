"""The scripting API for sculpting faces of a solid in place (part of the contract in :mod:`api`):
:func:`sculpt_solid` makes a SculptedSolid; :func:`HapticSculpt.run`, ``add_constraint`` and the
other sculpt functions accept it as they accept a Sculpt, and ``export_step`` writes its solid."""
from __future__ import annotations

import json
from typing import Any, Sequence

import numpy as np

from .. import core
from . import base_continuity, curve_api, face_chain, face_in_solid, face_symmetry, sculpt_state
from .api import _add_sculpt, _checked_resolution, _document, _material, _sculpt_state
from .source_surface import SourceSurface
from .face_net import TRIM_SPANS, Mirror, face_held, face_source, g2_net, mirror_of, seam_kinds, seam_links
from .face_walls import face_walls
from .sculpt_properties import read_state
from .sculpted_solid import (
    SculptedSolidFeature,
    attach_view_provider,
    base_solid,
    boundary_of,
    chain_of_solid,
    is_sculpted_solid,
    rebuild,
    sculpt_of,
)
from .undo import transaction


def _boundary_kinds(boundary: Any, edges: list[face_in_solid.FaceEdge], faces: Sequence[str],
                    shape: Any, seams: frozenset[str]) -> dict[str, str]:
    """Every edge of the faces to "free" or "G0" to "G3": as ``boundary`` says, and where it says
    "base" (or a dict does not say), as the base meets its neighbour there (base_continuity; the
    seams in ``seams`` then G0 here: :func:`face_net.seam_kinds` judges them on the net)."""
    names = [e.name for e in edges]
    allowed = (*face_in_solid.KINDS, base_continuity.AS_BASE)
    if isinstance(boundary, str):
        if boundary not in allowed:
            raise ValueError(f"boundary: one of {', '.join(allowed)}, not {boundary!r}")
        kinds = {n: boundary for n in names}
    elif isinstance(boundary, dict):
        kinds = {n: base_continuity.AS_BASE for n in names}
        for edge, kind in boundary.items():
            if edge not in names:
                raise ValueError(f"boundary: {edge!r} is not an edge of {', '.join(faces)} "
                                 f"(their edges: {', '.join(names)})")
            if kind not in allowed:
                raise ValueError(f"boundary: {edge} must be one of {', '.join(allowed)}, not {kind!r}")
            kinds[edge] = kind
    else:
        raise TypeError(f"boundary: one of {', '.join(allowed)} or a dict from edge name to one "
                        f"of them, not {boundary!r}")
    if base_continuity.AS_BASE in kinds.values():
        base = base_continuity.base_kinds(shape, faces, seams)
        kinds = {n: (base.get(n, "G0") if k == base_continuity.AS_BASE else k) for n, k in kinds.items()}
    for e in edges:
        if kinds[e.name] == "free" and not set(e.neighbours) <= set(faces):
            what = "the seam of " + e.neighbours[0] if e.neighbours == (faces[0],) else \
                "shared with " + ", ".join(n for n in e.neighbours if n not in faces)
            raise ValueError(f"boundary: {e.name} is {what}, which is not sculpted with it: a free edge would "
                             f"open the solid there (hold it G0 to G3)")
    return kinds


def _seam_edges(chain: face_chain.FaceChain) -> list[face_in_solid.FaceEdge]:
    """The seams between the chain's faces as edges (for the boundary's names and checks)."""
    return [face_in_solid.FaceEdge(s.edge, None, np.zeros((0, 2)), s.faces) for s in chain.seams]


def _made_of(sculpt: Any) -> Any:
    """A sculpt's current net as a SourceSurface (to find the poles that hold it)."""
    from .source_surface import SourceSurface
    return SourceSurface(sculpt.Proxy.live.snapshot().surface, "exact", 0.0, "")


def _holds(made: Any, chain: face_chain.FaceChain, edges: list[face_in_solid.FaceEdge], kinds: dict[str, str],
           mirror: Mirror | None, what: str) -> tuple[Any, list[int], list[Any]]:
    """The net to hold (``made``, its G2 seams made curvature-continuous first), the held poles
    and the seams' linked poles; ValueError if they would hold every pole."""
    held = face_held(made, edges, kinds, mirror)
    g2 = g2_net(made.surface, chain, kinds, held)
    if g2 is not None:
        s = made.surface
        made = SourceSurface(core.BSplineSurface(g2, tuple(s.degree), list(s.knots_u), list(s.knots_v),
                                                 None if s.weights is None else np.asarray(s.weights)),
                             made.method, made.error, made.description)
    links = seam_links(made, chain, kinds, held)
    nu, nv = made.surface.controls
    if len(held) + len(links) >= nu * nv:
        raise ValueError(f"boundary: holding the edges as asked holds every pole of {what}'s {nu} x {nv} net "
                         f"(give more controls)")
    return made, held, links


#: A face with a trim inside its parameter rectangle (a disc's circle, a hole) that holds more than
#: 1 - this of the poles that shape its inside is refined before it is sculpted: a cylinder's top (a disc, radius 20) on the 8 x 8 net had 71 of its 100 poles
#: held by the circle and none free inside it, so a stroke moved nothing. Each pass takes 1.5 times
#: the controls; the disc ends at 32 x 32, where a 6 mm rope pull lifts its middle 2.1 mm (a 40 mm
#: box top: 2.3 mm; at 18 x 18, a quarter free: 1.0 mm).
MIN_FREE_INSIDE = 0.6
#: ... up to this many controls per face (the mesh grows with them: two mass points per span).
MAX_REFINED_CONTROLS = 32


def free_inside(made: Any, held: list[int], links: list[Any], shape: Any, faces: Sequence[str]) -> tuple[int, int]:
    """How many of the poles that shape the faces' inside are free, and how many there are: the
    poles whose Greville point (the place on the surface that follows them most) lies on one of
    the faces, their trims counted."""
    import FreeCAD
    s = made.surface
    (p, q), (nu, nv) = s.degree, s.controls
    ku, kv = np.asarray(s.knots_u), np.asarray(s.knots_v)
    gu = [float(np.mean(ku[i + 1:i + p + 1])) for i in range(nu)]
    gv = [float(np.mean(kv[j + 1:j + q + 1])) for j in range(nv)]
    solid_faces = [shape.getElement(f) for f in faces]
    tolerance = 1e-6 * shape.BoundBox.DiagonalLength
    fixed = set(held) | {int(link[0]) for link in links}
    inside = free = 0
    for i in range(nu):
        for j in range(nv):
            point = FreeCAD.Vector(*s.evaluate(gu[i], gv[j])["point"])
            if any(f.isInside(point, tolerance, True) for f in solid_faces):
                inside += 1
                free += (i * nv + j) not in fixed
    return free, inside


def sculpt_solid(doc: Any, base: Any, faces: Sequence[str], boundary: Any = "base", symmetry: Any = None,
                 controls: tuple[int, int] = (8, 8), degree: tuple[int, int] = (3, 3),
                 mesh: tuple[int, int] = (40, 40), name: str = "SculptedSolid", material: str = "clay") -> Any:
    """A new SculptedSolid in ``doc``: ``base``'s solid with ``faces`` (names like ``["Face6"]``)
    sculptable in place, their trims kept.

    Several faces are sculpted together as one surface when they lie in a row, each sharing a
    whole side of its parameter range with the next (the top of a box and the fillet beside it,
    the faces of a loft): a stroke across a seam pulls both faces, which stay joined (G0) and,
    where they meet tangentially, tangent (G1) across it.

    ``boundary``: how the faces' edges are held while sculpting, "G0" (they stay where they are, so
    the neighbour faces still meet them: the poles that shape the surface along them do not move),
    "G1" (their tangent planes too), "G2" (the curvature across them too: the neighbour face meets
    the sculpted one as it met the base, to second order), "G3" (that curvature's rate too),
    "free", or "base" (the default): each edge as the base meets its neighbour there, G2 where
    curvature-continuous, G1 where tangent, G0 at a crease (base_continuity), so a sculpted top
    stays tangent to its rounds. One kind for all edges, or a dict from edge name ("Edge3") to one
    of them, "base" for the others. A free edge must not border a face that is not sculpted (it
    would open the solid). A seam between two of the faces is G1 where they meet tangentially and
    G0 (a crease that may move) where they meet at an angle, unless the dict says otherwise.
    ``controls``/``degree`` are the least net per face (each face is converted exactly, then
    refined; trims inside a face get extra knots around them; a face whose trim holds most of the
    poles shaping its inside, as a cylinder's top, gets a finer net, up to 32 x 32, and mesh: see
    MIN_FREE_INSIDE), ``mesh`` the mass points per face,
    ``material`` "clay" (strokes stay) or "elastic". One undo step; the base is hidden in the GUI.
    Where a held edge meets a face that is not sculpted at a crease (a box's top and its sides),
    the sculpt stays behind that face's plane (walls: see ``face_walls``), so a stroke toward a
    side never folds it over the side into a solid that cuts itself.
    ``symmetry`` (one face only): None, or a mirror plane (``(point, normal)`` or a plane of the
    document) the face is symmetric in (with u or v reversed): the sculpt then stays exactly
    symmetric, a stroke acting mirrored on the other side.
    """
    doc = _document(doc)
    if not hasattr(base, "Shape") or getattr(base, "Document", None) is not doc:
        raise TypeError(f"base: expected a document object of {doc.Name} with a solid Shape, got {base!r}")
    try:
        shape = base_solid(base)
    except ValueError as exc:
        raise ValueError(f"base: {exc}") from None
    if isinstance(faces, str) or not isinstance(faces, Sequence) or not faces:
        raise TypeError(f"faces: expected a non-empty list of face names like ['Face6'], got {faces!r}")
    faces = list(faces)
    for f in faces:
        if not isinstance(f, str) or not f.startswith("Face") or not f[4:].isdigit() or not 1 <= int(f[4:]) <= len(shape.Faces):
            raise ValueError(f"faces: {f!r} is not a face of {base.Label} (Face1 .. Face{len(shape.Faces)})")
    if len(set(faces)) != len(faces):
        raise ValueError(f"faces: {faces} names a face twice")
    if len(faces) > 1 and symmetry is not None:
        raise ValueError("symmetry: for one face (several faces sculpted together have no mirror plane in this version)")
    controls, degree, mesh = _checked_resolution(controls, degree, mesh)
    if not isinstance(name, str) or not name:
        raise TypeError("name: expected a non-empty string")
    _material(material)
    chain = face_chain.chain_of(shape, faces)
    if len(faces) > 1:  # (the least net and the mesh are per face: the faces are joined along u)
        controls, mesh = (controls[0] * len(faces), controls[1]), (mesh[0] * len(faces), mesh[1])
    edges = chain.edges(shape)
    seams = chain.seam_edges()
    kinds = _boundary_kinds(boundary, edges + _seam_edges(chain), faces, shape, frozenset(seams))
    mirror = None
    if symmetry is not None:
        point, normal = face_symmetry.plane_of(symmetry, doc)
        nface = face_in_solid.nurbs_face(shape.getElement(faces[0]))
        mirror = Mirror(face_symmetry.mirror_direction(nface, point, normal, faces[0]), point, normal)
    asked = set(boundary) & seams if isinstance(boundary, dict) else set()
    per_face = len(faces)
    while True:
        made = face_source(base, chain, edges, controls, degree, TRIM_SPANS, mirror)
        net_kinds = seam_kinds(made, chain, kinds, asked)
        made, held, links = _holds(made, chain, edges, net_kinds, mirror, ", ".join(faces))
        if not any(e.side is None for e in edges):
            break  # (edges on the net's sides hold rows as asked: G2 holds three; no trim to refine for)
        free, inside = free_inside(made, held, links, shape, faces)
        grown = (min(MAX_REFINED_CONTROLS * per_face, controls[0] * 3 // 2), min(MAX_REFINED_CONTROLS, controls[1] * 3 // 2))
        if free >= MIN_FREE_INSIDE * inside or grown == controls:
            break
        controls = grown  # (the trim holds most of what shapes the inside: a finer net frees more)
        # (two mass points per span at least: the trim's extra knots make some spans short, and a
        # span no mass point sees leaves the mass matrix singular)
        mesh = (max(mesh[0], 2 * controls[0]), max(mesh[1], 2 * controls[1]))
    kinds = net_kinds
    made, ends = _g2_ends_refined(made, kinds, seams)
    if ends:  # (a G2 seam: G2 over all but a short span at each end)
        made, held, links = _holds(made, chain, edges, kinds, mirror, ", ".join(faces))
        mesh = (mesh[0], max(mesh[1], 2 * made.surface.controls[1]))
    walls = face_walls(shape, faces, edges, kinds, made.surface.poles, held + [link[0] for link in links])
    state = _sculpt_state(made, mesh, material, held, mirror.settings() if mirror else None, links, walls)
    if doc.UndoMode == 0:
        doc.UndoMode = 1
    with transaction(doc, "Sculpt solid"):
        sculpt = _add_sculpt(doc, name + "Face", made, state)
        obj = doc.addObject("Part::FeaturePython", name)
        SculptedSolidFeature(obj)
        obj.Base = base
        obj.SculptFaces = faces
        obj.Boundary = json.dumps(kinds)
        obj.Sculpts = [sculpt]
        obj.Symmetry = json.dumps(mirror.settings() if mirror else None)
        obj.Layout = chain.dumps() if len(faces) > 1 else ""
        obj.Resolution = json.dumps({"controls": list(controls), "degree": list(degree), "trim_spans": TRIM_SPANS,
                                     **({"fit_knots": [[], ends]} if ends else {})})
        obj.SourcePoles = np.asarray(made.surface.poles, float).ravel().tolist()
        rebuild(obj)
        obj.purgeTouched()  # (built from its base just now: nothing to recompute)
        attach_view_provider(obj)
    return obj


#: A G2 seam's end spans along it are refined to at most this share of its parameter range: where
#: it ends on an edge held to a face that is not sculpted, the end span cannot be G2 (the edge's
#: rows and the seam's conditions meet there), and the seam fades over it: a third of a 100 mm
#: seam on 8 controls (67 % G2), 6 % once refined so (94 %).
G2_END_SHARE = 1.0 / 32.0


def g2_end_knots(surface: core.BSplineSurface, kinds: dict[str, str], seams: set[str]) -> list[float]:
    """The knots along the seams (v: faces are joined along u) that bring the net's end spans to
    G2_END_SHARE of the range, halving each end span, when a seam in ``seams`` is held G2 or G3;
    none otherwise."""
    if not any(kinds.get(e) in ("G2", "G3") for e in seams):
        return []
    breaks = sorted(set(float(k) for k in surface.knots_v))
    lo, hi = breaks[0], breaks[-1]
    limit = G2_END_SHARE * (hi - lo) * (1.0 + 1e-9)
    out: list[float] = []
    first, last = breaks[1], breaks[-2]
    while first - lo > limit:
        first = 0.5 * (lo + first)
        out.append(first)
    while hi - last > limit:
        last = 0.5 * (last + hi)
        out.append(last)
    return sorted(out)


def _g2_ends_refined(made: Any, kinds: dict[str, str], seams: set[str], most: int | None = None) -> tuple[Any, list[float]]:
    """``made`` with :func:`g2_end_knots` inserted (exactly: the shape is kept), and those knots;
    as it is where that would make more than ``most`` controls along v (a mesh sculpted already
    has two mass points per span at least)."""
    from .source_surface import refined
    ends = g2_end_knots(made.surface, kinds, seams)
    if not ends or (most is not None and made.surface.controls[1] + len(ends) > most):
        return made, []
    return SourceSurface(refined(made.surface, ([], ends)), made.method, made.error, made.description), ends


def _rehold_as_base(obj: Any, made: Any, edges: list[face_in_solid.FaceEdge], kinds: dict[str, str]) -> Any:
    """``made`` with the poles that ``kinds`` holds and the current holds did not put back where the
    base net has them: an edge held G1 after strokes with it held G0 meets its neighbour
    tangentially again, as the base did, instead of keeping the kink the strokes made."""
    s = made.surface
    source = np.asarray(obj.SourcePoles, float)
    poles = np.asarray(s.poles, float)
    if source.size != poles.size:
        return made
    mirror = mirror_of(obj)
    before = set(face_held(made, edges, {**{e.name: "G0" for e in edges}, **boundary_of(obj)}, mirror))
    newly = [i for i in face_held(made, edges, kinds, mirror) if i not in before]
    if not newly:
        return made
    flat = poles.reshape(-1, 3).copy()
    flat[newly] = source.reshape(-1, 3)[newly]
    return SourceSurface(core.BSplineSurface(flat.reshape(poles.shape), tuple(s.degree), list(s.knots_u),
                                             list(s.knots_v), None if s.weights is None else np.asarray(s.weights)),
                         made.method, made.error, made.description)


def _boundary_plan(obj: Any, boundary: Any) -> tuple[dict[str, str], Any, list[int], list[Any], list[Any]]:
    """What :func:`set_boundary` would hold: every edge's kind, the net (its G2 seams made
    curvature-continuous), the held poles, the seams' links and the walls (ValueError where it
    cannot hold, saying why)."""
    if not is_sculpted_solid(obj):
        raise TypeError(f"obj: expected a HapticSculpt SculptedSolid, got {getattr(obj, 'TypeId', type(obj).__name__)}")
    shape = base_solid(obj.Base)
    faces = list(obj.SculptFaces)
    chain = chain_of_solid(obj, shape)
    edges = chain.edges(shape)
    if isinstance(boundary, dict):
        boundary = {**boundary_of(obj), **boundary}
    kinds = _boundary_kinds(boundary, edges + _seam_edges(chain), faces, shape, frozenset(chain.seam_edges()))
    made = _rehold_as_base(obj, _made_of(sculpt_of(obj)), edges, kinds)
    if isinstance(boundary, str):  # (a seam is as tangent as its faces let it be)
        kinds = seam_kinds(made, chain, kinds, set())
    mesh = read_state(sculpt_of(obj)).settings["mesh"]
    made, _ = _g2_ends_refined(made, kinds, chain.seam_edges(), mesh[1] // 2)
    made, held, links = _holds(made, chain, edges, kinds, mirror_of(obj), ", ".join(faces))
    walls = face_walls(shape, faces, edges, kinds, made.surface.poles, held + [link[0] for link in links])
    return kinds, made, held, links, walls


def refined_net(obj: Any, surface: core.BSplineSurface, extra: tuple[Any, Any]) -> tuple[Any, list[int], list[Any], list[Any]]:
    """The SculptedSolid's net ``surface`` with knots ``extra`` inserted (exactly: the shape is
    kept) and what holds it there as its Boundary says: (the finer net, its held poles, its seams'
    linked poles, its walls). ValueError where the holds would take every pole."""
    from .source_surface import refined
    shape = base_solid(obj.Base)
    faces = list(obj.SculptFaces)
    chain = chain_of_solid(obj, shape)
    edges = chain.edges(shape)
    kinds = boundary_of(obj)
    made = SourceSurface(refined(surface, extra), "exact", 0.0, "")
    made, held, links = _holds(made, chain, edges, kinds, mirror_of(obj), ", ".join(faces))
    walls = face_walls(shape, faces, edges, kinds, made.surface.poles, held + [link[0] for link in links])
    return made.surface, held, links, walls


def record_refinement(obj: Any, before: core.BSplineSurface, after: core.BSplineSurface) -> None:
    """The SculptedSolid's net went from ``before`` to the finer ``after`` (knots inserted): its
    Resolution keeps the knots (so the net made again from the base, when the base changes, is
    this one) and its SourcePoles the face refined alike (so the sculpt still reads as a
    displacement from it). The caller holds the transaction."""
    from collections import Counter

    from .source_surface import refined
    added = tuple(sorted((Counter(np.asarray(b, float).tolist()) - Counter(np.asarray(a, float).tolist())).elements())
                  for a, b in ((before.knots_u, after.knots_u), (before.knots_v, after.knots_v)))
    if not added[0] and not added[1]:
        return
    res = json.loads(obj.Resolution)
    kept = res.get("fit_knots", [[], []])
    res["fit_knots"] = [sorted(kept[0] + list(added[0])), sorted(kept[1] + list(added[1]))]
    nu, nv = before.controls
    source = core.BSplineSurface(np.asarray(obj.SourcePoles, float).reshape(nu, nv, 3), tuple(before.degree),
                                 list(before.knots_u), list(before.knots_v), before.weights)
    obj.Resolution = json.dumps(res)
    obj.SourcePoles = np.asarray(refined(source, added).poles, float).ravel().tolist()


def can_hold(obj: Any, boundary: Any) -> bool:
    """Whether :func:`set_boundary` can hold ``boundary`` on the SculptedSolid (nothing changes)."""
    try:
        _boundary_plan(obj, boundary)
    except ValueError:
        return False
    return True


def set_boundary(obj: Any, boundary: Any) -> dict[str, str]:
    """Changes how a SculptedSolid's edges are held (``boundary`` as in :func:`sculpt_solid`: one
    kind for all, or a dict from edge name to kind, the others kept). One undo step (not during a
    session: RuntimeError); returns the kind of every edge."""
    kinds, made, held, links, walls = _boundary_plan(obj, boundary)
    sculpt = sculpt_of(obj)
    live = sculpt.Proxy.live
    if live.session is not None:
        raise RuntimeError(f"{obj.Label}: stop the sculpting session before changing how its edges are held")
    surface = live.surface
    before = surface.surface
    if tuple(made.surface.controls) != tuple(before.controls):  # (refined toward a G2 seam's ends)
        surface = sculpt_state.on_net(surface, made.surface)
    shape = np.asarray(made.surface.poles).shape
    # (a G2 seam made so: the least move; the curves it follows held again on top: ValueError first)
    poles, links, write_curves = curve_api.rehold(sculpt, surface, held, links,
                                                  np.asarray(made.surface.poles, float).reshape(-1, 3))
    with transaction(obj.Document, "Hold edges"):
        surface.set_poles(poles.reshape(shape))
        surface.hold_poles(held, links)
        surface.set_walls(walls)
        if surface is not live.surface:
            record_refinement(obj, before, surface.surface)
        live.write(sculpt_state.capture(surface))
        if surface is not live.surface:
            live.document_changed()  # (the cached surface is the coarser one: read it again)
        write_curves()
        obj.Boundary = json.dumps(kinds)
        rebuild(obj)
    return kinds



def next_holds(obj: Any, edges: Sequence[str] = ()) -> dict[str, str]:
    """What Hold edges does next to a SculptedSolid, as a ``set_boundary`` dict: with ``edges``
    (base edge names: the designer's pick) those edges go one step further, G0 -> G1 -> G2 -> G3
    -> G0 (a seam between sculpted faces stops at G2), from the weakest of them; with none, every
    outer edge goes around "base" (as the part meets its other faces there) -> G0 -> ... -> G3.
    Seams and edges not picked keep what they hold. Steps the net cannot hold are skipped; {} if
    none can."""
    shape = base_solid(obj.Base)
    chain = chain_of_solid(obj, shape)
    seams = chain.seam_edges()
    kinds = boundary_of(obj)
    unknown = [e for e in edges if e not in kinds]
    if unknown:
        raise ValueError(f"{obj.Label}: {', '.join(unknown)} is not an edge of its sculpted faces")
    if edges:
        cycle = ["G0", "G1", "G2"] + ([] if set(edges) & seams else ["G3"])
        now = min(cycle.index(kinds[e]) if kinds[e] in cycle else 0 for e in edges)
        plans = [{e: kind for e in edges} for kind in cycle[now + 1:] + cycle[:now + 1]]
    else:
        # the distinct states of the outer edges: as the part has them, then each kind for all
        # (where the part's is one of those, it is that one: G0 to G3 then go round in turn)
        outer = [e for e in kinds if e not in seams]
        as_base = _boundary_kinds(base_continuity.AS_BASE, chain.edges(shape), list(obj.SculptFaces), shape,
                                  frozenset(seams))
        states = [{e: as_base[e] for e in outer}] + [{e: kind for e in outer} for kind in ("G0", "G1", "G2", "G3")]
        if states[0] in states[1:]:
            states.pop(0)
        current = {e: kinds[e] for e in outer}
        now = states.index(current) if current in states else len(states) - 1
        plans = states[now + 1:] + states[:now]
    for plan in plans:
        if can_hold(obj, plan):
            return plan
    return {}
