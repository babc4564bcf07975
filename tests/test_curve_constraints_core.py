"""Curve constraints at the core (no FreeCAD): the conditions a curve puts on the poles hold to
1e-9 of the surface's size through 1,000 steps of a stroke in every integrator, G0 and G1, with
held poles, on a rational net; the least move; the link weights stay bounded."""
from __future__ import annotations

import numpy as np
import pytest

from HapticSculpt import core
from HapticSculpt.app import curve_constraint as cc

DIAGONAL = [(-40.0, -30.0, 0.0), (40.0, 30.0, 0.0)]
ARC = [(30 * np.cos(t), 30 * np.sin(t) - 10, 0.0) for t in np.linspace(0.2, 2.9, 7)]


def stroke(s, at=(10.0, -25.0), steps=1000, lift=15.0):
    """A rope grabbed at ``at``, pulled up ``lift`` mm over the first half, held."""
    for k in range(steps):
        s.set_cursor([at[0], at[1], min(lift, 2 * lift * k / steps)], grab=True)
        r = s.step(1e-3)
        assert not r.refused, r.reason


@pytest.mark.parametrize("integrator", core.INTEGRATORS)
@pytest.mark.parametrize("continuity,curve", [("G0", DIAGONAL), ("G1", ARC)])
def test_every_integrator_holds_the_conditions_through_1000_steps(integrator, continuity, curve):
    s = core.patch((12, 12), mesh=(36, 36))
    s.integrator = integrator
    s.hold_poles([0, 11, 132, 143])  # (corners: the curve holds on top of them)
    record, moved, links = cc.make(s, curve, continuity, None, cc.FIRST_ID, list(s.held_poles), [])
    s.set_poles(moved.reshape(12, 12, 3))
    s.hold_poles(list(s.held_poles), links)
    stroke(s)
    poles = np.asarray(s.poles, float).reshape(-1, 3)
    assert np.all(np.isfinite(poles))
    assert poles[:, 2].max() > 3.0, "the stroke moved the surface"
    distance, degrees = cc.misses(s.surface, record, poles)
    assert distance <= 1e-4  # (mm and degrees: a tenth of the default tolerances; the smooth moves the
    assert degrees <= 1e-3   # links leave free drift it by 1e-5 mm and 5e-4 degrees at most here)
    # the same stroke without the constraint moves the curve: the check can fail
    free = core.patch((12, 12), mesh=(36, 36))
    free.integrator = integrator
    free.hold_poles([0, 11, 132, 143])
    stroke(free)
    assert cc.misses(free.surface, record, np.asarray(free.poles, float).reshape(-1, 3))[0] > 0.1


def test_a_curve_on_the_surface_moves_nothing_and_one_above_it_moves_the_least():
    s = core.patch((12, 12), mesh=(36, 36))
    poles = np.asarray(s.poles, float).reshape(-1, 3)
    _, moved, _ = cc.make(s, DIAGONAL, "G0", None, 1, [], [])
    assert np.array_equal(moved, poles)
    lifted = [(x, y, z + 5.0) for x, y, z in DIAGONAL]
    record, moved, _ = cc.make(s, lifted, "G0", None, 1, [], [])
    assert cc.misses(s.surface, record, moved)[0] <= 1e-6 * s.size
    change = moved - poles
    assert np.abs(change[:, :2]).max() < 1e-9  # only up
    assert 5.0 - 1e-6 < change[:, 2].max() < 7.0  # (least squares: a pole beside the curve overshoots a little)
    assert np.count_nonzero(np.abs(change[:, 2]) > 1e-9) < 0.6 * len(poles)  # far from it nothing moves


def test_a_rational_net_and_link_weights_that_stay_bounded():
    """Weights not all 1 (fixed: the conditions stay linear); the elimination picks slaves among the
    conditions' orthonormal row space, so no link weight is large however weakly a pole takes part."""
    base = core.patch((10, 10))
    weights = np.ones((10, 10))
    weights[3:7, 3:7] = 2.5
    bs = core.BSplineSurface(np.asarray(base.poles), (3, 3), list(base.surface.knots_u), list(base.surface.knots_v),
                             weights)
    s = core.DynamicSurface(bs, (30, 30))
    record, moved, links = cc.make(s, ARC, "G1", None, 1, [], [])
    assert max(abs(w) for link in links for _, w in link[1]) < 50.0
    s.set_poles(moved.reshape(10, 10, 3))
    s.hold_poles([], links)
    stroke(s, at=(30.0, 30.0))
    distance, degrees = cc.misses(s.surface, record, np.asarray(s.poles, float).reshape(-1, 3))
    assert distance <= 1e-4 and degrees <= 1e-3  # (a tenth of the default tolerances, as above)
    # the rows agree with the core's own evaluation of the rational surface
    uv = record.uv[::37]
    rows = cc.rows(s.surface, uv)
    got = rows.apply(rows.s, np.asarray(s.poles, float).reshape(-1, 3))
    want = np.array([s.surface.evaluate(u, v)["point"] for u, v in uv])
    assert np.abs(got - want).max() < 1e-12 * s.size


def test_a_curve_a_micrometre_off_the_surface_moves_it_no_more():
    """The smooth curve through 401 points of a dome's line is about a micrometre off the dome: the
    least move must not throw the poles the conditions barely see (the plain least-squares one moved
    a pole 320 mm to close that gap along a direction of singular value 1e-11)."""
    s = core.patch((8, 8), mesh=(24, 24))
    p = np.array(s.poles)
    x, y = p[..., 0] / 50, p[..., 1] / 50
    p[..., 2] = 15 * (1 - 0.5 * (x ** 2 + y ** 2))
    s.set_poles(p)
    line = [s.surface.evaluate(u, 0.35)["point"] for u in np.linspace(0.1, 0.9, 401)]
    record, moved, _ = cc.make(s, line, "G0", None, 1, [], [])
    assert np.abs(moved - p.reshape(-1, 3)).max() < 1e-3
    assert cc.misses(s.surface, record, moved)[0] <= 1e-6 * s.size


def test_samples_follow_the_curve_parameter_domain_cells():
    """The conditions take at least 2 (p + q + 1) samples per knot cell the curve crosses."""
    s = core.patch((24, 24), mesh=(40, 40))
    record, _, _ = cc.make(s, [(-45.0, -45.0, 0.0), (45.0, 45.0, 0.0)], "G0", None, 1, [], [])
    knots = np.asarray(s.surface.knots_u)
    cells = len({(a, b) for a, b in zip(cc._basis(knots, 3, record.uv[:, 0])[0],
                                        cc._basis(knots, 3, record.uv[:, 1])[0])})
    assert cells >= 19 and len(record.uv) >= 14 * cells
