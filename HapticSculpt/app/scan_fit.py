"""Fitting a sculpt to its target (issue 30): the surface relaxed onto the scan's points, robust to
outliers and holes, every hard constraint kept; the net refined where the fit cannot get within the
tolerance.

Each round projects the points onto the surface (their feet give the parameters), weighs them
(points past the surface's edges and outliers get none) and solves for the poles nearest them
(``DynamicSurface.fit_poles``: least squares with the mesh's curvature variation bridging holes,
the change levelled off past the scan's reach; held, linked and mirrored poles hold). Outliers are points farther than ``OUTLIER_SPREAD`` robust
standard deviations (1.4826 x the median absolute distance) and than twice the tolerance: a scan's
stray returns pull nothing, and a hole (no points) is bridged by the curvature term alone.
No FreeCAD here: the API (:mod:`scan_api`) writes the result as one undo step.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import core

#: Rounds of project-weigh-solve per net (the feet settle in a few; more change nothing).
ROUNDS = 8
#: A round that brings the points' mean distance closer by less than this share of the tolerance
#: ends the fit of a net.
SETTLED = 0.005
#: How much a point's slide along the surface weighs against its distance across it (1 would be
#: plain least squares, whose feet creep: 3 % a round on a bump where this takes 2 or 3 rounds).
TANGENTIAL = 0.02
#: A net that folds (a cell of its parameter grid turned over) is fitted again with these (slide,
#: in-plane) weights in turn (see fit_poles: a pole's move in the surface's own plane, against a
#: pole's share of the points' weight). The points hold a pole mostly across the surface, and on a
#: slope a move along it serves them too: poles slid in the plane and nets folded, a sheet with held
#: edges and a held line 56 of 1600 cells beside the line (in-plane 0.1: 36, 1: none), a solid's
#: refined top beside a bump. Not from the start: on a free sheet's coarse net the in-plane weight
#: costs accuracy (8 x 8 at 0.25 mm: 98.9 % within, 0.23 mm from the truth; with it, 3 nets to
#: 11 x 11 and 0.31 mm).
FIRMER = ((TANGENTIAL, 1.0), (0.3, 1.0), (1.0, 1.0))
#: Robust standard deviations beyond which a point is an outlier.
OUTLIER_SPREAD = 4.0
#: Points far off in a span cell are outliers only while they are fewer than this share of its
#: points (a scan's stray returns are about 1 %; a region the fit has not reached is most of its cell).
CLUSTER = 0.1
#: ... and at least this many (one stray point in a cell of few is not a region).
CLUSTER_POINTS = 5
#: Points over the surface per pole a net is refined to at most (fewer leave poles the scan does
#: not determine: the fit would follow the noise, and the net slide along itself).
POINTS_PER_POLE = 12
#: Share of the points that must lie within the tolerance.
WITHIN_GOAL = 95.0
#: The curvature variation's weight, relative to the points'.
SMOOTHING = 1e-5
#: The weight of the change's slope beyond the scan's reach, relative to the points' (see fit_poles).
#: Without it a 100 mm patch over a 60 mm scan of a 2.3 mm bump rose 10 mm at its corners and its
#: edge moved 4 mm in its plane; at 1e-2 its corners stay below 0.9 mm, its edge within 0.5 mm of
#: its place, the scanned part as close to the truth (0.139 mm); at 1e-1 the fit reached 94.98 %
#: at 0.1 mm where it had reached 95 % (the membrane holds back the scan's own edge). The bench's
#: scans (the whole sheet) fit as before to the last digit.
BEYOND = 1e-2


@dataclass
class FitRound:
    """One net's fit: its controls, how much is within the tolerance, and where it falls short."""

    controls: tuple[int, int]
    within_pct: float
    max_mm: float
    p95_mm: float
    outliers: int
    worst_uv: tuple[float, float]


@dataclass
class FitReport:
    """What :func:`fit` did: the rounds (one per net), whether the goal was met, and why not."""

    tolerance_mm: float
    within_pct: float
    met: bool
    controls: tuple[int, int]
    rounds: list[FitRound] = field(default_factory=list)
    message: str = ""
    points: int = 0
    outliers: int = 0
    beyond_edge: int = 0
    blocked_by: list[dict[str, Any]] = field(default_factory=list)  # held edges that keep the scan out of reach
    free_within_pct: float | None = None  # the share within the tolerance with them let go

    def as_dict(self) -> dict[str, Any]:
        """The report as plain numbers (for JSON and for scripts)."""
        return {"tolerance_mm": self.tolerance_mm, "within_pct": self.within_pct, "met": self.met,
                "controls": list(self.controls), "message": self.message, "points": self.points,
                "outliers": self.outliers, "beyond_edge": self.beyond_edge,
                "blocked_by": list(self.blocked_by), "free_within_pct": self.free_within_pct,
                "rounds": [r.__dict__ | {"controls": list(r.controls), "worst_uv": list(r.worst_uv)}
                           for r in self.rounds]}


