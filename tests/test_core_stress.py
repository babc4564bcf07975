"""Seeded stress: extreme parameters, teleports and random forces never put NaN/Inf in the state."""
import numpy as np
import pytest

from HapticSculpt import core


@pytest.mark.parametrize("seed", range(40))
def test_random_extreme_scene_stays_finite(seed):
    rng = np.random.default_rng(seed)
    ds = core.patch((int(rng.integers(4, 9)), int(rng.integers(4, 9))), (3, 3),
                    (int(rng.integers(9, 20)), int(rng.integers(9, 20))))
    ds.integrator = core.INTEGRATORS[seed % 3]
    ds.stiffness_map.set_uniform(10 ** rng.uniform(-3, 7))
    ds.mass_map.set_uniform(10 ** rng.uniform(-6, 3))
    ds.damping_map.set_uniform(0.0 if seed % 4 == 0 else 10 ** rng.uniform(-2, 4))
    dt = 10 ** rng.uniform(-6, -1)
    ds.set_tool(core.TOOLS[int(rng.integers(0, 4))])
    if seed % 5 == 0:
        ds.add_constraint("point", index=0, target=[0, 0, 50.0])
        ds.add_constraint("point", index=0, target=[0, 0, -50.0])  # conflicting
    n_refused = 0
    for k in range(60):
        ds.set_cursor(list(rng.normal(size=3) * 10 ** rng.uniform(0, 3)), grab=bool(k % 7))
        if k % 11 == 0:
            ds.set_point_force(int(rng.integers(0, ds.mesh.shape[0] * ds.mesh.shape[1])),
                               list(rng.normal(size=3) * 10 ** rng.uniform(0, 8)))
        r = ds.step(dt)
        n_refused += r.refused
        assert np.isfinite(ds.poles).all() and np.isfinite(ds.velocities).all(), f"seed {seed}"
    with pytest.raises(ValueError):
        ds.set_cursor([np.nan, 0, 0], grab=True)
