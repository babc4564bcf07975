"""Scripting API of scan targets (issue 30): give a sculpt a scan to be measured against and pulled
toward, read how far the scan lies from it, fit it.

The target is a document object the Sculpt's ``Target`` property links to (:mod:`scan_target`);
``TargetTolerance`` is a number beside it and ``Deviation`` is the report (JSON, read-only) kept up
to date at each recompute (:mod:`scan_deviation`). The pull (data springs toward the target, in
sessions and ``hs.run``) is part of the sculpt state: on or off, its strength, and the ``pull`` map
painted like the other material maps.
"""
from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from . import scan_deviation, scan_target
from .net_refinement import refined_sculpt
from .api import _sculpt as api_sculpt
from .sculpt_properties import read_state
from .sculpted_solid import chain_of_solid, solid_of
from .undo import transaction

GROUP = "Scan"


def _sculpt(obj: Any) -> Any:
    return api_sculpt(obj, solids=True)


def _number(value: Any, name: str, low: float, high: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    x = float(value)
    if not (math.isfinite(x) and low <= x <= high):
        raise ValueError(f"{name}: must be in [{low:g}, {high:g}], got {value!r}")
    return x


def _ensure_properties(sculpt: Any) -> None:
    props = sculpt.PropertiesList
    if "Target" not in props:
        sculpt.addProperty("App::PropertyLink", "Target", GROUP, "The scan the surface is measured against "
                           "(a mesh or point cloud in the document)")
    if "TargetTolerance" not in props:  # (a length: the property editor shows and takes its unit)
        sculpt.addProperty("App::PropertyLength", "TargetTolerance", GROUP, "Deviation a point may have "
                           "and count as within")
    if "TargetSide" not in props:
        sculpt.addProperty("App::PropertyInteger", "TargetSide", GROUP, "+1 or -1: the sign that makes a "
                           "deviation positive outside a sculpted solid; 0 on a sheet (along its normal)")
        sculpt.setEditorMode("TargetSide", 2)
    if scan_deviation.PROPERTY not in props:
        sculpt.addProperty("App::PropertyString", scan_deviation.PROPERTY, GROUP, "How far the target lies from "
                           "the surface (JSON: max_mm, mean_mm, p95_mm, within_pct, tolerance_mm, points)")
        sculpt.setEditorMode(scan_deviation.PROPERTY, 1)


def _outward_side(sculpt: Any) -> int:
    """+1 or -1 so that a deviation is positive outside the part on a sculpted solid's face (the
    surface's normal turned outwards); 0 on a sheet, whose sign follows its normal du x dv."""
    solid = solid_of(sculpt)
    if solid is None or solid.Shape.isNull() or not solid.Shape.Solids:
        return 0
    import FreeCAD
    surface = scan_deviation.core_surface(read_state(sculpt))
    (u0, u1), (v0, v1) = surface.domain
    u, v = (u0 + u1) / 2, (v0 + v1) / 2
    step = 1e-3 * solid.Shape.BoundBox.DiagonalLength
    probe = np.asarray(surface.evaluate(u, v)["point"]) + step * np.asarray(surface.normal(u, v))
    return -1 if solid.Shape.isInside(FreeCAD.Vector(*probe), step * 1e-3, True) else 1


def set_target(obj: Any, target: Any, weight: float = 1.0, tolerance: float = 0.1) -> Any:
    """Sets the scan ``obj`` (a Sculpt or SculptedSolid) is measured against and pulled toward,
    and returns its document object. ``target``: a ``Mesh::Feature`` or ``Points::Feature`` of the
    document (linked), a path to an STL, OBJ or PLY file (read into a new Mesh or Points object), or
    an (n, 3) array of points (up to 20 million; kept in a new Points object). The target's
    ``Placement`` positions it. ``weight`` (0..1e6) is the strength of its pull (see
    :func:`set_pull`; 0 switches it off); ``tolerance`` (mm, > 0) is the deviation a point may have
    to count as within.

    One undo step (the new object, the link and the pull together); saved with the document.
    ValueError or TypeError naming the argument for an empty, non-finite, missing or unreadable
    target, and nothing changes. Returns the target object."""
    sculpt = _sculpt(obj)
    weight = _number(weight, "weight", 0.0, 1e6)
    tolerance = _number(tolerance, "tolerance", 1e-9, 1e6)
    doc = sculpt.Document
    if hasattr(target, "isDerivedFrom"):
        if not scan_target.is_target_object(target):
            raise TypeError(f"target: expected a mesh or point cloud, got {getattr(target, 'TypeId', '?')}")
        if target.Document is not doc:
            raise ValueError("target: is in another document")
        scan_target.points_of(target)  # empty or not finite: refused before anything changes
        made = None
    elif isinstance(target, (str, os.PathLike)) or hasattr(target, "__len__") or hasattr(target, "__array__"):
        made = target
    else:
        raise TypeError(f"target: expected a mesh or point cloud object, a file path or an (n, 3) array, got "
                        f"{type(target).__name__}")
    if made is not None and not isinstance(made, (str, os.PathLike)):
        scan_target.checked_points(made)  # validated before the transaction opens
    # The properties are added outside the undo step: FreeCAD's redo of a link added and set in one
    # transaction with the object it links to restores a link to the deleted object.
    _ensure_properties(sculpt)
    chosen = []

    def link() -> None:
        linked = scan_target.add_target_object(doc, made, f"{sculpt.Name}Target") if made is not None else target
        sculpt.Proxy.setting_target = True  # (the report is measured once, below, not at each property)
        try:
            sculpt.Target = linked
            sculpt.TargetTolerance = tolerance
            sculpt.TargetSide = _outward_side(sculpt)
        finally:
            sculpt.Proxy.setting_target = False
        scan_deviation.refresh_property(sculpt)
        chosen.append(linked)

    live = sculpt.Proxy.live
    if live.session is None:
        live.edit(lambda s: s.set_pull(weight > 0, weight if weight > 0 else s.pull["strength"]), "Set target",
                  inside=link)
    else:  # (the session commits the pull's change when it took it: its own undo step)
        with transaction(doc, "Set target"):
            link()
        if weight != live.snapshot().pull["strength"] or (weight > 0) != live.snapshot().pull["enabled"]:
            set_pull(sculpt, weight > 0, weight if weight > 0 else None)
    return chosen[0]  # (the link's change hands the surface its new target: SculptFeature.onChanged)


def set_pull(obj: Any, enabled: bool | None = None, strength: float | None = None) -> None:
    """Switches the pull toward the target on or off and sets its ``strength`` (0..1e6; None keeps
    either). At strength 1 a mesh point pulled alone settles on the scan in about 1/40 s, and the
    pull outweighs the sheet's own stiffness over a feature a few mesh cells wide; the ``pull`` map
    (``hs.paint(obj, "pull", ...)``) scales it where it is painted, 0 nowhere. The pull acts in
    sessions and ``hs.run``: each mesh point hangs on a critically damped spring to the nearest
    scan point within a tenth of the surface's size, dropped where that point lies past the
    scan's edge or across a hole. One undo step; during a session it takes effect at once."""
    sculpt = _sculpt(obj)
    if enabled is not None and not isinstance(enabled, bool):
        raise TypeError(f"enabled: expected True, False or None, got {type(enabled).__name__}")
    if strength is not None:
        strength = _number(strength, "strength", 0.0, 1e6)
    live = sculpt.Proxy.live
    current = live.snapshot().pull
    on = current["enabled"] if enabled is None else enabled
    value = current["strength"] if strength is None else strength
    live.edit(lambda s: s.set_pull(on, value), "Pull toward target" if on else "Stop pulling toward target")


def pull_of(obj: Any) -> dict[str, Any]:
    """The pull toward the target: ``enabled``, ``strength``, ``target`` (whether one is set),
    ``reach`` (mm), ``active`` (it pulls), ``anchored`` (mesh points it holds now)."""
    return dict(_sculpt(obj).Proxy.live.snapshot().pull)


def clear_target(obj: Any) -> None:
    """Removes the target link (the target object stays in the document); the pull stops. One undo step."""
    sculpt = _sculpt(obj)
    if "Target" not in sculpt.PropertiesList or sculpt.Target is None:
        return
    with transaction(sculpt.Document, "Clear target"):
        sculpt.Target = None
        scan_deviation.refresh_property(sculpt)


def target_object(obj: Any) -> Any:
    """The document object ``obj``'s target is, or None."""
    sculpt = _sculpt(obj)
    return sculpt.Target if "Target" in sculpt.PropertiesList else None


def deviation_of(obj: Any, tolerance: float | None = None) -> dict[str, Any]:
    """How far the target's points lie from the surface, on all of them: ``max_mm``, ``mean_mm``,
    ``p95_mm`` (of |distance|), ``within_pct`` (share within ``tolerance``; default the sculpt's
    ``TargetTolerance``), ``tolerance_mm``, ``points`` (measured: over the surface), plus
    ``beyond_edge`` (points past its edges, not measured), ``signed`` and the signed
    ``min_signed_mm``, ``max_signed_mm``, ``mean_signed_mm``: positive outside a sculpted solid,
    along the normal (du x dv) of a sheet. ValueError if ``obj`` has no target or no point lies
    over the surface."""
    sculpt = _sculpt(obj)
    target = scan_target.target_of(sculpt)
    if target is None:
        raise ValueError(f"obj: {sculpt.Label} has no target (hs.set_target)")
    tol = float(sculpt.TargetTolerance) if tolerance is None else _number(tolerance, "tolerance", 1e-9, 1e6)
    try:
        return scan_deviation.measure(sculpt, target.points, tol)
    except ValueError as exc:
        raise ValueError(f"{sculpt.Label}: {exc}") from None


#: The net a fit refines up to when ``max_controls`` is not given (per direction).
DEFAULT_MAX_CONTROLS = 48
#: A cell's root mean square distance, as a share of the tolerance, beyond which its points are
#: off because of the net, not the scan's noise (a scan within the tolerance at 95 % has noise of
#: about half of it: its cells stay below).
SYSTEMATIC = 0.6


def _max_controls(value: Any, controls: tuple[int, int]) -> tuple[int, int]:
    if value is None:
        return (max(DEFAULT_MAX_CONTROLS, controls[0]), max(DEFAULT_MAX_CONTROLS, controls[1]))
    pair = (value, value) if isinstance(value, int) and not isinstance(value, bool) else value
    try:
        a, b = pair
    except (TypeError, ValueError):
        raise TypeError(f"max_controls: expected a whole number or a pair, got {value!r}") from None
    for x in (a, b):
        if isinstance(x, bool) or not isinstance(x, int) or not 4 <= x <= 256:
            raise ValueError(f"max_controls: whole numbers in 4..256, got {value!r}")
    return int(a), int(b)


def _refine_knots(surface: Any, r: dict[str, Any], tolerance: float, room: tuple[int, int]) -> tuple[list[float], list[float]]:
    """Knots for the spans where the fit is off, not the scan's noise: the cells (a u span by a v
    span) whose points out of the tolerance are at least a quarter of the worst cell's and whose
    root mean square distance exceeds SYSTEMATIC of the tolerance (noise well within the tolerance
    leaves it below; a shape the net cannot follow does not); the midpoints of their spans, a third
    of the spans at most per pass, at most ``room`` per direction."""
    from .scan_fit import span_cells
    kept = r["weights"] > 0
    d = r["distance"][kept]
    bu, bv = (np.unique(np.asarray(k, float)) for k in (surface.knots_u, surface.knots_v))
    cell = span_cells(surface, r["uv"][kept])
    cells = (len(bu) - 1) * (len(bv) - 1)
    count = np.bincount(cell, minlength=cells)
    bad = np.bincount(cell, weights=(np.abs(d) > tolerance).astype(float), minlength=cells)
    rms = np.sqrt(np.bincount(cell, weights=d * d, minlength=cells) / np.maximum(count, 1))
    off = (bad >= 0.25 * bad.max(initial=0)) & (bad > 0) & (rms > SYSTEMATIC * tolerance)
    out: tuple[list[float], list[float]] = ([], [])
    for direction, (breaks, index) in enumerate(((bu, np.arange(cells) // (len(bv) - 1)),
                                                  (bv, np.arange(cells) % (len(bv) - 1)))):
        if room[direction] <= 0:
            continue
        score = np.bincount(index[off], weights=bad[off], minlength=len(breaks) - 1)
        order = [k for k in np.argsort(-score, kind="stable") if score[k] > 0]
        chosen = order[: max(1, min(room[direction], (len(breaks) - 1) // 3))] if order else []
        out[direction].extend(float(0.5 * (breaks[k] + breaks[k + 1])) for k in sorted(chosen))
    return out


#: A face of a solid's faces sculpted as one surface that holds less than this share of the scan's
#: points over the surface is one the scan does not reach: it keeps its shape through the fit.
UNCOVERED_SHARE = 0.002


def _uncovered_poles(sculpt: Any, surface: Any, u_over: np.ndarray) -> list[int]:
    """The poles of a sculpted solid's faces (sculpted as one surface, joined along u) whose whole
    support lies on a face the scan does not reach (``u_over``: the joined u of the points over the
    surface). Held while fitting: no point shapes them, and a net too coarse for the scan rings
    (least squares overshoot a bump it cannot follow): the smoothing alone let that ring on through
    a G2 seam into a round, 2 mm out of its part on the net as made, 20 mm once refined."""
    solid = solid_of(sculpt)
    if solid is None or u_over.size == 0:
        return []
    chain = chain_of_solid(solid)
    if len(chain.placements) < 2:
        return []
    knots, p = np.asarray(surface.knots_u, float), surface.degree[0]
    nu, nv = surface.controls
    rows: set[int] = set()
    for placement in chain.placements:
        lo, hi = sorted(placement.span)
        if np.count_nonzero((u_over >= lo) & (u_over <= hi)) >= UNCOVERED_SHARE * u_over.size:
            continue
        rows |= {i for i in range(nu) if knots[i] >= lo - 1e-9 * (hi - lo) and knots[i + p + 1] <= hi + 1e-9 * (hi - lo)}
    return [i * nv + j for i in sorted(rows) for j in range(nv)]


def _fit_holding(work: Any, points: np.ndarray, tolerance: float, frozen: list[int]) -> tuple[Any, dict[str, Any]]:
    """``fit_net_unfolded`` with the ``frozen`` poles held too (the surface's own holds back afterwards)."""
    from .scan_fit import fit_net_unfolded
    links = [tuple(link) for link in work.linked_poles]
    extra = sorted(set(frozen) - set(work.held_poles) - {link[0] for link in links})
    if not extra:
        return fit_net_unfolded(work, points, tolerance)
    held = list(work.held_poles)
    work.hold_poles(sorted(held + extra), links)
    try:
        return fit_net_unfolded(work, points, tolerance)
    finally:
        work.hold_poles(held, links)


def _blockers(sculpt: Any, work: Any, points: np.ndarray, tolerance: float, held: dict[str, Any],
              within_pct: float) -> dict[str, Any] | None:
    """What keeps the fit of ``work`` (its projection ``held``) out of the tolerance when its holds
    do (fit_blockers): ``message``, ``edges`` (the held edges, each with its share of the scan) and
    ``free_within_pct``; None when the holds are not what blocks it."""
    from . import fit_blockers, sculpt_state
    from .api import held_boundary
    from .scan_fit import fit_net_unfolded
    found = fit_blockers.diagnose(sculpt_state.restore(sculpt.Proxy.live.stored()), points, tolerance, held,
                                  within_pct, lambda trial: fit_net_unfolded(trial, points, tolerance))
    if found is None:
        return None
    solid = solid_of(sculpt)
    if solid is None:  # (a sheet: its sides, each with the share blocked beside it)
        surface = work.surface
        (p, q), ku, kv = surface.degree, np.asarray(surface.knots_u), np.asarray(surface.knots_v)
        bounds = (float(ku[p]), float(ku[-p - 1]), float(kv[q]), float(kv[-q - 1]))
        edges = fit_blockers.by_edge(found, held_boundary(sculpt), bounds)
        message = fit_blockers.sentence(found, edges, "its held edges", tolerance,
                                        "Free edges and fit: hold_boundary(obj, 'free'), then fit again")
    else:  # (a solid's edges cannot be free: held G0 they still meet their neighbours)
        from .sculpted_solid import boundary_of
        edges = [{"edge": e, "kind": k, "share_pct": None} for e, k in boundary_of(solid).items() if k not in ("free", "G0")]
        message = fit_blockers.sentence(found, [], ", ".join(f"{e['edge']} ({e['kind']})" for e in edges), tolerance,
                                        "Free edges and fit: those edges held G0, then fit again")
    return {"message": message, "edges": edges, "free_within_pct": found["free_within_pct"]}


def fit_to_target(obj: Any, tolerance: float, max_controls: Any = None) -> dict[str, Any]:
    """Relaxes the surface of ``obj`` (a Sculpt or SculptedSolid) onto its target (``set_target``)
    until at least 95 % of the target's points over the surface lie within ``tolerance`` (mm).

    Each pass fits the poles to the points (least squares at the points' closest parameters,
    repeated as they settle), weighing out the outliers (farther than 4 robust standard deviations
    and twice the tolerance, unless they gather in a span: a region the surface has not reached)
    and the points past the surface's edges; where there are no points
    (a hole) the surface is bridged by its curvature variation. Held edges, seams, symmetry and
    curve constraints hold exactly. Where the fit stays out of the tolerance, knots are inserted in
    the spans whose points are off by more than the scan's noise (exactly: the shape is kept) and it
    fits again, up to ``max_controls`` poles per direction (a number or a pair; default 48, never
    fewer than the net has), half the mesh's points and one pole per 12 points. On a sculpted solid's
    face the finer net is held as the face was (its edges, trims and seams: held poles, seam links and
    walls found again), and the solid keeps the knots, so the net it makes again when its base
    changes is the same; of faces sculpted as one, one the scan does not reach keeps its shape. A
    sheet whose held poles are not its edges' and a symmetric sculpt are fitted on their net as it
    is (the report says so). A net that folds in its own plane (its poles slid there, where little
    holds them) is fitted again holding them more firmly; if it still folds, the coarser net's fit
    is kept (the report says so), or on the first net nothing changes (ValueError).

    One undo step; the fitted shape is the rest shape. Not during a session (RuntimeError).
    Returns the report: ``met``, ``within_pct``, ``tolerance_mm``, ``controls``, ``points``,
    ``outliers``, ``beyond_edge``, ``message`` (where and why it fell short) and ``rounds`` (one
    per net: its controls, within_pct, max_mm, p95_mm, outliers, worst_uv)."""
    from . import sculpt_state
    from .scan_fit import POINTS_PER_POLE, WITHIN_GOAL, FitReport
    sculpt = _sculpt(obj)
    tolerance = _number(tolerance, "tolerance", 1e-6, 1e6)
    live = sculpt.Proxy.live
    if live.session is not None:
        raise RuntimeError(f"{sculpt.Label}: stop the sculpting session before fitting it")
    target = scan_target.target_of(sculpt)
    if target is None:
        raise ValueError(f"obj: {sculpt.Label} has no target (hs.set_target)")
    work = sculpt_state.restore(live.stored())
    limit = _max_controls(max_controls, tuple(work.surface.controls))
    points = target.points
    if work.symmetry is not None:  # the symmetric fit of the points is the fit of them and their mirror image
        _, point, normal = work.symmetry
        n = np.asarray(normal, float) / np.linalg.norm(normal)
        points = np.vstack([points, points - 2.0 * ((points - np.asarray(point, float)) @ n)[:, None] * n])
    solid = solid_of(sculpt)
    start = work.surface
    first = start.project(points)
    u_over = first["uv"][~first["beyond_edge"], 0]
    report = FitReport(tolerance, 0.0, False, tuple(work.surface.controls))
    coarser: Any = None  # (the last net's fit, kept while a finer one is tried)
    while True:
        try:
            summary, r = _fit_holding(work, points, tolerance, _uncovered_poles(sculpt, work.surface, u_over))
        except ValueError as exc:  # (a net that folds: never written)
            if coarser is None:
                blocked = _blockers(sculpt, work, points, tolerance, first, 0.0)
                raise ValueError(f"{sculpt.Label}: not fitted, {blocked['message'] if blocked else exc} "
                                 f"(nothing changed)") from None
            work, summary, r = coarser
            report.within_pct, report.controls = summary.within_pct, summary.controls
            where = (f"worst near (u, v) = ({summary.worst_uv[0]:.3f}, {summary.worst_uv[1]:.3f}), "
                     f"{summary.max_mm:.3g} mm off")
            report.message = f"kept the {summary.controls} net's fit: {exc} ({where})"
            break
        report.rounds.append(summary)
        report.within_pct, report.controls = summary.within_pct, summary.controls
        if summary.within_pct >= WITHIN_GOAL:
            report.met = True
            break
        controls = tuple(work.surface.controls)
        room = (limit[0] - controls[0], limit[1] - controls[1])
        where = f"worst near (u, v) = ({summary.worst_uv[0]:.3f}, {summary.worst_uv[1]:.3f}), {summary.max_mm:.3g} mm off"
        if room[0] <= 0 and room[1] <= 0:
            report.message = f"stopped at max_controls {limit}: {where}"
            break
        mesh = tuple(sculpt_state.capture(work).settings["mesh"])
        room = (min(room[0], mesh[0] // 2 - controls[0]), min(room[1], mesh[1] // 2 - controls[1]))
        if room[0] <= 0 and room[1] <= 0:
            report.message = (f"stopped at {controls} controls: its {mesh[0]} x {mesh[1]} mesh samples at most half "
                              f"as many (make the sculpt with a finer mesh for more): {where}")
            break
        over_surface = int(np.count_nonzero(~r["beyond_edge"]))
        if (controls[0] + 1) * (controls[1] + 1) > over_surface / POINTS_PER_POLE:
            report.message = (f"stopped at {controls} controls: {over_surface} points determine at most "
                              f"{over_surface // POINTS_PER_POLE} poles ({POINTS_PER_POLE} a pole): {where}")
            break
        knots = _refine_knots(work.surface, r, tolerance, room)
        if not knots[0] and not knots[1]:
            report.message = (f"what is left out of the tolerance is the scan's noise (no span's points are off by "
                              f"more than {SYSTEMATIC:g} of it in root mean square; p95 {summary.p95_mm:.3g} mm): {where}")
            break
        finer = refined_sculpt(sculpt, work, knots)
        if finer is None:
            report.message = (f"not refined (its held poles are not its edges', it is symmetric, or its mesh has no "
                              f"room for more poles): fitted on its net as it is; {where}")
            break
        if tuple(finer.surface.controls) == controls:
            report.message = f"no span left to refine: {where}"
            break
        coarser, work = (work, summary, r), finer
    if not report.met:  # (what keeps it out of reach: the holds, said so, rather than a reason about the net)
        blocked = _blockers(sculpt, work, points, tolerance, r, report.within_pct)
        if blocked is not None:
            report.message = blocked["message"] + (f"; {report.message}" if report.message else "")
            report.blocked_by, report.free_within_pct = blocked["edges"], blocked["free_within_pct"]
    over = ~r["beyond_edge"]
    report.points = int(np.count_nonzero(over[: len(target.points)]))
    report.beyond_edge = int(len(target.points) - report.points)
    report.outliers = int(np.count_nonzero(over[: len(target.points)] & (r["weights"][: len(target.points)] == 0)))
    work.relax()
    state = sculpt_state.capture(work)
    with transaction(sculpt.Document, "Fit to target"):
        if solid is not None and tuple(work.surface.controls) != tuple(start.controls):
            from .solid_api import record_refinement
            record_refinement(solid, start, work.surface)
        if float(sculpt.TargetTolerance) != tolerance:  # (the tolerance asked for is the one judged against)
            sculpt.TargetTolerance = tolerance
        live.write(state)
        live.document_changed()  # (the cached surface is not the fitted one: read it again)
        scan_deviation.refresh_property(sculpt)
    live.last_fit = report.as_dict()
    return live.last_fit
