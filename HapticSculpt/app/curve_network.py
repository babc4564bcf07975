"""A fair patch through a network of curves (issue 48), where Alias and Rhino users start a surface.

Three or four boundary curves that close into a loop, and curves inside it: the patch's edges
follow the boundary and it passes through every interior curve, each held as a curve constraint
(within the tolerance, the net refined along a curve where it must be, as Follow curve does), and
between the curves it takes the least bending energy, the thin-plate term
``integral |S_uu|^2 + 2 |S_uv|^2 + |S_vv|^2`` over its parameters (D-NURBS' fair surface through
curves), the curves' conditions held exactly. It starts from the Coons patch of the boundary; a
three-sided boundary is four-sided with its longest curve split at its middle (a straight corner,
no degenerate edge), where the parameters crowd: with no curve inside, that patch keeps the Coons
shape (the parameters' energy would bend it there). The curves stay held while the patch is
sculpted afterwards: the boundary as its edges (held G0), the others as curve constraints.
"""
from __future__ import annotations

import itertools
from typing import Any, Sequence

import numpy as np

from .. import core
from . import curve_constraint as cc
from . import sculpt_state
from .api import _add_sculpt, _document, _material, _sculpt_state
from .curve_api import _writer
from .source_surface import SourceSurface, refined
from .thin_plate import bending_matrix, design
from .undo import transaction

#: Boundary curves whose ends are farther apart than this share of the loop's size do not close.
CLOSE_SHARE = 1e-3
#: Passes of knots inserted along each interior curve after it holds, so that the poles beside it
#: are free to take the fair transition (its conditions fix those whose support it crosses).
ROOM_PASSES = 1
#: Samples per curve for the loop, the Coons patch and its fit.
SAMPLES = 200
#: An inside curve that ends at a corner of the loop must leave it in the plane the two boundary
#: curves' tangents span there (a smooth patch has one tangent plane at a point): past this angle
#: (degrees) it is refused, saying so (it was refused as a curve the net could not follow, "use
#: more controls", which no net fixes).
CORNER_DEGREES = 1.0
#: The finest mass-point mesh a network's patch is given (per direction) when its curves need a
#: finer net than the default mesh takes (half its points): the patch then steps slower.
MOST_MESH = 64
#: The most curves :func:`split_network` sorts (its search tries every 4 and 3 of them).
MOST_CURVES = 16


def _loop(curves: list[tuple[np.ndarray, str]]) -> list[tuple[np.ndarray, str]]:
    """The boundary curves ordered and turned head to tail into a closed loop; ValueError saying
    which end meets no other."""
    ends = np.array([[p[0], p[-1]] for p, _ in curves])
    size = float(np.linalg.norm(np.ptp(ends.reshape(-1, 3), axis=0)))
    if size == 0.0:
        raise ValueError("boundary: the curves lie at one point")
    gap = CLOSE_SHARE * size
    left = list(range(1, len(curves)))
    loop = [curves[0]]
    for _ in range(len(curves) - 1):
        tail = loop[-1][0][-1]
        near = [(float(np.linalg.norm(curves[k][0][end] - tail)), k, end) for k in left for end in (0, -1)]
        distance, k, end = min(near)
        if distance > gap:
            raise ValueError(f"boundary: the curves do not close: the end of '{loop[-1][1]}' at "
                             f"({', '.join(f'{x:.4g}' for x in tail)}) is {distance:.3g} mm from every other "
                             f"curve's end (they must meet within {gap:.3g} mm)")
        points, label = curves[k]
        loop.append((points if end == 0 else points[::-1], label))
        left.remove(k)
    closing = float(np.linalg.norm(loop[-1][0][-1] - loop[0][0][0]))
    if closing > gap:
        raise ValueError(f"boundary: the curves do not close: '{loop[-1][1]}' ends {closing:.3g} mm from where "
                         f"'{loop[0][1]}' starts (they must meet within {gap:.3g} mm)")
    return loop


def _unit_vector(v: np.ndarray) -> np.ndarray:
    return v / max(float(np.linalg.norm(v)), 1e-300)


