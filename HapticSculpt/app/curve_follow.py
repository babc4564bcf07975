"""Following a curve (issue 48): the scripting call that adds a curve constraint, and the net
refined along the curve where it has too little freedom to come within the tolerance
(:mod:`curve_constraint` holds the conditions, :mod:`net_refinement` refines the net)."""
from __future__ import annotations

from typing import Any

import numpy as np

from . import curve_constraint as cc
from .curve_api import _sculpt, _writer, base_links, not_in_session

#: How near a followed curve the surface passes by default (mm), everywhere along it.
DEFAULT_TOLERANCE = 0.001


def add_curve_constraint(obj: Any, curve: Any, continuity: str = "G0", normal: Any = None,
                         tolerance: float | None = None, replace: int | None = None) -> int:
    """Makes the sculpt (a Sculpt or a SculptedSolid) follow ``curve`` exactly: "G0" passes
    through it within ``tolerance`` (mm, everywhere along it; default 0.001 mm), "G1" also keeps
    the surface's normal along it at ``normal`` (a vector; None keeps the normal the surface has
    there now) within 0.01 degrees. ``curve`` is a document object with one edge or wire (a Sketch,
    a Part feature, a Draft wire), a ``Part.Edge`` or ``Part.Wire``, or a list of points (the
    natural cubic spline through them, by chord length).

    A curve off the surface (up to a quarter of its size away) pulls it onto itself, the poles
    moving as little as possible, straight across the sheet where it faces one way (along the
    normal of the plane its net lies nearest), no pole further than 10 times the curve's largest
    distance; the pulled shape is the new rest shape. Where the net has too
    little freedom along the curve to come within the tolerance, it is refined there: knots
    inserted in the spans the curve crosses and their neighbours (the shape unchanged by the
    insertion), pass after pass, up to half the sculpt's mesh points per direction; the sculpt's
    ``last_curve`` says how (``refined_from``, ``refined_to``). The constraint is hard: exact linear
    conditions on the poles, kept by every stroke and session. One undo step with the refinement
    (Undo gives the net back as it was; not during a session: RuntimeError), which also removes
    curve constraint ``replace`` if given (the GUI's Follow curve turns a G0 curve into G1 so).
    Returns its id (for :func:`remove_constraint`). ValueError saying why where no net can
    follow: a curve too far away, a normal the curve is not perpendicular to, a net that cannot be
    refined further (its mesh, held poles that are not its edges', symmetry)."""
    sculpt = _sculpt(obj)
    if tolerance is None:
        tolerance = DEFAULT_TOLERANCE
    elif isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not 1e-9 <= tolerance <= 1e3:
        raise ValueError(f"tolerance: a length in mm from 1e-9 to 1000, got {tolerance!r}")
    tolerance = float(tolerance)
    live = not_in_session(sculpt, "adding a curve constraint")
    surface = live.surface
    records = cc.records_of(sculpt)
    cid = max([r.id for r in records], default=cc.FIRST_ID - 1) + 1
    held, links = list(surface.held_poles), base_links(sculpt, surface)
    if replace is not None:
        if replace not in [r.id for r in records]:
            raise ValueError(f"replace: {sculpt.Label} has no curve constraint {replace}")
        records = [r for r in records if r.id != replace]
    controls = tuple(surface.surface.controls)
    try:
        record, moved, all_links = cc.make(surface, curve, continuity, normal, cid, held, links, records, tolerance)
    except cc.NetTooCoarse as coarse:
        _follow_refined(sculpt, curve, continuity, normal, cid, records, tolerance, coarse)
        return cid
    try:
        _check_beside(surface, record, held, all_links, moved, tolerance)
    except cc.NetTooCoarse as better:
        try:
            _follow_refined(sculpt, curve, continuity, normal, cid, records, tolerance, better)
            return cid
        except ValueError:
            pass  # (no finer net can be made: held on this one, as it is)
    before = np.asarray(surface.poles, float).reshape(-1, 3)
    pulled = not np.array_equal(moved, before)
    shape = np.asarray(surface.poles).shape

    def change(s: Any) -> None:
        if pulled:
            s.set_poles(moved.reshape(shape))
        s.hold_poles(held, all_links)
    live.edit(change, "Follow curve", keep_shape=pulled, inside=_writer(sculpt, records + [record]))
    live.last_curve = {"id": cid, "label": record.label, "tolerance_mm": tolerance, "refined_from": list(controls),
                       "refined_to": list(controls)}
    return cid


