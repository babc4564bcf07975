"""Scripting API of curve constraints: a sculpt (or a sculpted solid) that passes through a curve,
G0, or along it with a normal, G1, held within its tolerance through every stroke
(:mod:`curve_constraint`).

The conditions live in the core as links; the curves themselves in the Sculpt's
``CurveConstraints`` property (JSON), written in the same undo step, so Undo, Redo, save and reopen
keep both. Whatever changes the held poles or the other links (Hold edges, a solid's boundary)
holds the curves again on top of them (:func:`rehold`).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from . import curve_constraint as cc
from .sculpt_feature import is_sculpt
from .sculpted_solid import is_sculpted_solid, sculpt_of

PROPERTY = cc.PROPERTY
records_of = cc.records_of


def _sculpt(obj: Any) -> Any:
    if is_sculpted_solid(obj):
        return sculpt_of(obj)
    if not is_sculpt(obj):
        raise TypeError(f"obj: expected a HapticSculpt Sculpt or SculptedSolid object, got "
                        f"{getattr(obj, 'TypeId', type(obj).__name__)}")
    return obj


def _writer(sculpt: Any, records: list[cc.CurveConstraint]) -> Any:
    def write() -> None:
        if PROPERTY not in sculpt.PropertiesList:
            sculpt.addProperty("App::PropertyString", PROPERTY, "Sculpt", "Curves the surface must follow (JSON)")
            sculpt.setEditorMode(PROPERTY, 2)
        text = cc.records_to_json(records)
        if sculpt.CurveConstraints != text:
            sculpt.CurveConstraints = text
    return write


def not_in_session(sculpt: Any, what: str) -> Any:
    """``sculpt``'s live state; RuntimeError saying to stop the session first where one sculpts it
    (``what``: the change refused, "adding a curve constraint")."""
    live = sculpt.Proxy.live
    if live.session is not None:
        raise RuntimeError(f"{sculpt.Label}: stop the sculpting session before {what}")
    return live


def curve_constraints_of(obj: Any) -> list[dict[str, Any]]:
    """The curve constraints of a Sculpt or SculptedSolid, with how well each holds now: id,
    continuity, label, samples, normal (G1 asked for, or None), distance_mm (largest distance of
    the surface from the curve at its samples) and normal_deg (G1: the largest angle of the normal
    from the one held)."""
    sculpt = _sculpt(obj)
    surface = sculpt.Proxy.live.snapshot()
    poles = np.asarray(surface.poles, float).reshape(-1, 3)
    out = []
    for r in records_of(sculpt):
        distance, degrees = cc.misses(surface.surface, r, poles)
        out.append({"id": r.id, "continuity": r.continuity, "label": r.label, "samples": len(r.uv),
                    "normal": r.normal, "distance_mm": distance, "normal_deg": degrees})
    return out


def curve_points_on(obj: Any) -> list[np.ndarray]:
    """Where each curve constraint runs on the surface now ((K, 3) per curve): for drawing it."""
    sculpt = _sculpt(obj)
    surface = sculpt.Proxy.live.snapshot()
    poles = np.asarray(surface.poles, float).reshape(-1, 3)
    out = []
    for r in records_of(sculpt):
        rows = cc.rows(surface.surface, r.uv)
        out.append(rows.apply(rows.s, poles))
    return out


def constraint_along(obj: Any, curve: Any) -> dict[str, Any] | None:
    """The curve constraint (as :func:`curve_constraints_of` gives it) that follows ``curve``
    already, by where it runs (its ends within 1e-4 of the size, either way, and its length within
    0.1 %), or None."""
    sculpt = _sculpt(obj)
    points, _ = cc.curve_points(curve, cc.SAMPLES)
    size = sculpt.Proxy.live.snapshot().size

    def length(p: np.ndarray) -> float:
        return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    for r in records_of(sculpt):
        ends, mine = r.points[[0, -1]], points[[0, -1]]
        if min(np.abs(ends - mine).max(), np.abs(ends[::-1] - mine).max()) <= 1e-4 * size and \
                abs(length(r.points) - length(points)) <= 1e-3 * length(points):
            return next(c for c in curve_constraints_of(sculpt) if c["id"] == r.id)
    return None


def is_curve_id(cid: int) -> bool:
    """Whether ``cid`` is a curve constraint's id (they start at :data:`curve_constraint.FIRST_ID`)."""
    return isinstance(cid, int) and cid >= cc.FIRST_ID


def remove_curve_constraint(obj: Any, cid: int) -> None:
    """Removes curve constraint ``cid``: its poles are free again, the other curves still hold.
    One undo step; ValueError for an id it does not have."""
    sculpt = _sculpt(obj)
    live = not_in_session(sculpt, "removing a curve constraint")
    records = records_of(sculpt)
    kept = [r for r in records if r.id != cid]
    if len(kept) == len(records):
        raise ValueError(f"cid: {sculpt.Label} has no curve constraint {cid} "
                         f"(it has {', '.join(str(r.id) for r in records) or 'none'})")
    surface = live.surface
    held = list(surface.held_poles)
    moved, links = cc.relink(surface, kept, held, base_links(sculpt, surface),
                             np.asarray(surface.poles, float).reshape(-1, 3))
    live.edit(lambda s: s.hold_poles(held, links), "Remove curve constraint", inside=_writer(sculpt, kept))


def rehold(sculpt: Any, surface: Any, held: list[int], links: list[Any], poles: np.ndarray
           ) -> tuple[np.ndarray, list[Any], Any]:
    """The curves of ``sculpt`` held again on top of new ``held`` poles and ``links`` (without the
    curves' own) on ``surface`` with ``poles``: the poles (moved as little as possible where a curve
    no longer held), all links, and a function that writes the curves' new record (call it in the
    same transaction). ValueError naming a curve that cannot hold on top of them."""
    records = records_of(sculpt)
    if not records:
        return poles, list(links), lambda: None
    moved, all_links = cc.relink(surface, records, held, list(links), poles)
    return moved, all_links, _writer(sculpt, records)


def base_links(sculpt: Any, surface: Any) -> list[Any]:
    """The surface's links that are not a curve constraint's."""
    slaves = {p for r in records_of(sculpt) for p in r.slaves}
    return [link for link in surface.linked_poles if link[0] not in slaves]