def _check_corners(loop: list[tuple[np.ndarray, str]], inside: list[tuple[np.ndarray, str]], size: float) -> None:
    """ValueError for an inside curve that ends at a corner of the loop out of the plane of the
    boundary tangents there (see CORNER_DEGREES); a corner where the loop runs straight on has no
    such plane and takes any."""
    gap = CLOSE_SHARE * size
    for k in range(len(loop)):
        (before, first), (after, second) = loop[k - 1], loop[k]
        corner = after[0]
        normal = np.cross(_unit_vector(before[-2] - before[-1]), _unit_vector(after[1] - after[0]))
        if np.linalg.norm(normal) < np.sin(np.radians(10.0)):
            continue
        normal = _unit_vector(normal)
        for points, label in inside:
            for end, next_point in ((points[0], points[1]), (points[-1], points[-2])):
                if np.linalg.norm(end - corner) > gap:
                    continue
                out = float(np.degrees(np.arcsin(min(1.0, abs(_unit_vector(next_point - end) @ normal)))))
                if out > CORNER_DEGREES:
                    raise ValueError(f"curve: '{label}' ends at the corner where '{first}' and '{second}' meet, "
                                     f"{out:.3g} degrees out of the plane their tangents span there: a smooth patch "
                                     f"has one tangent plane at a point, so none passes through all three; end "
                                     f"'{label}' on a side, or let it leave the corner in that plane")


def split_network(curves: Sequence[Any]) -> tuple[list[int], list[int]]:
    """Which of ``curves`` (in any order, as a designer selects them) close into the boundary loop
    and which lie inside it: (the boundary's indices, the others'), four curves that close taken
    before three. ValueError when no 3 or 4 of them close (3 or 4 curves: which end meets no other)."""
    if isinstance(curves, (str, bytes)) or not 3 <= len(curves) <= MOST_CURVES:
        raise ValueError(f"curves: 3 to {MOST_CURVES} curves, 3 or 4 of them closing into a loop, got "
                         f"{len(curves) if hasattr(curves, '__len__') else curves!r}")
    samples = [cc.curve_points(c, SAMPLES) for c in curves]
    for n in (4, 3):
        for subset in itertools.combinations(range(len(curves)), n):
            try:
                _loop([samples[k] for k in subset])
            except ValueError:
                continue
            return list(subset), [k for k in range(len(curves)) if k not in subset]
    if len(curves) <= 4:
        _loop(samples)  # (raises, saying which end meets no other)
    raise ValueError(f"no 3 or 4 of the {len(curves)} curves close into a loop: a boundary is 3 or 4 curves "
                     "meeting end to end")


#: Where a three-sided loop's longest curve is split, by length, the first that lies more than a
#: tenth of the curve from where every inside curve ends: the split is a corner of the parameters,
#: which crowd there, and an inside curve ending at it (a curve to a side's middle) bent the patch
#: there (mean curvature turned, 0.18 1/mm).
SPLITS = (0.5, 0.35, 0.65)


def _sides(loop: list[tuple[np.ndarray, str]], ends: Sequence[np.ndarray] = ()) -> list[np.ndarray]:
    """Four sides of the loop (a three-sided one's longest curve split by length, at its middle
    unless an inside curve ends there: see SPLITS)."""
    sides = [p for p, _ in loop]
    if len(sides) == 3:
        lengths = np.array([_length(p) for p in sides])
        k = int(np.flatnonzero(lengths >= lengths.max() * (1 - 1e-9))[0])  # (ties: the first, on any machine)
        p = sides[k]
        s = _arc(p)
        clear = 0.1 * _length(p)
        t = next((t for t in SPLITS if all(np.linalg.norm(_at(p, s, t) - e) > clear for e in ends)), SPLITS[0])
        split = _at(p, s, t)
        first = np.vstack([p[s < t], split])
        second = np.vstack([split, p[s > t]])
        sides[k:k + 1] = [first, second]
    return sides


