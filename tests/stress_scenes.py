"""Random extreme scenes for the stability stress test (tests/test_stress.py) and the long campaign
(`make stress`, tests/stress_campaign.py).

One seed fully decides a scene: shape (including collapsed rows and zero-area patches), material
(stiffness 1e-3..1e7, mass 1e-6..1e3, damping 0..1e4, bending 0, the default or 1e-3..1e4 times the
stiffness), integrator and time step (1e-6..1e-1 s),
tool, conflicting constraints, non-linear laws and plasticity, and a script of random forces,
cursor teleports, grabs and releases and non-finite inputs. `run_scene(seed)` plays it and returns
what it found; a failure names the seed, so `run_scene(seed)` replays it exactly.

What every scene must show:
- no NaN/Inf ever in poles, velocities or mesh;
- energy bounded by the work put in: kinetic + potential energy never exceeds
  ENERGY_SLACK * (initial energy + positive work of applied forces and tools) + a floor;
- every invalid input refused with ValueError naming the argument, and the state unchanged.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from HapticSculpt import core
from HapticSculpt.app import curve_constraint

# Energy bound: semi-implicit Euler and the linearised implicit step exchange energy between kinetic
# and potential at O(w dt), and work is accumulated with forces held over a step, so the bound has a
# factor; a scheme that gains energy grows without limit and exceeds any fixed factor within a few steps.
ENERGY_SLACK = 2.0
STEPS = 40


@dataclasses.dataclass
class SceneResult:
    """What one seeded scene showed; `failure` is empty when every check held."""

    seed: int
    integrator: str
    dt: float
    stiffness: float
    mass: float
    damping: float
    shape: str
    bending: float = -1.0  # the bending weight; -1: the core's default
    steps: int = 0
    refused_steps: int = 0
    energy_limited_steps: int = 0
    verlet_steps: int = 0  # local/global steps taken by its explicit branch
    substeps: int = 0
    max_energy_ratio: float = 0.0
    invalid_inputs_refused: int = 0
    failure: str = ""

    @property
    def ok(self) -> bool:
        return not self.failure


def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(10 ** rng.uniform(math.log10(lo), math.log10(hi)))


def _shape(rng: np.random.Generator, s: core.DynamicSurface) -> str:
    """Perturb or degenerate the initial shape and make it the rest shape."""
    kind = ("flat", "bumpy", "collapsed row", "collapsed column", "zero area", "collinear")[int(rng.integers(0, 6))]
    p = np.array(s.poles)
    n_u, n_v = s.surface.controls
    grid = p.reshape(n_u, n_v, 3)
    if kind == "bumpy":
        grid[..., 2] += rng.normal(size=(n_u, n_v)) * 10 ** rng.uniform(-1, 1.5)
    elif kind == "collapsed row":
        grid[int(rng.integers(0, n_u))] = grid[int(rng.integers(0, n_u)), int(rng.integers(0, n_v))]
    elif kind == "collapsed column":
        grid[:, int(rng.integers(0, n_v))] = grid[int(rng.integers(0, n_u)), int(rng.integers(0, n_v))]
    elif kind == "zero area":
        grid[...] = rng.normal(size=3)
    elif kind == "collinear":
        t = np.linspace(-50, 50, n_u * n_v).reshape(n_u, n_v)
        grid[...] = t[..., None] * np.array([1.0, 0.3, 0.1])
    s.set_poles(grid.reshape(-1, 3))
    s.relax()
    return kind


def _energy(s: core.DynamicSurface) -> float:
    return s.kinetic_energy() + s.potential_energy()


def _finite(s: core.DynamicSurface) -> bool:
    return bool(np.isfinite(s.poles).all() and np.isfinite(s.velocities).all() and np.isfinite(s.mesh).all())


def _snapshot(s: core.DynamicSurface) -> tuple[bytes, bytes, int]:
    return np.array(s.poles).tobytes(), np.array(s.velocities).tobytes(), len(s.constraints)


# Invalid inputs a scene throws at the core: (argument the error must name, call).
_INVALID = (
    ("position", lambda s: s.set_cursor([math.nan, 0.0, 0.0], grab=True)),
    ("position", lambda s: s.set_cursor([0.0, math.inf, 0.0])),
    ("force", lambda s: s.set_point_force(0, [0.0, -math.inf, 0.0])),
    ("dt", lambda s: s.step(math.nan)),
    ("dt", lambda s: s.step(-1e-3)),
    ("target", lambda s: s.add_constraint("point", index=0, target=[math.nan, 0.0, 0.0])),
    ("stiffness", lambda s: s.add_constraint("point", index=0, stiffness=math.inf)),
    ("value", lambda s: s.stiffness_map.set_uniform(math.nan)),
    ("value", lambda s: s.mass_map.set_uniform(-1.0)),
    ("poles", lambda s: s.set_poles(np.full(s.poles.shape, math.nan))),
    ("indices", lambda s: s.hold_poles([-1])),
)


def _invalid_input(rng: np.random.Generator, s: core.DynamicSurface) -> str:
    """Throw one invalid input; return a failure message, or '' when it was refused cleanly."""
    name, call = _INVALID[int(rng.integers(0, len(_INVALID)))]
    before = _snapshot(s)
    try:
        call(s)
    except ValueError as exc:
        if name not in str(exc):
            return f"invalid {name} refused without naming it: {exc}"
    else:
        return f"invalid {name} accepted"
    if _snapshot(s) != before:
        return f"refusing invalid {name} changed the state"
    return ""


def _random_constraint(rng: np.random.Generator, s: core.DynamicSurface, n_points: int) -> str:
    """Add a random constraint, or two conflicting ones; a refusal must name its argument."""
    kind = core.CONSTRAINTS[int(rng.integers(0, 4))]
    where = int(rng.integers(0, n_points))
    k = _log_uniform(rng, 1e-2, 1e8)
    try:
        if kind == "curvature":  # may be refused: tighter than the mesh can bend
            s.add_constraint(kind, index=where, stiffness=k, curvature=tuple(rng.uniform(0, 0.2, 2)))
        elif kind == "point":  # two at one point, far apart: a conflict
            s.add_constraint(kind, index=where, stiffness=k, target=list(rng.normal(size=3) * 100))
            s.add_constraint(kind, index=where, stiffness=k, target=list(rng.normal(size=3) * 100))
        else:
            s.add_constraint(kind, index=where, stiffness=k, target=list(rng.normal(size=3)))
    except ValueError as exc:
        if not any(f"{name}:" in str(exc) for name in ("curvature", "kind", "target")):
            return f"{kind} constraint refused without naming the argument: {exc}"
    return ""


def run_scene(seed: int, steps: int = STEPS) -> SceneResult:
    """Build and play scene `seed`; never raises for a scene that misbehaves, reports it instead."""
    rng = np.random.default_rng(seed)
    deg = (int(rng.integers(1, 4)), int(rng.integers(1, 4)))
    controls = (int(rng.integers(deg[0] + 1, 9)), int(rng.integers(deg[1] + 1, 9)))
    mesh = (int(rng.integers(controls[0], 20)), int(rng.integers(controls[1], 20)))
    s = core.patch(controls, deg, mesh)
    res = SceneResult(seed=seed, integrator=core.INTEGRATORS[seed % 3], dt=_log_uniform(rng, 1e-6, 1e-1),
                      stiffness=_log_uniform(rng, 1e-3, 1e7), mass=_log_uniform(rng, 1e-6, 1e3),
                      damping=0.0 if rng.random() < 0.25 else _log_uniform(rng, 1e-2, 1e4), shape="")
    try:
        res.shape = _shape(rng, s)
        s.integrator = res.integrator
        s.max_halvings = int(rng.integers(0, 11))  # explicit: from no halving to the default depth
        s.stiffness_map.set_uniform(res.stiffness)
        s.mass_map.set_uniform(res.mass)
        s.damping_map.set_uniform(res.damping)
        if rng.random() < 0.3:
            s.stiffness_map.dab((rng.random(), rng.random()), 0.3, res.stiffness * 10 ** rng.uniform(-2, 2),
                                core.FALLOFFS[int(rng.integers(0, 4))], 1.0)
        if rng.random() < 0.2:
            s.set_stiffness_law(core.LAWS[int(rng.integers(0, 3))], _log_uniform(rng, 1e-3, 1e3))
        if rng.random() < 0.2:
            s.set_damping_law(core.LAWS[int(rng.integers(0, 3))], _log_uniform(rng, 1e-3, 1e3))
        if rng.random() < 0.2:
            s.set_plasticity(True, float(rng.uniform(0, 0.2)), float(rng.uniform(0, 10)))
        n_points = s.mesh.shape[0] * s.mesh.shape[1]
        for _ in range(int(rng.integers(0, 4))):
            msg = _random_constraint(rng, s, n_points)
            if msg:
                res.failure = msg
                return res
        s.set_tool(core.TOOLS[int(rng.integers(0, len(core.TOOLS)))])
        # Held poles (hard constraints) in a quarter of the scenes, from a stream of their own so the
        # other scenes stay what they were: any subset, up to all of them.
        held_rng = np.random.default_rng([seed, 1])
        held: list[int] = []
        if held_rng.random() < 0.25:
            n_poles = controls[0] * controls[1]
            held = sorted(int(i) for i in held_rng.choice(n_poles, int(held_rng.integers(1, n_poles + 1)), replace=False))
            s.hold_poles(held)
        held_at = np.array(s.poles).reshape(-1, 3)[held].copy()
        # The bending weight, from a stream of its own: off, huge, anything between, or the default;
        # a negative or NaN weight is refused naming the map.
        bend_rng = np.random.default_rng([seed, 3])
        pick = bend_rng.random()
        if pick < 0.75:
            # (a ratio to the stiffness: 1e4 is 1000x the materials' 10; past it, as for stiffness,
            # a long step's system no longer factors and the step is refused naming dt)
            res.bending = 0.0 if pick < 0.2 else 1e4 if pick < 0.35 else _log_uniform(bend_rng, 1e-3, 1e4)
            s.bending_map.set_uniform(res.bending)
        for bad in (-1.0, math.nan):
            before = _snapshot(s), np.array(s.bending_map.values).tobytes()
            try:
                s.bending_map.set_uniform(bad)
                res.failure = f"bending weight {bad} accepted"
                return res
            except ValueError as exc:
                if "bending" not in str(exc) or (_snapshot(s), np.array(s.bending_map.values).tobytes()) != before:
                    res.failure = f"bending weight {bad} refused without naming the map or changed the state: {exc}"
                    return res
        # Linked poles (a G1 seam: a row kept between its neighbours) or mirror symmetry (x = 0) in
        # a quarter each of the scenes with nothing held, from a stream of their own.
        extra_rng = np.random.default_rng([seed, 2])
        nv = controls[1]
        links: list = []
        mirrored = False
        if not held and extra_rng.random() < 0.25 and controls[0] >= 3:
            row, a = int(extra_rng.integers(1, controls[0] - 1)), float(extra_rng.uniform(0.05, 0.95))
            links = [(row * nv + j, [((row - 1) * nv + j, a), ((row + 1) * nv + j, 1.0 - a)]) for j in range(nv)]
            if row + 3 < controls[0] and extra_rng.random() < 0.5:
                # a G2 seam's second follower: the pole two rows past it, an affine combination of
                # four others with weights like seam_continuity's (some negative, summing to 1)
                masters = sorted({max(row - 2, 0), row - 1, row + 1, row + 3})
                w = extra_rng.uniform(-1.5, 2.5, len(masters))
                w[-1] = 1.0 - w[:-1].sum()
                links.extend(((row + 2) * nv + j, [(m * nv + j, float(x)) for m, x in zip(masters, w)])
                             for j in range(nv))
            s.hold_poles([], links)
        elif not held and extra_rng.random() < 0.33:
            try:
                s.set_symmetry(0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
                mirrored = True
            except ValueError:
                pass  # (a shape that is not symmetric: refused, as it must be)
        # A curve the surface must follow (G0 or G1: links with offsets from a least-squares
        # elimination) in a third of the scenes left, from a stream of its own; refused with a
        # reason where the net cannot follow it.
        curve_rng = np.random.default_rng([seed, 4])
        if not held and not links and not mirrored and curve_rng.random() < 0.33:
            corners = curve_rng.uniform(-45, 45, (int(curve_rng.integers(2, 5)), 2))
            points = np.column_stack([corners, np.zeros(len(corners))])
            try:
                _, moved, links = curve_constraint.make(s, points, ("G0", "G1")[int(curve_rng.integers(0, 2))], None,
                                                        curve_constraint.FIRST_ID, [], [])
                s.set_poles(moved.reshape(np.array(s.poles).shape))
                s.hold_poles([], links)
            except ValueError as exc:
                if "curve" not in str(exc):
                    res.failure = f"a curve constraint refused without saying why: {exc}"
                    return res
        # Walls (a face kept behind its neighbours' planes) in a third of the scenes with nothing
        # held or mirrored, from a stream of their own: one to three planes through the net, at any angle.
        wall_rng = np.random.default_rng([seed, 5])
        walls: list = []
        if not held and not mirrored and wall_rng.random() < 0.33:
            net = np.array(s.poles).reshape(-1, 3)
            for _ in range(int(wall_rng.integers(1, 4))):
                normal = wall_rng.normal(size=3)
                normal /= np.linalg.norm(normal)
                heights = net @ normal
                point = normal * float(wall_rng.uniform(heights.min(), heights.max()) + 1e-3 * np.ptp(heights))
                walls.append((point.tolist(), normal.tolist(), list(range(len(net)))))
            s.set_walls(walls)
        # Regional steps in a third of the scenes (a stream of their own), with the smallest margin
        # so that these small nets get regions smaller than themselves.
        region_rng = np.random.default_rng([seed, 6])
        if region_rng.random() < 0.33:
            s.regional = True
            s.region_margin = 1
            s.region_wake = float(region_rng.choice([0.0, 1e-3, 1e-1, 1.0]))
        energy0 = _energy(s)
        work_in = 0.0
        last_work = s.work_done
        scale = 1e-9 * max(1.0, res.stiffness) * 1e4  # an absolute floor: 1e-9 of a 100 mm spring at this stiffness
        for k in range(steps):
            r = rng.random()
            if r < 0.3:  # cursor teleport, grab or release
                s.set_cursor(list(rng.normal(size=3) * 10 ** rng.uniform(0, 3)), grab=bool(rng.random() < 0.7))
            elif r < 0.4:
                s.set_point_force(int(rng.integers(0, n_points)), list(rng.normal(size=3) * 10 ** rng.uniform(0, 8)))
            elif r < 0.45:
                s.clear_forces()
            elif r < 0.55:
                res.invalid_inputs_refused += 1
                msg = _invalid_input(rng, s)
                if msg:
                    res.failure = msg
                    return res
            rep = s.step(res.dt)
            res.steps += 1
            res.refused_steps += int(rep.refused)
            res.energy_limited_steps += int(rep.energy_limited)
            res.verlet_steps += int(rep.verlet)
            res.substeps += rep.substeps
            if not _finite(s):
                res.failure = f"non-finite state after step {k}"
                return res
            if held and not np.array_equal(np.array(s.poles).reshape(-1, 3)[held], held_at):
                res.failure = f"a held pole moved in step {k}"
                return res
            p = np.array(s.poles)
            flat = p.reshape(-1, 3)
            # (to rounding: the core's sums are fused multiply-adds)
            if links and any(np.abs(flat[link[0]] - sum(w * flat[m] for m, w in link[1])
                                    - (link[2] if len(link) > 2 else 0.0)).max()
                             > 1e-13 * (sum(abs(w) for _, w in link[1]) + 1) * max(1.0, np.abs(flat).max())
                             for link in links):
                res.failure = f"a linked pole left its masters in step {k}"
                return res
            if walls:
                free = np.setdiff1d(np.arange(len(flat)), [link[0] for link in links])
                out = max(float(((flat[free] - point) @ np.asarray(normal)).max()) for point, normal, _ in walls)
                if out > 1e-9 * max(1.0, np.abs(flat).max()):
                    res.failure = f"a pole left its wall by {out:g} in step {k}"
                    return res
            if mirrored and not np.array_equal(p[::-1] * [-1.0, 1.0, 1.0], p):
                res.failure = f"the mirror symmetry broke in step {k}"
                return res
            work = s.work_done
            work_in += max(0.0, work - last_work)
            last_work = work
            e = _energy(s)
            if not math.isfinite(e):
                res.failure = f"non-finite energy after step {k}"
                return res
            bound = ENERGY_SLACK * (energy0 + work_in) + scale
            res.max_energy_ratio = max(res.max_energy_ratio, e / bound)
            if e > bound:
                res.failure = (f"energy {e:.3g} exceeds {ENERGY_SLACK} x (initial {energy0:.3g} + work {work_in:.3g}) "
                               f"after step {k}")
                return res
    except Exception as exc:  # noqa: BLE001 - any escape is a finding, reported with its seed
        res.failure = f"{type(exc).__name__}: {exc}"
    return res
