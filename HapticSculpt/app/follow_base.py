"""A SculptedSolid follows its base: when the base's face changes (a pad made taller, a box made
wider), the sculpt is carried over to the new face as a displacement from it, so what was sculpted
stays sculpted on the changed part.

The displacement (sculpted surface minus the face it was made from, kept in ``SourcePoles``) is
sampled at the same relative parameters on both, fitted on the new face's net by least squares
with its held poles not displaced (the edges stay exactly on the new neighbours), and added to the
new face's poles. Spring rest lengths scale with the source's, so clay keeps its set; the material
maps and the tool carry over. Constraints were placed in the old part's space: they are dropped,
and the report view says how many.
"""
from __future__ import annotations

import json
from typing import Any

import numpy as np

from .. import core
from . import face_in_solid, sculpt_state
from .face_chain import FaceChain, chain_of
from .curve_constraint import PROPERTY, records_of
from .face_net import face_held, face_source, mirror_of, seam_links
from .face_walls import face_walls
from .sculpt_properties import face_of, read_state, write_state
from .source_surface import SourceSurface, refined

#: Grid (per direction) on which the displacement is sampled and fitted.
FIT_SAMPLES = 48


def source_of(obj: Any, chain: FaceChain, edges: list[face_in_solid.FaceEdge]) -> Any:
    """The base faces' exact B-spline surface at the SculptedSolid's resolution (a SourceSurface),
    refined where a fit refined the sculpt's net (its ``fit_knots``)."""
    res = json.loads(obj.Resolution)
    made = face_source(obj.Base, chain, edges, tuple(res["controls"]), tuple(res["degree"]),
                       int(res["trim_spans"]), mirror_of(obj))
    fit = res.get("fit_knots")
    if fit and (fit[0] or fit[1]):
        made = SourceSurface(refined(made.surface, tuple(fit)), made.method, made.error, made.description)
    return made


def _basis_matrix(surface: core.BSplineSurface, n: int) -> np.ndarray:
    """(n*n, poles) matrix: the surface's points on its n x n grid are this times its poles (linear
    in the poles for fixed weights)."""
    poles = np.zeros(np.asarray(surface.poles).shape)
    columns = []
    for k in range(poles.shape[0] * poles.shape[1]):
        unit = poles.copy()
        unit.reshape(-1, 3)[k, 0] = 1.0
        probe = core.BSplineSurface(unit, surface.degree, surface.knots_u, surface.knots_v, surface.weights)
        columns.append(np.asarray(probe.grid(n, n)[0])[..., 0].ravel())
    return np.stack(columns, axis=1)


def carried_poles(old_source: core.BSplineSurface, sculpted: core.BSplineSurface, new_source: core.BSplineSurface,
                  held: list[int]) -> np.ndarray:
    """The new face's poles plus the old sculpt's displacement, fitted with the held poles fixed."""
    n = FIT_SAMPLES
    displacement = (np.asarray(sculpted.grid(n, n)[0]) - np.asarray(old_source.grid(n, n)[0])).reshape(-1, 3)
    basis = _basis_matrix(new_source, n)
    free = np.setdiff1d(np.arange(basis.shape[1]), np.asarray(held, dtype=int))
    delta = np.zeros((basis.shape[1], 3))
    delta[free], *_ = np.linalg.lstsq(basis[:, free], displacement, rcond=None)
    return np.asarray(new_source.poles).reshape(-1, 3) + delta


