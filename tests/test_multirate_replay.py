"""The loops on a virtual clock from Python (bench/haptic_force.py's tool): what it returns, and a
clear error for what it cannot replay."""
from __future__ import annotations

import numpy as np
import pytest

from HapticSculpt import core
from HapticSculpt.core import native as _core
from HapticSculpt.runtime.replay_device import ReplayDevice


def stroke() -> ReplayDevice:
    t = np.linspace(0.0, 0.4, 401)
    xyz = np.column_stack([np.full_like(t, 10.0), np.zeros_like(t), 20.0 * t])
    return ReplayDevice(t, xyz, buttons=((t > 0.02) & (t < 0.35)).astype(int))


def test_states_reach_the_haptic_loop_after_their_cost_and_latency():
    device = stroke()
    run = _core.replay_multirate(core.patch((6, 6), mesh=(24, 24)), device.native, 0.4, step_cost=5e-4, latency=3e-3)
    n = run["t"].size
    assert n == 401 and run["position"].shape == (n, 3) and run["estimated_force"].shape == (n, 3)
    later = run["t"] > 0.05
    # a step covers 1 ms, ends when its interval has passed, costs 0.5 ms, reaches the loop 3 ms on
    assert np.all(run["t"][later] - run["state_time"][later] <= 4.6e-3)
    assert np.all(run["t"][later] - run["state_time"][later] >= 3e-3 - 1e-9)
    grabbed = (run["t"] > 0.1) & (run["t"] < 0.3)
    assert np.all(np.linalg.norm(run["estimated_force"][grabbed], axis=1) > 0)  # the rope pulls back
    assert run["dropped_sim_time"] == 0 and run["doubled_steps"] == 0


@pytest.mark.parametrize("bad", [dict(step_cost=-1.0), dict(sim_dt=0.0), dict(latency=float("nan")), dict(haptic_rate=50.0)])
def test_what_cannot_be_replayed_is_refused_by_name(bad):
    with pytest.raises(ValueError, match="haptic_rate|sim_dt|step_cost|latency"):
        _core.replay_multirate(core.patch((6, 6), mesh=(24, 24)), stroke().native, 0.4, **bad)
