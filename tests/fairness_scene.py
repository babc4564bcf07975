"""The fair-stroke scene (issue 26): a flat 100 mm patch (8 x 8 cubic poles, 40 x 40 mesh, as
make_sculpt makes it) whose centre the rope pulls up until it stands LIFT mm high, then holds for
HOLD seconds; free or with its corner poles held, elastic or clay (the materials of
HapticSculpt.app.api), with the bending weight that makes strokes fair or with none. Shared by
tests/test_fairness.py and bench/time_vs_error.py."""
from __future__ import annotations

import time

import numpy as np

from HapticSculpt import core
from HapticSculpt.app import api, fairness

LIFT = 20.0   # mm the centre stands above the sheet
HOLD = 4.0    # s the rope holds it there
RISE = 10.0   # mm/s the cursor rises
DT = 1e-3     # a session's default step
CENTRE = (20, 20)
FLAT = 1 / (1000 * 100.0)  # 1/mm: a curvature radius of 100 m (1000 patch sizes) is flat


def build(material: str, pinned: bool, bending: float = api.FAIR_BENDING) -> core.DynamicSurface:
    """The patch as make_sculpt makes it, with bending weight ``bending`` (0: springs alone)."""
    s = core.patch((8, 8), (3, 3), (40, 40))
    api._apply_material(s, material)
    s.bending_map.set_uniform(bending)
    if pinned:
        nu, nv = s.controls
        s.hold_poles([0, nv - 1, (nu - 1) * nv, nu * nv - 1])
    return s


def pull(s: core.DynamicSurface, lift: float = LIFT, hold: float = HOLD, max_time: float = 10.0) -> dict:
    """Grabs the centre with the rope and raises the cursor until the centre stands ``lift`` above
    where it started, then holds the cursor still for ``hold`` s (long enough for the elastic sheet
    to stop ringing). Returns the lift at the end, the kinetic energy left and the wall seconds per
    step."""
    z0 = float(s.mesh[CENTRE][2])
    cursor = np.array(s.mesh[CENTRE], dtype=float)
    t, steps, wall = 0.0, 0, 0.0

    def step() -> None:
        nonlocal steps, wall
        s.set_cursor(list(cursor), grab=True)
        start = time.perf_counter()
        s.step(DT)
        wall += time.perf_counter() - start
        steps += 1

    while float(s.mesh[CENTRE][2]) - z0 < lift:
        if t > max_time:
            raise RuntimeError(f"the rope did not lift the centre {lift} mm in {max_time} s")
        cursor[2] += RISE * DT
        step()
        t += DT
    for _ in range(round(hold / DT)):
        step()
    return {"lift": float(s.mesh[CENTRE][2]) - z0, "kinetic_energy": s.kinetic_energy(),
            "step_seconds": wall / steps}


#: The reach scenes: a mouse drag that raises the rope REACH mm over 0.5 s above the centre, held 1 s.
REACH = 20.0


def build_held(material: str, edges: str, bending: float = api.FAIR_BENDING, rope_as_before: bool = False
               ) -> core.DynamicSurface:
    """The patch with ``edges`` held ("free", "corners", or a boundary as make_sculpt takes it:
    "G1" is New clamped patch); ``rope_as_before``: the rope's settings divided by its plate gain,
    so it pulls as it did before the gain (the same forces, for comparison)."""
    s = build(material, edges == "corners", bending)
    if edges not in ("free", "corners"):
        s.hold_poles(api.boundary_poles(tuple(s.controls), edges), s.linked_poles)
    if rope_as_before:
        gain = 1 + core.ROPE_PLATE_GAIN * bending
        s.tool.stiffness, s.tool.stiff_stiffness = s.tool.stiffness / gain, s.tool.stiff_stiffness / gain
        s.tool.max_force /= gain
    return s


def reach(s: core.DynamicSurface, pull_mm: float = REACH, rise: float = 0.5, hold: float = 1.0,
          after: float = 1.0) -> dict:
    """How far a drag takes the surface: the cursor rises ``pull_mm`` above the centre over
    ``rise`` s and stays ``hold`` s (the lift then), the rope lets go and the sheet settles
    ``after`` s (the lift kept)."""
    z0 = float(s.mesh[CENTRE][2])
    cursor = np.array(s.mesh[CENTRE], dtype=float)
    steps = round((rise + hold) / DT)
    for k in range(steps):
        cursor[2] = z0 + pull_mm * min(1.0, (k + 1) * DT / rise)
        s.set_cursor(list(cursor), grab=True)
        s.step(DT)
    held = float(s.mesh[CENTRE][2]) - z0
    gain = s.tool.gain
    s.set_cursor(list(cursor), grab=False)
    for _ in range(round(after / DT)):
        s.step(DT)
    return {"held": held, "kept": float(s.mesh[CENTRE][2]) - z0, "gain": gain}


def sections(s: core.DynamicSurface, pinned: bool) -> list[fairness.Section]:
    """The six central sections through and beside the pulled point (two mesh lines apart), and
    with held corners the two diagonals, where a crease to a corner would run."""
    g, h = s.mesh_shape
    centre = (CENTRE[0] / (g - 1), CENTRE[1] / (h - 1))
    return fairness.central_sections(centre, spread=2 / (g - 1), diagonals=pinned, domain=s.surface.domain)


def measure(s: core.DynamicSurface, pinned: bool) -> fairness.Fairness:
    """The exact normal curvature of the core's B-spline along ``sections``."""
    return fairness.measure(fairness.core_derivatives(s.surface), sections(s, pinned), flat=FLAT)
