"""Fuzzing the Python API with Hypothesis: arbitrary numbers (NaN, Inf, huge, negative, zero),
shapes, strings and byte strings at every public entry point. A call either works or raises
ValueError/TypeError naming an argument; nothing crashes, nothing else escapes, and whatever a call
accepts or refuses, the state stays finite. Derandomised, so a run is reproducible.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from HapticSculpt import core
from HapticSculpt.core import native as _core
from HapticSculpt.runtime.replay_device import ReplayDevice

SETTINGS = settings(max_examples=1000, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

any_float = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                      st.sampled_from([0.0, -0.0, 1e-300, -1e300, 1e308, math.nan, math.inf, -math.inf]))
small_int = st.integers(min_value=-3, max_value=12)
vec = st.lists(any_float, min_size=0, max_size=5)
names = st.one_of(st.sampled_from(core.TOOLS + core.CONSTRAINTS + core.FALLOFFS + core.LAWS + core.INTEGRATORS),
                  st.text(max_size=12))
# "name: message" or "name/other: message": the error names the argument
NAMED = re.compile(r"^[A-Za-z_][\w/ ]*:")


def refused_clearly(call, *args, **kwargs) -> bool:
    """Call; True if it worked, False if it was refused with a clear error; anything else fails."""
    try:
        call(*args, **kwargs)
        return True
    except (ValueError, TypeError) as exc:
        assert str(exc), f"{call} refused {args} {kwargs} without a message"
        if isinstance(exc, ValueError):
            assert NAMED.match(str(exc)), f"error does not name its argument: {exc}"
        return False


def finite(s: core.DynamicSurface) -> bool:
    return bool(np.isfinite(s.poles).all() and np.isfinite(s.velocities).all() and np.isfinite(s.mesh).all())


@SETTINGS
@given(nu=small_int, nv=small_int, du=small_int, dv=small_int,
       knots_u=st.one_of(st.none(), st.lists(any_float, max_size=20)),
       weight=st.one_of(st.none(), any_float), poles_value=any_float)
def test_surface_construction(nu, nv, du, dv, knots_u, weight, poles_value):
    poles = np.zeros((max(nu, 0), max(nv, 0), 3))
    if poles.size:
        poles[..., 0] = np.arange(max(nu, 0))[:, None]
        poles[..., 1] = np.arange(max(nv, 0))[None, :]
        poles[0, 0, 2] = poles_value
    weights = None if weight is None else np.full((max(nu, 0), max(nv, 0)), weight)
    ok = refused_clearly(core.BSplineSurface, poles, (du, dv), knots_u=knots_u, weights=weights)
    if ok:
        s = core.BSplineSurface(poles, (du, dv), knots_u=knots_u, weights=weights)
        (u0, u1), (v0, v1) = s.domain
        d = s.evaluate(0.5 * (u0 + u1), 0.5 * (v0 + v1))
        assert all(np.isfinite(np.asarray(x, dtype=float)).all() for x in d.values())


@SETTINGS
@given(controls=st.tuples(small_int, small_int), degree=st.tuples(small_int, small_int),
       mesh=st.tuples(small_int, small_int), size=st.tuples(any_float, any_float))
def test_patch_construction(controls, degree, mesh, size):
    if refused_clearly(core.patch, controls, degree, mesh, size):
        assert finite(core.patch(controls, degree, mesh, size))


# One random call on a live surface: (name, strategy for its arguments, how to call).
def _calls():
    idx = st.integers(min_value=-5, max_value=400)
    uv = st.tuples(any_float, any_float)
    return st.one_of(
        st.tuples(st.just("set_cursor"), st.tuples(vec, vec, st.booleans())),
        st.tuples(st.just("set_point_force"), st.tuples(idx, vec)),
        st.tuples(st.just("step"), st.tuples(any_float)),
        st.tuples(st.just("set_tool"), st.tuples(names)),
        st.tuples(st.just("add_constraint"), st.tuples(names, st.one_of(st.none(), idx), st.one_of(st.none(), uv),
                                                       st.one_of(st.none(), any_float), st.one_of(st.none(), vec))),
        st.tuples(st.just("material"), st.tuples(st.sampled_from(["mass_map", "damping_map", "stiffness_map"]),
                                                 uv, any_float, any_float, names, any_float)),
        st.tuples(st.just("law"), st.tuples(st.booleans(), names, any_float)),
        st.tuples(st.just("plasticity"), st.tuples(st.booleans(), any_float, any_float)),
        st.tuples(st.just("integrator"), st.tuples(names)),
        st.tuples(st.just("setting"), st.tuples(st.sampled_from(["iterations", "cg_iterations", "max_halvings"]),
                                                st.integers(min_value=-10, max_value=2000))),
        st.tuples(st.just("set_poles"), st.tuples(any_float)),
    )


def _apply(s: core.DynamicSurface, name: str, a: tuple) -> None:
    if name == "set_cursor":
        s.set_cursor(a[0], a[1], grab=a[2])
    elif name == "set_point_force":
        s.set_point_force(*a)
    elif name == "step":
        s.step(a[0])
    elif name == "set_tool":
        s.set_tool(a[0])
    elif name == "add_constraint":
        kind, index, where, stiffness, target = a
        s.add_constraint(kind, index=index, uv=where, stiffness=stiffness, target=target)
    elif name == "material":
        m = getattr(s, a[0])
        m.dab(a[1], a[2], a[3], a[4], a[5])
    elif name == "law":
        (s.set_stiffness_law if a[0] else s.set_damping_law)(a[1], a[2])
    elif name == "plasticity":
        s.set_plasticity(*a)
    elif name == "integrator":
        s.integrator = a[0]
    elif name == "setting":
        setattr(s, a[0], a[1])
    elif name == "set_poles":
        p = np.array(s.poles)
        p[1, 1, 2] = a[0]
        s.set_poles(p)


@settings(SETTINGS, max_examples=4000)
@given(calls=st.lists(_calls(), min_size=1, max_size=25))
def test_any_sequence_of_calls_keeps_the_surface_finite(calls):
    s = core.patch((5, 5), (3, 3), (9, 9))
    for name, args in calls:
        refused_clearly(_apply, s, name, args)
        assert finite(s), f"after {name}{args}"
    assert math.isfinite(s.kinetic_energy() + s.potential_energy())


@SETTINGS
@given(t=st.lists(any_float, min_size=0, max_size=6), xyz=st.lists(vec, max_size=6),
       quat=st.one_of(st.none(), st.lists(st.lists(any_float, min_size=4, max_size=4), max_size=6)),
       buttons=st.one_of(st.none(), st.lists(st.integers(min_value=-5, max_value=2**40), max_size=6)),
       at=any_float)
def test_replay_device(t, xyz, quat, buttons, at):
    if refused_clearly(ReplayDevice, t, xyz, quat, buttons):
        dev = ReplayDevice(t, xyz, quat, buttons)
        if refused_clearly(dev.sample, at):
            s = dev.sample(at)
            assert np.isfinite(s.position).all()


@SETTINGS
@given(text=st.text(max_size=300))
def test_replay_file_garbage(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("replay") / "t.txt"
    path.write_text(text)
    refused_clearly(ReplayDevice.load, path)


@SETTINGS
@given(data=st.binary(max_size=200))
def test_report_descriptor_bytes(data):
    refused_clearly(_core.parse_report_descriptor, data)


@SETTINGS
@given(reports=st.lists(st.binary(max_size=70), max_size=20))
def test_spacemouse_reports(reports):
    p = _core.SpaceMouseParser()
    for r in reports:
        p.feed(r)


def test_named_pattern_is_strict():
    assert NAMED.match("dt: must be finite")
    assert not NAMED.match("something went wrong")
    with pytest.raises(AssertionError):
        refused_clearly(lambda: (_ for _ in ()).throw(ValueError("no name here")))
