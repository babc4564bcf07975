"""Every validation error names its argument; refused input leaves the state unchanged."""
import numpy as np
import pytest

from HapticSculpt import core


def plane(n=5):
    p = np.zeros((n, n, 3))
    p[..., 0], p[..., 1] = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    return p


@pytest.mark.parametrize("kwargs, match", [
    (dict(degree=(0, 3)), "degree"),
    (dict(degree=(3, 6)), "degree"),
    (dict(knots_u=[0, 0, 0, 0, 1, 1, 1]), "knots_u"),                     # wrong count
    (dict(knots_u=[0, 0, 0, 0, 0.7, 0.5, 1, 1, 1]), "knots_u"),           # decreasing
    (dict(knots_v=[0, 0, 0, 0, 0.5, 1, 1, 1, float("nan")]), "knots_v"),  # non-finite
    (dict(knots_u=[0, 0, 0, 0.5, 0.5, 0.5, 0.5, 1, 1]), "knots_u"),       # multiplicity 4 > degree 3
    (dict(weights=np.ones((5, 4))), "weights"),
    (dict(weights=np.full((5, 5), -1.0)), "weights"),
])
def test_surface_validation(kwargs, match):
    with pytest.raises(ValueError, match=match):
        core.BSplineSurface(plane(), **{"degree": (3, 3), **kwargs})


def test_poles_validation():
    with pytest.raises(ValueError, match="poles"):
        core.BSplineSurface(np.zeros((5, 5, 2)))
    bad = plane()
    bad[1, 1, 1] = np.inf
    with pytest.raises(ValueError, match="poles"):
        core.BSplineSurface(bad)
    with pytest.raises(ValueError, match="poles"):
        core.BSplineSurface(plane(3), degree=(3, 3))  # fewer than degree+1
    with pytest.raises(ValueError, match="controls"):
        core.BSplineSurface.plane((3, 8), (3, 3), (1.0, 1.0))
    with pytest.raises(ValueError, match="size"):
        core.BSplineSurface.plane((4, 4), (3, 3), (0.0, 1.0))


def test_dynamic_surface_validation():
    s = core.BSplineSurface.plane((8, 8), (3, 3), (10.0, 10.0))
    with pytest.raises(ValueError, match="mesh"):
        core.DynamicSurface(s, (6, 20))
    ds = core.DynamicSurface(s, (12, 12))
    before = ds.poles.copy()
    cases = [
        (lambda: ds.step(0.0), "dt"),
        (lambda: ds.step(float("nan")), "dt"),
        (lambda: ds.step(1e-3, 0), "steps"),
        (lambda: ds.set_cursor([0, float("nan"), 0]), "position"),
        (lambda: ds.set_cursor([0, 0, 0], orientation=[0, 0, 0, 0]), "orientation"),
        (lambda: ds.set_cursor([0, 0, 0], orientation=[1, 0, 0]), "orientation"),
        (lambda: ds.set_tool("hammer"), "tool"),
        (lambda: ds.add_constraint("weld", index=3), "kind"),
        (lambda: ds.add_constraint("point"), "index/uv/near"),
        (lambda: ds.add_constraint("point", index=3, uv=(0.1, 0.1)), "index/uv/near"),
        (lambda: ds.add_constraint("point", index=10**6), "point"),
        (lambda: ds.add_constraint("point", uv=(2.0, 0.5)), "uv"),
        (lambda: ds.add_constraint("point", index=3, stiffness=-1.0), "stiffness"),
        (lambda: ds.add_constraint("point", index=3, target=[0, 0, float("inf")]), "target"),
        (lambda: ds.add_constraint("normal", index=30, target=[0, 0, 0]), "normal"),
        (lambda: ds.add_constraint("curvature", index=30, curvature=(10.0, 0.0)), "curvature"),
        (lambda: ds.add_constraint("point", index=30, curvature=(0.1, 0.1)), "curvature"),
        (lambda: ds.set_point_force(5, [0, 0, float("nan")]), "force"),
        (lambda: ds.set_point_force(-1, [0, 0, 1]), "index"),
        (lambda: ds.set_poles(np.full((8, 8, 3), np.nan)), "poles"),
        (lambda: ds.set_poles(np.zeros((7, 8, 3))), "poles"),
        (lambda: ds.mass_map.set_uniform(0.0), "mass"),
        (lambda: ds.stiffness_map.set_uniform(float("nan")), "stiffness"),
        (lambda: ds.damping_map.set_uniform(-1.0), "damping"),
        (lambda: ds.mass_map.set_values(np.ones((3, 3)) * -1), "mass"),
        (lambda: ds.mass_map.set_values(np.ones(3)), "values"),
        (lambda: ds.mass_map.dab((0.5, 0.5), 0.0, 1.0), "radius"),
        (lambda: ds.mass_map.dab((0.5, 0.5), 0.1, 1.0, "square"), "falloff"),
        (lambda: ds.mass_map.dab((0.5, 0.5), 0.1, 1.0, "conical", 2.0), "strength"),
        (lambda: ds.set_stiffness_law("quartic"), "law"),
        (lambda: ds.set_damping_law("cubic", scale=0.0), "scale"),
        (lambda: ds.set_plasticity(True, yield_strain=-0.1), "yield_strain"),
        (lambda: setattr(ds, "integrator", "rk4"), "integrator"),
        (lambda: setattr(ds, "iterations", 0), "iterations"),
        (lambda: setattr(ds.tool, "max_force", 0.0), "max_force"),
        (lambda: ds.remove_constraint(99), "id"),
        (lambda: ds.mesh_index_at(float("nan"), 0.5), "uv"),
        (lambda: ds.set_rest_lengths([1.0]), "rest"),
        (lambda: setattr(ds, "max_point_force", 0.0), "max_point_force"),
        (lambda: setattr(ds, "max_point_force", float("inf")), "max_point_force"),
        (lambda: setattr(ds, "constraint_stiffness_factor", -1.0), "constraint_stiffness_factor"),
    ]
    for call, match in cases:
        with pytest.raises(ValueError, match=match):
            call()
    with pytest.raises(TypeError):
        ds.step("fast")
    assert np.array_equal(before, ds.poles) and ds.constraints == [] and ds.mass_map.uniform


def test_a_step_that_would_create_nan_is_refused_and_state_kept():
    ds = core.patch((6, 6), (3, 3), (12, 12))
    ds.integrator = "explicit"
    ds.max_halvings = 0
    ds.acceleration_limit = 1e300
    ds.energy_guard = False  # the energy guard would refuse it first, for creating energy
    ds.stiffness_map.set_uniform(1e12)
    ds.mass_map.set_uniform(1e-12)
    ds.damping_map.set_uniform(0.0)
    p = ds.poles.copy()
    p[2, 2, 2] += 1.0
    ds.set_poles(p)
    refused = None
    for _ in range(50):
        snapshot = ds.poles.copy()
        r = ds.step(0.1)
        if r.refused:
            refused = r
            break
    assert refused is not None and "NaN" in refused.reason
    assert np.array_equal(snapshot, ds.poles) and np.isfinite(ds.poles).all()
