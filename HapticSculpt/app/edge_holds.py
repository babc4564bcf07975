"""How the edges of a sculpt's control net are held: which rows of poles hold an edge G0 to G3,
and which kinds a set of held poles holds."""
from __future__ import annotations

from typing import Any, Iterable

#: The four edges of a sculpt's control net, by the side of its parameter domain they lie on.
EDGES = ("u0", "u1", "v0", "v1")
#: How an edge may be held: not at all, in place (G0), in place with its tangent planes (G1).
BOUNDARIES = ("free", "G0", "G1", "G2", "G3")


def boundary_poles(controls: tuple[int, int], boundary: Any) -> list[int]:
    """The pole indices (i * nv + j for pole (i, j)) that hold ``boundary`` on a net of ``controls``
    poles: G0 holds an edge's row of poles (a clamped B-spline's edge curve depends on it alone), G1
    that row and the next (the derivative across the edge depends on those two), G2 three rows (the
    second derivative: the curvature across it), G3 four (its rate)."""
    nu, nv = controls
    if isinstance(boundary, str):
        boundary = {edge: boundary for edge in EDGES}
    if not isinstance(boundary, dict):
        raise TypeError(f"boundary: one of {', '.join(BOUNDARIES)}, or a dict from edge ({', '.join(EDGES)}) "
                        f"to one of them, not {boundary!r}")
    rows = {}
    for edge, kind in boundary.items():
        if edge not in EDGES:
            raise ValueError(f"boundary: unknown edge {edge!r} (one of {', '.join(EDGES)})")
        if kind not in BOUNDARIES:
            raise ValueError(f"boundary: {edge} must be one of {', '.join(BOUNDARIES)}, not {kind!r}")
        rows[edge] = BOUNDARIES.index(kind)  # rows of poles held: 0 to 4
    for side, count in (("u", nu), ("v", nv)):
        if rows.get(side + "0", 0) + rows.get(side + "1", 0) >= count:
            raise ValueError(f"boundary: {side}0 and {side}1 hold {rows.get(side + '0', 0) + rows.get(side + '1', 0)} "
                             f"rows of the {count} poles along {side}, too few to leave any free (use more controls)")
    held: set[int] = set()
    for edge, n in rows.items():
        count = nu if edge[0] == "u" else nv
        for r in range(n):
            line = r if edge[1] == "0" else count - 1 - r
            if edge[0] == "u":
                held.update(line * nv + j for j in range(nv))
            else:
                held.update(i * nv + line for i in range(nu))
    return sorted(held)


def kinds_held(held: Iterable[int], controls: tuple[int, int]) -> dict[str, str]:
    """What each edge of a net of ``controls`` poles is held as ("free", "G0" to "G3") by the
    ``held`` pole indices: the most rows it holds."""
    held = set(held)
    out = {}
    for edge in EDGES:
        out[edge] = "free"
        for kind in reversed(BOUNDARIES[1:]):
            try:
                rows = set(boundary_poles(controls, {edge: kind}))
            except ValueError:
                continue
            if rows <= held:
                out[edge] = kind
                break
    return out