def _length(points: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def _arc(points: np.ndarray) -> np.ndarray:
    """The points' chord-length parameters in [0, 1]."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    return s / s[-1]


def _at(points: np.ndarray, s: np.ndarray, t: Any) -> np.ndarray:
    """The polyline ``points`` (parameters ``s``) at parameters ``t``."""
    return np.stack([np.interp(t, s, points[:, k]) for k in range(3)], axis=-1)


def coons(sides: list[np.ndarray], n: int) -> np.ndarray:
    """The bilinearly blended Coons patch of four sides (head to tail: P00 -> P10 -> P11 -> P01 ->
    P00) on an n x n grid of (u, v) in [0, 1]^2, each side by its chord length: (n, n, 3)."""
    t = np.linspace(0.0, 1.0, n)
    c0 = _at(sides[0], _arc(sides[0]), t)           # v = 0
    d1 = _at(sides[1], _arc(sides[1]), t)           # u = 1
    c1 = _at(sides[2], _arc(sides[2]), 1.0 - t)     # v = 1
    d0 = _at(sides[3], _arc(sides[3]), 1.0 - t)     # u = 0
    p00, p10, p11, p01 = c0[0], c0[-1], c1[-1], c1[0]
    u, v = t[:, None, None], t[None, :, None]
    return ((1 - v) * c0[:, None] + v * c1[:, None] + (1 - u) * d0[None, :] + u * d1[None, :]
            - ((1 - u) * (1 - v) * p00 + u * (1 - v) * p10 + (1 - u) * v * p01 + u * v * p11))


def _knots(n: int, p: int = 3) -> np.ndarray:
    """A clamped uniform knot vector of ``n`` poles of degree ``p`` on [0, 1]."""
    return np.concatenate([np.zeros(p), np.linspace(0.0, 1.0, n - p + 1), np.ones(p)])


def fitted_net(grid: np.ndarray, controls: tuple[int, int]) -> core.BSplineSurface:
    """The cubic B-spline surface of ``controls`` poles (clamped, uniform) nearest ``grid`` (n, n, 3)
    in least squares at the grid's parameters."""
    n = grid.shape[0]
    t = np.linspace(0.0, 1.0, n)
    bu, bv = design(_knots(controls[0]), t), design(_knots(controls[1]), t)
    pu, pv = np.linalg.pinv(bu), np.linalg.pinv(bv)
    poles = np.einsum("ia,abk,jb->ijk", pu, grid, pv)
    return core.BSplineSurface(poles, (3, 3), list(_knots(controls[0])), list(_knots(controls[1])), None)


def _edge_fit(points: np.ndarray, knots: np.ndarray, first: np.ndarray, last: np.ndarray
              ) -> tuple[np.ndarray, float]:
    """The row of poles whose cubic B-spline (on ``knots``) is nearest the side ``points`` (by chord
    length) with its ends at ``first`` and ``last`` (the corners): the row and its largest distance
    from the points (at them and between them)."""
    s = _arc(points)
    b = design(knots, s)
    inner = b[:, 1:-1]
    rhs = points - np.outer(b[:, 0], first) - np.outer(b[:, -1], last)
    middle = np.linalg.lstsq(inner, rhs, rcond=None)[0]
    row = np.vstack([first, middle, last])
    dense = np.linspace(0.0, 1.0, 4 * len(points))
    off = np.linalg.norm(design(knots, dense) @ row - _at(points, s, dense), axis=1).max()
    return row, float(max(off, np.linalg.norm(b @ row - points, axis=1).max()))


def edge_fitted_net(sides: list[np.ndarray], controls: tuple[int, int], tolerance: float, most: tuple[int, int]
                    ) -> core.BSplineSurface:
    """The Coons patch's net (:func:`fitted_net`) with its four edge rows fitted to the sides, each
    within ``tolerance``: the net refined (uniformly along the side that misses) until it is, up to
    ``most`` controls per direction; ValueError where it cannot."""
    controls = tuple(controls)
    while True:
        net = fitted_net(coons(sides, 4 * max(controls) + 1), controls)
        poles = np.array(net.poles, float)
        ku, kv = _knots(controls[0]), _knots(controls[1])
        corners = [sides[0][0], sides[1][0], sides[2][0], sides[3][0]]  # P00, P10, P11, P01
        worst = [0.0, 0.0]
        for side, knots, put, axis in ((sides[0], ku, lambda r: poles.__setitem__((slice(None), 0), r), 0),
                                       (sides[2][::-1], ku, lambda r: poles.__setitem__((slice(None), -1), r), 0),
                                       (sides[3][::-1], kv, lambda r: poles.__setitem__((0, slice(None)), r), 1),
                                       (sides[1], kv, lambda r: poles.__setitem__((-1, slice(None)), r), 1)):
            row, off = _edge_fit(side, knots, side[0], side[-1])
            put(row)
            worst[axis] = max(worst[axis], off)
        if worst[0] <= tolerance and worst[1] <= tolerance:
            return core.BSplineSurface(poles, (3, 3), list(ku), list(kv), None)
        grown = tuple(min(2 * c - 3, m) if w > tolerance else c for c, w, m in zip(controls, worst, most))
        if grown == controls:
            raise ValueError(f"boundary: a {controls[0]} x {controls[1]} net's edges come no closer than "
                             f"{max(worst):.3g} mm to the curves (tolerance {tolerance:g} mm), and its mesh takes no "
                             "finer net; use smoother curves, or a larger tolerance")
        controls = grown


def faired(poles: np.ndarray, surface: core.BSplineSurface, links: list[Any], held: Sequence[int] = (),
           reference: np.ndarray | None = None) -> np.ndarray:
    """The poles (n, 3) of least bending energy (of their change from ``reference``, when given)
    with the ``held`` poles where they are and the ``links`` (pole, masters, offset) held: every
    slave its masters' combination. (A touch of the current shape, 1e-9 of the energy's scale,
    keeps the directions it does not see where they are.)"""
    n = len(poles)
    slaves = {link[0] for link in links}
    fixed = set(held)
    free = [i for i in range(n) if i not in slaves and i not in fixed]
    column = {p: k for k, p in enumerate(free)}
    t = np.zeros((n, len(free)))
    c = np.zeros((n, 3))
    for i in free:
        t[i, column[i]] = 1.0
    for i in fixed:
        c[i] = poles[i]
    for pole, masters, *offset in links:
        c[pole] = np.asarray(offset[0] if offset else (0.0, 0.0, 0.0), float)
        for m, w in masters:
            if m in column:
                t[pole, column[m]] += w
            else:
                c[pole] += w * poles[m]
    k = bending_matrix(surface)
    a = t.T @ k @ t
    touch = 1e-9 * np.trace(a) / max(len(free), 1)
    offset = c if reference is None else c - reference
    q = np.linalg.solve(a + touch * np.eye(len(free)), -t.T @ k @ offset + touch * poles[free])
    return t @ q + c


def make_sculpt_from_curves(doc: Any, boundary: Sequence[Any], interior: Sequence[Any] = (),
                            controls: tuple[int, int] | None = None, material: str = "clay",
                            name: str = "Sculpt", tolerance: float | None = None) -> Any:
    """A new Sculpt whose edges follow ``boundary`` (3 or 4 curves that close into a loop, in any
    order and direction) and which passes through every curve of ``interior``, each within
    ``tolerance`` (mm; 0.001 by default), filled by the least bending energy between them and held
    to them as curve constraints while it is sculpted afterwards. A curve is what
    add_curve_constraint takes (a sketch, an edge, a wire, points). ``controls``: the least net
    (12 x 12 by default), refined along a curve where it must be. One undo step. ValueError
    saying why for curves that do not close, a loop that encloses nothing (curves in one line), a
    curve off the patch or that no net here follows; nothing is made then."""
    from .curve_follow import DEFAULT_TOLERANCE
    doc = _document(doc)
    _material(material)
    tolerance = DEFAULT_TOLERANCE if tolerance is None else float(tolerance)
    if not 1e-9 <= tolerance <= 1e3:
        raise ValueError(f"tolerance: a length in mm from 1e-9 to 1000, got {tolerance!r}")
    if isinstance(boundary, (str, bytes)) or len(boundary) not in (3, 4):
        raise ValueError(f"boundary: 3 or 4 curves that close into a loop, got {len(boundary) if hasattr(boundary, '__len__') else boundary!r}")
    controls = (12, 12) if controls is None else tuple(int(x) for x in controls)
    if len(controls) != 2 or min(controls) < 4 or max(controls) > 64:
        raise ValueError(f"controls: two whole numbers in 4..64, got {controls!r}")
    curves = [cc.curve_points(c, SAMPLES) for c in boundary]
    loop = _loop(curves)
    inside = [cc.curve_points(c, SAMPLES) for c in interior]
    sides = _sides(loop, [end for points, _ in inside for end in (points[0], points[-1])])
    corners = np.array([s[0] for s in sides])
    normal = sum(np.cross(corners[k], corners[(k + 1) % 4]) for k in range(4))
    everything = np.vstack(sides)
    size = float(np.linalg.norm(np.ptp(everything, axis=0)))
    area = 0.5 * float(np.linalg.norm(normal))
    if area <= 1e-6 * size * size:
        raise ValueError("boundary: the curves lie in one line: the loop they close encloses no area")
    _check_corners(loop, inside, size)
    mesh = (max(40, 2 * controls[0]), max(40, 2 * controls[1]))
    net = edge_fitted_net(sides, controls, tolerance, (32, 32))
    mesh = (max(mesh[0], 2 * net.controls[0]), max(mesh[1], 2 * net.controls[1]))
    records, moved, links, dynamic, held, mesh = _held(net, list(interior), mesh, material, tolerance)
    for _ in range(ROOM_PASSES):  # (room beside each interior curve: its conditions fix the poles it crosses)
        knots: tuple[list[float], list[float]] = ([], [])
        for record in records:
            more = cc.refinement_knots(dynamic.surface, record.uv, (mesh[0] // 2 - dynamic.surface.controls[0],
                                                                   mesh[1] // 2 - dynamic.surface.controls[1]))
            knots = (sorted(set(knots[0] + more[0])), sorted(set(knots[1] + more[1])))
        if not knots[0] and not knots[1]:
            break
        records, moved, links, dynamic, held, mesh = _held(refined(dynamic.surface, knots), list(interior), mesh,
                                                           material, tolerance)
    if len(loop) == 4 or interior:
        # (three curves: the least bending of the change from the Coons patch, and with none inside
        # the Coons patch itself: the parameters crowd at the straight corner, where their own energy
        # bends the patch, 0.4 1/mm against the Coons patch's 0.037, 0.32 with a curve inside)
        reference = None
        if len(loop) == 3:
            final = dynamic.surface
            reference = np.asarray(refined(net, (np.unique(final.knots_u), np.unique(final.knots_v))).poles,
                                   float).reshape(-1, 3)
        dynamic.set_poles(faired(moved, dynamic.surface, links, held, reference).reshape(np.asarray(dynamic.poles).shape))
    dynamic.hold_poles(held, links)
    dynamic.relax()
    state = sculpt_state.capture(dynamic)
    made = SourceSurface(dynamic.surface, "curves", 0.0, f"curve network of {len(boundary)} + {len(interior)} curves")
    if doc.UndoMode == 0:
        doc.UndoMode = 1
    with transaction(doc, "Patch from curves"):
        obj = _add_sculpt(doc, name, made, state)
        _writer(obj, records)()
        obj.purgeTouched()
    return obj


def _held(net: core.BSplineSurface, interior: list[Any], mesh: tuple[int, int], material: str, tolerance: float
          ) -> tuple[list[cc.CurveConstraint], np.ndarray, list[Any], Any, list[int], tuple[int, int]]:
    """A surface of ``net`` with its edges held (G0: the boundary) and every interior curve held on
    it (refined along a curve where it must be, up to half the mesh's points per direction, the
    mesh made finer up to MOST_MESH when that is not enough): the records, the poles moved onto
    them, the links, the surface, the held poles and the mesh."""
    from .edge_holds import boundary_poles
    while True:
        held = boundary_poles(tuple(net.controls), "G0")
        dynamic = sculpt_state.restore(_sculpt_state(SourceSurface(net, "curves", 0.0, ""), mesh, material, held))
        records: list[cc.CurveConstraint] = []
        links: list[Any] = []
        moved = np.asarray(dynamic.poles, float).reshape(-1, 3)
        try:
            for k, curve in enumerate(interior):
                record, moved, links = cc.make(dynamic, curve, "G0", None, cc.FIRST_ID + k, held, [], records,
                                               tolerance)
                records.append(record)
                dynamic.set_poles(moved.reshape(np.asarray(dynamic.poles).shape))
                dynamic.hold_poles(held, links)
            return records, moved, links, dynamic, held, mesh
        except cc.NetTooCoarse as coarse:
            controls = tuple(net.controls)
            knots = cc.refinement_knots(net, coarse.uv, (mesh[0] // 2 - controls[0], mesh[1] // 2 - controls[1]))
            if not knots[0] and not knots[1]:
                if max(mesh) >= MOST_MESH:  # (the advice a sculpt gets, more controls, is this one's own limit)
                    raise ValueError(f"curve: the patch cannot follow {coarse.curve} on the most controls a patch "
                                     f"from curves takes: {coarse.why}; make the curve smoother, or give a larger "
                                     f"tolerance") from None
                mesh = (min(MOST_MESH, mesh[0] * 3 // 2), min(MOST_MESH, mesh[1] * 3 // 2))
                knots = cc.refinement_knots(net, coarse.uv, (mesh[0] // 2 - controls[0], mesh[1] // 2 - controls[1]))
            net = refined(net, knots)