def _check_beside(dynamic: Any, record: cc.CurveConstraint, held: list[int], links: list[Any], moved: np.ndarray,
                  tolerance: float) -> None:
    """NetTooCoarse (``held_anyway``) where the net holds the curve but a finer one would do
    better beside it: where its conditions leave a pull beside it no room to move the surface
    (cc.room_beside), or where the pull onto it (``dynamic``'s poles to ``moved``) takes the surface
    far beside it along (cc.reach_beside: a line across a bump flattened the bump). Refined like a
    net that cannot reach the curve, and held on the finest net there is where none does better."""
    reach = None
    if cc.room_beside(dynamic.surface, record.uv, held, links) < cc.ROOM_SHARE:
        why = "it leaves the surface no room to move beside it"
    else:
        reach = cc.reach_beside(dynamic.surface, record.uv, np.asarray(dynamic.poles, float), moved, tolerance,
                                dynamic.size)
        if reach <= cc.REACH_SHARE:
            return
        why = "the pull onto it moves the surface far beside it"
    coarse = cc.NetTooCoarse(f"'{record.label}' {record.continuity}", why, "use more controls", record.uv)
    coarse.held_anyway, coarse.reach = True, reach
    raise coarse


def _follow_refined(sculpt: Any, curve: Any, continuity: str, normal: Any, cid: int,
                    records: list[cc.CurveConstraint], tolerance: float, coarse: cc.NetTooCoarse) -> None:
    """Refines ``sculpt``'s net along the curve until it follows it (see add_curve_constraint) and
    writes it, the curve held, as one undo step "Follow curve"; ValueError where it cannot."""
    from . import sculpt_state
    from .net_refinement import refined_work
    from .sculpted_solid import solid_of
    from .undo import transaction
    live = sculpt.Proxy.live
    work = sculpt_state.restore(live.stored())
    start = work.surface
    mesh = tuple(sculpt_state.capture(work).settings["mesh"])
    limit = (max(mesh[0] // 2, start.controls[0]), max(mesh[1] // 2, start.controls[1]))
    # (the finer net that held the curve best, though not well beside it, with what held it: the one
    # whose pull reaches least far beside it, else the finest without room; kept over the net given
    # only where its reach is REACH_GAIN of that net's or less)
    held_anyway, best = None, (np.inf, 0)
    given = coarse.reach
    while True:
        controls = tuple(work.surface.controls)
        room = (limit[0] - controls[0], limit[1] - controls[1])
        knots = cc.refinement_knots(work.surface, coarse.uv, room)
        made = refined_work(sculpt, work, knots) if knots[0] or knots[1] else None
        if made is None and held_anyway is not None:  # (held as well as the nets made do beside it)
            if given is not None and best[0] > cc.REACH_GAIN * given:  # (the net given holds it as well: held there)
                raise ValueError(f"curve: {coarse.curve}: no finer net reaches less far beside it")
            finer, held, walls, record, moved, all_links = held_anyway
            break
        if made is None:
            first = tuple(start.controls)
            if knots[0] or knots[1]:  # (room, but the holds could not be carried to a finer net)
                raise ValueError(f"curve: the surface cannot follow {coarse.curve}: {coarse.why}, and its net cannot be "
                                 "refined (its held poles are not its edges', or it is symmetric); free its edges, or "
                                 "use a curve nearer the surface or smoother") from None
            refined = f"refined from {first[0]} x {first[1]} " if first != controls else ""
            raise ValueError(f"curve: the surface cannot follow {coarse.curve}: {refined}up to {controls[0]} x "
                             f"{controls[1]} controls, the most its {mesh[0]} x {mesh[1]} mesh takes (half its points "
                             f"per direction), {coarse.why.removeprefix(f'with {controls[0]} x {controls[1]} controls ')}"
                             "; make the sculpt with a finer mesh, or use a curve nearer the surface or smoother") from None
        finer, held, links, walls = made
        try:
            record, moved, all_links = cc.make(finer, curve, continuity, normal, cid, held, links, records, tolerance)
            _check_beside(finer, record, held, all_links, moved, tolerance)
            break
        except cc.NetTooCoarse as again:
            rank = (np.inf if again.reach is None else again.reach, -int(np.prod(finer.surface.controls)))
            if again.held_anyway and rank <= best:
                held_anyway, best = (finer, held, walls, record, moved, all_links), rank
            finer.hold_poles(held, links)
            if walls:
                finer.set_walls(walls)
            work, coarse = finer, again
    now = tuple(finer.surface.controls)
    pulled = not np.array_equal(moved, np.asarray(finer.poles, float).reshape(-1, 3))
    finer.set_poles(moved.reshape(now[0], now[1], 3))
    finer.hold_poles(held, all_links)
    if walls:
        finer.set_walls(walls)
    if pulled:
        finer.relax()  # (the pulled shape is the rest shape, as without refinement)
    state = sculpt_state.capture(finer)
    solid = solid_of(sculpt)
    with transaction(sculpt.Document, "Follow curve"):
        if solid is not None:
            from .solid_api import record_refinement
            record_refinement(solid, start, finer.surface)
        live.write(state)
        _writer(sculpt, records + [record])()
        live.document_changed()  # (the cached surface is not the refined one: read it again)
    live.last_curve = {"id": cid, "label": record.label, "tolerance_mm": tolerance,
                       "refined_from": list(start.controls), "refined_to": list(now)}
