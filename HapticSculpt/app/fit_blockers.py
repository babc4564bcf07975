"""What keeps a fit to a scan from its tolerance when the net itself could reach it: the held
edges (their tangent planes, for a clamped sheet), the seams' and curves' linked poles, a mirror
symmetry. The fit is made again on the same net with all of them let go; where that one meets the
tolerance at points the held fit could not, those points are what the holds keep out of reach,
each counted at the held edge nearest it (in the net's parameters)."""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from .. import core

#: The free fit must bring at least this share of the scan (percentage points) more within the
#: tolerance for the holds to be named as what blocks the fit.
MARGIN_PCT = 5.0
def _side_distances(uv: np.ndarray, bounds: tuple[float, float, float, float]) -> dict[str, np.ndarray]:
    u0, u1, v0, v1 = bounds
    su, sv = (u1 - u0) or 1.0, (v1 - v0) or 1.0
    return {"u0": (uv[:, 0] - u0) / su, "u1": (u1 - uv[:, 0]) / su,
            "v0": (uv[:, 1] - v0) / sv, "v1": (v1 - uv[:, 1]) / sv}


def diagnose(trial: core.DynamicSurface, points: np.ndarray, tolerance: float, held: dict[str, Any],
             held_within_pct: float, fit: Callable[[core.DynamicSurface], tuple[Any, dict[str, Any]]]
             ) -> dict[str, Any] | None:
    """``trial``: the sculpt as it was before the fit (a copy, changed here), ``held``: the held
    fit's projection of the points ("distance", "beyond_edge" per point) and ``held_within_pct`` its
    share within the tolerance. ``fit`` fits a surface to the points on its net. Returns None when
    the holds are not what blocks it, else ``free_within_pct`` (the fit with the holds let go, on
    the sculpt's own net) and ``blocked_pct`` (the share of the scan within the tolerance only then)."""
    if not trial.held_poles and not trial.linked_poles and trial.symmetry is None:
        return None
    trial.hold_poles([], [])
    if trial.symmetry is not None:
        trial.set_symmetry(-1, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    try:
        free, r = fit(trial)
    except ValueError:  # (it folds even free: the net is what falls short)
        return None
    if free.within_pct < held_within_pct + MARGIN_PCT:
        return None
    n = len(points)
    over = ~np.asarray(held["beyond_edge"][:n], bool)
    blocked = over & (np.abs(held["distance"][:n]) > tolerance) & (np.abs(r["distance"][:n]) <= tolerance)
    return {"free_within_pct": float(free.within_pct), "blocked": blocked, "uv": np.asarray(r["uv"][:n], float),
            "blocked_pct": float(100.0 * np.count_nonzero(blocked) / max(1, np.count_nonzero(over)))}


def by_edge(found: dict[str, Any], kinds: dict[str, str], bounds: tuple[float, float, float, float]) -> list[dict[str, Any]]:
    """A sheet's held sides (``kinds``: "u0".. to "G0".. or "free") with the share of the scan
    (percent of the points over the surface) blocked nearest each, the largest first."""
    held = [side for side, kind in kinds.items() if kind != "free"]
    blocked = found["blocked"]
    if not held or not blocked.any():
        return []
    distance = _side_distances(found["uv"][blocked], bounds)
    nearest = np.array(held)[np.argmin(np.stack([distance[s] for s in held]), axis=0)]
    each = found["blocked_pct"] / int(np.count_nonzero(blocked))  # (one blocked point's share, percent)
    out = [{"edge": side, "kind": kinds[side], "share_pct": float(each * np.count_nonzero(nearest == side))}
           for side in held]
    return sorted((e for e in out if e["share_pct"] > 0), key=lambda e: -e["share_pct"])


def sentence(found: dict[str, Any], edges: list[dict[str, Any]], what: str, tolerance: float, remedy: str) -> str:
    """The report's message: which holds keep what share of the scan out of reach, what the fit
    gives without them, and the remedy."""
    named = ", ".join(f"{e['edge']} ({e['kind']}) {e['share_pct']:.0f} %" for e in edges) if edges else what
    return (f"held edges keep {found['blocked_pct']:.0f} % of the scan out of reach: {named}; with them free "
            f"{found['free_within_pct']:.0f} % would lie within {tolerance:g} mm ({remedy})")