def follow_base(obj: Any, shape: Any) -> bool:
    """Carries the sculpt over to the base's face if it changed since the sculpt was made from it
    (or last followed it); True if it did. The caller holds the transaction (a recompute)."""
    if not obj.Resolution or not obj.SourcePoles:
        return False  # (made before sculpts followed their base: nothing to compare with)
    sculpt = obj.Sculpts[0]
    chain = chain_of(shape, list(obj.SculptFaces))
    edges = chain.edges(shape)
    made = source_of(obj, chain, edges)
    new_source = made.surface
    old = read_state(sculpt)
    nu, nv = old.settings["controls"]
    old_poles = np.asarray(obj.SourcePoles, float)
    same_net = (tuple(new_source.controls) == (nu, nv)
                and np.array_equal(np.asarray(new_source.knots_u), old.arrays["KnotsU"])
                and np.array_equal(np.asarray(new_source.knots_v), old.arrays["KnotsV"]))
    size = float(np.ptp(np.asarray(new_source.poles).reshape(-1, 3), axis=0).max())
    if same_net and old_poles.size == nu * nv * 3 and \
            np.abs(np.asarray(new_source.poles).ravel() - old_poles).max() <= 1e-12 * max(size, 1.0):
        return False
    weights = old.arrays["Weights"].reshape(nu, nv) if old.arrays["Weights"].size else None
    old_source = core.BSplineSurface(old_poles.reshape(nu, nv, 3), tuple(old.settings["degree"]),
                                     old.arrays["KnotsU"], old.arrays["KnotsV"], weights)
    sculpted = core.BSplineSurface(old.arrays["Poles"].reshape(nu, nv, 3), tuple(old.settings["degree"]),
                                   old.arrays["KnotsU"], old.arrays["KnotsV"], weights)
    boundary = json.loads(obj.Boundary)
    kinds = {name: boundary.get(name, "G0") for name in [e.name for e in edges] + sorted(chain.seam_edges())}
    held = face_held(made, edges, kinds, mirror_of(obj))
    links = seam_links(made, chain, kinds, held)
    poles = carried_poles(old_source, sculpted, new_source, held)
    walls = face_walls(shape, list(obj.SculptFaces), edges, kinds, poles, held + [link[0] for link in links])
    mesh = tuple(old.settings["mesh"])
    carried = core.BSplineSurface(poles.reshape(*new_source.controls, 3), new_source.degree, new_source.knots_u,
                                  new_source.knots_v, new_source.weights)
    # rest lengths: the old ones, scaled spring by spring as the source's lengths scaled
    old_lengths = np.asarray(core.DynamicSurface(old_source, mesh).rest_lengths)
    new_lengths = np.asarray(core.DynamicSurface(new_source, mesh).rest_lengths)
    rest = old.arrays["RestLengths"] * np.divide(new_lengths, old_lengths, out=np.ones_like(new_lengths),
                                                 where=old_lengths > 0)
    moved = sculpt_state.capture(core.DynamicSurface(carried, mesh))
    arrays = dict(old.arrays, Poles=moved.arrays["Poles"], Velocities=np.zeros_like(moved.arrays["Poles"]),
                  KnotsU=moved.arrays["KnotsU"], KnotsV=moved.arrays["KnotsV"], Weights=moved.arrays["Weights"],
                  RestLengths=rest)
    dropped = len(old.settings.get("constraints", [])) + len(records_of(sculpt))
    settings = dict(old.settings, controls=list(new_source.controls), held_poles=held, constraints=[],
                    linked_poles=[[p, [list(m) for m in masters]] for p, masters in links], walls=walls,
                    reference=moved.settings["reference"])
    # (restoring validates before anything is written, and puts the linked poles onto their masters)
    state = sculpt_state.capture(sculpt_state.restore(sculpt_state.SculptState(arrays, settings)))
    live = sculpt.Proxy.live
    live.writing = True
    try:
        write_state(sculpt, state)
        if getattr(sculpt, PROPERTY, ""):
            setattr(sculpt, PROPERTY, "")  # (its curves' conditions were on the old net)
        sculpt.Shape = face_of(state)
    finally:
        live.writing = False
    live.document_changed()
    obj.SourcePoles = np.asarray(new_source.poles, float).ravel().tolist()
    obj.Boundary = json.dumps(kinds)
    obj.Layout = chain.dumps() if len(chain.placements) > 1 else ""
    if dropped:
        import FreeCAD
        FreeCAD.Console.PrintWarning(f"HapticSculpt: {obj.Label}: the base changed; the sculpt follows it, its "
                                     f"{dropped} constraint(s) (placed on the old part) were dropped\n")
    return True