def robust_weights(distance: np.ndarray, over: np.ndarray, tolerance: float, cells: np.ndarray | None = None
                   ) -> np.ndarray:
    """1 for points over the surface that are not outliers, 0 for the others. An outlier lies
    beyond OUTLIER_SPREAD robust standard deviations (and twice the tolerance) and is stray: in its
    ``cells`` entry (a knot span cell per point) such points are fewer than CLUSTER of the points,
    so a region the surface does not follow yet (a crown it is below) keeps pulling."""
    a = np.abs(distance)
    used = a[over]
    spread = 1.4826 * float(np.median(used)) if used.size else 0.0
    limit = max(OUTLIER_SPREAD * spread, 2.0 * tolerance)
    far = over & (a > limit)
    if cells is not None and far.any():
        counts = np.bincount(cells[over], minlength=int(cells.max()) + 1)
        far_counts = np.bincount(cells[far], minlength=len(counts))
        clustered = (far_counts > CLUSTER * np.maximum(counts, 1)) & (far_counts >= CLUSTER_POINTS)
        far &= ~clustered[cells]
    return (over & ~far).astype(float)


def span_cells(surface: core.BSplineSurface, uv: np.ndarray) -> np.ndarray:
    """The knot span cell (u span x v span, row-major) each parameter pair lies in."""
    bu, bv = (np.unique(np.asarray(k, float)) for k in (surface.knots_u, surface.knots_v))
    iu = np.clip(np.searchsorted(bu, uv[:, 0], side="right") - 1, 0, len(bu) - 2)
    iv = np.clip(np.searchsorted(bv, uv[:, 1], side="right") - 1, 0, len(bv) - 2)
    return iu * (len(bv) - 1) + iv


def folded(normals: np.ndarray, surface: core.BSplineSurface) -> bool:
    """True if ``surface`` crosses itself in its own plane somewhere: a cell of its parameter grid
    (the grid ``normals`` were taken on, (n, m, 3), from the surface before it moved) is mapped
    turned over (its corners' orientation against the normal there)."""
    n, m = normals.shape[:2]
    pts = np.asarray(surface.grid(n, m)[0])
    du, dv = pts[1:, :-1] - pts[:-1, :-1], pts[:-1, 1:] - pts[:-1, :-1]
    cross = np.cross(du, dv)
    turn = np.einsum("ijk,ijk->ij", cross, normals[:-1, :-1])
    return bool(np.any(turn < -1e-9 * np.linalg.norm(cross, axis=-1)))


def fit_net_unfolded(surface: core.DynamicSurface, points: np.ndarray, tolerance: float) -> tuple[FitRound, dict[str, Any]]:
    """:func:`fit_net`, and again from the same poles with each of FIRMER in turn while the net
    folds; ValueError (the poles put back) if it folds even so."""
    nu, nv = surface.surface.controls
    start = np.asarray(surface.poles, float).copy()
    normals = np.asarray(surface.surface.grid(4 * nu + 1, 4 * nv + 1)[1])
    for tangential, in_plane in ((TANGENTIAL, 0.0), *FIRMER):
        surface.set_poles(start.reshape(nu, nv, 3))
        summary, r = fit_net(surface, points, tolerance, tangential=tangential, in_plane=in_plane)
        if not folded(normals, surface.surface):
            return summary, r
    surface.set_poles(start.reshape(nu, nv, 3))
    raise ValueError(f"the {nu} x {nv} net folds in its own plane fitting these points")


def fit_net(surface: core.DynamicSurface, points: np.ndarray, tolerance: float, smoothing: float = SMOOTHING,
            rounds: int = ROUNDS, tangential: float = TANGENTIAL, in_plane: float = 0.0, beyond: float = BEYOND
            ) -> tuple[FitRound, dict[str, Any]]:
    """Fits ``surface``'s poles to ``points`` on its net as it is (the surface is moved there).
    Returns the net's summary and the last projection (with the weights)."""
    nu, nv = surface.surface.controls
    r = surface.surface.project(points)
    w = robust_weights(r["distance"], ~r["beyond_edge"], tolerance, span_cells(surface.surface, r["uv"]))
    mean = math.inf
    for _ in range(rounds):
        fitted = surface.fit_poles(points, r["uv"], r["normal"], w, tangential, smoothing, in_plane, beyond)
        surface.set_poles(fitted.reshape(nu, nv, 3))
        r = surface.surface.project(points, start=r["uv"])
        w = robust_weights(r["distance"], ~r["beyond_edge"], tolerance, span_cells(surface.surface, r["uv"]))
        kept = w > 0
        now = float(np.abs(r["distance"][kept]).mean()) if kept.any() else 0.0
        if mean - now < SETTLED * tolerance:
            break
        mean = now
    over = ~r["beyond_edge"]
    kept = w > 0
    a = np.abs(r["distance"])
    measured = a[kept]
    worst = int(np.argmax(np.where(kept, a, -1.0)))
    summary = FitRound((nu, nv), float(100.0 * np.mean(a[over] <= tolerance)) if over.any() else 0.0,
                       float(measured.max()) if measured.size else math.inf,
                       float(np.percentile(measured, 95)) if measured.size else math.inf,
                       int(np.count_nonzero(over & ~kept)), (float(r["uv"][worst, 0]), float(r["uv"][worst, 1])))
    return summary, r | {"weights": w}
