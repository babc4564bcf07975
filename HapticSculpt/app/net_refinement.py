"""A sculpt's net refined in place: knots inserted (exactly: the shape and its parameterisation are
kept), the holds carried to the finer net. What a fit to a scan and a curve the net cannot follow
both need."""
from __future__ import annotations

from typing import Any

import numpy as np

from .sculpted_solid import solid_of


def refined_work(sculpt: Any, work: Any, extra: tuple[list[float], list[float]]
                 ) -> tuple[Any, list[int], list[Any], list[Any]] | None:
    """A new working surface on ``work``'s net with knots ``extra`` (u, v) inserted, and the held
    poles, links and walls that hold it as ``work`` was held (apply the walls after the holds:
    they move only poles not held), its curves' links left out (knot insertion
    keeps the parameterisation, so the curves' records hold as they are: hold them on top):
    a sheet's edges, or a sculpted solid's edges, trims and seams (held poles, seam links and walls
    found again on the finer net). None where the holds cannot be carried to the finer net: a
    sheet's held poles that are not its edges', a symmetric sculpt, a mesh with fewer points than
    the finer net has poles."""
    from . import sculpt_state
    from .edge_holds import boundary_poles, kinds_held
    from .solid_api import refined_net
    from .source_surface import refined
    controls = tuple(work.surface.controls)
    solid = solid_of(sculpt)
    if work.symmetry is not None:
        return None
    if solid is None:
        kinds = kinds_held(work.held_poles, controls)
        if sorted(work.held_poles) != sorted(set(boundary_poles(controls, kinds))):
            return None
        finer, links, walls = refined(work.surface, extra), [], []
        held = boundary_poles(tuple(finer.controls), kinds)
    else:
        finer, held, links, walls = refined_net(solid, work.surface, extra)
    mesh = tuple(sculpt_state.capture(work).settings["mesh"])
    if mesh[0] < finer.controls[0] or mesh[1] < finer.controls[1]:
        return None
    return sculpt_state.on_net(work, finer), list(held), list(links), list(walls)


def refined_sculpt(sculpt: Any, work: Any, extra: tuple[list[float], list[float]]) -> Any:
    """:func:`refined_work` with the holds applied and ``sculpt``'s curves held again on top; None
    where the holds cannot be carried."""
    from . import curve_api
    made = refined_work(sculpt, work, extra)
    if made is None:
        return None
    surface, held, links, walls = made
    controls = tuple(surface.surface.controls)
    moved, links, _ = curve_api.rehold(sculpt, surface, held, links, np.asarray(surface.poles, float).reshape(-1, 3))
    surface.set_poles(moved.reshape(controls[0], controls[1], 3))
    surface.hold_poles(held, links)
    if walls:
        surface.set_walls(walls)
    return surface
