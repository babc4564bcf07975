"""B-spline evaluation against OCCT (FreeCAD's Part.BSplineSurface), and d = A p."""
import numpy as np
import pytest

from HapticSculpt import core
from HapticSculpt.app.part_surface import part_bspline

import FreeCAD  # noqa: E402  (FreeCAD is a hard test dependency: `make test` installs it; import it before Part)
import Part  # noqa: E402


def random_surface(rng, p, q, rational, nonuniform):
    nu, nv = p + 1 + int(rng.integers(0, 4)), q + 1 + int(rng.integers(0, 4))
    poles = rng.normal(size=(nu, nv, 3)) * 10.0
    poles[..., 0] += np.arange(nu)[:, None] * 10
    poles[..., 1] += np.arange(nv)[None, :] * 10

    def knots(n, d):
        inner = n - d - 1
        if nonuniform and inner > 0:
            vals = np.sort(rng.uniform(0.05, 0.95, inner))
            if inner >= 2 and d >= 2:
                vals[1] = vals[0]  # a double knot (multiplicity 2 <= degree)
        else:
            vals = np.linspace(0, 1, inner + 2)[1:-1]
        return [0.0] * (d + 1) + list(vals) + [1.0] * (d + 1)

    ku, kv = knots(nu, p), knots(nv, q)
    w = rng.uniform(0.5, 2.0, size=(nu, nv)) if rational else None
    return core.BSplineSurface(poles, (p, q), ku, kv, w), poles, ku, kv, w


def to_occt(poles, ku, kv, p, q, w):
    return part_bspline(poles, ku, kv, (p, q), w)


@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("degree", [(1, 1), (2, 3), (3, 3), (4, 2), (5, 5), (1, 5)])
def test_evaluation_matches_occt(degree, rational):
    rng = np.random.default_rng(hash((degree, rational)) % 2**32)
    p, q = degree
    for nonuniform in (False, True):
        s, poles, ku, kv, w = random_surface(rng, p, q, rational, nonuniform)
        bs = to_occt(poles, ku, kv, p, q, w)
        scale = np.abs(poles).max()
        for u, v in rng.uniform(0, 1, size=(60, 2)):
            ours = s.evaluate(u, v)
            ref = [np.array(bs.getD0(u, v))] if hasattr(bs, "getD0") else [np.array(bs.value(u, v))]
            ref.append(np.array(bs.getDN(u, v, 1, 0)))
            ref.append(np.array(bs.getDN(u, v, 0, 1)))
            names = ["point", "du", "dv"]
            if p >= 2:
                ref.append(np.array(bs.getDN(u, v, 2, 0))); names.append("duu")
            ref.append(np.array(bs.getDN(u, v, 1, 1))); names.append("duv")
            if q >= 2:
                ref.append(np.array(bs.getDN(u, v, 0, 2))); names.append("dvv")
            for name, r in zip(names, ref):
                err = np.linalg.norm(ours[name] - r) / max(np.linalg.norm(r), scale)
                assert err <= 1e-12, (name, u, v, err)


def test_normal_and_curvature_match_occt():
    rng = np.random.default_rng(3)
    s, poles, ku, kv, w = random_surface(rng, 3, 3, True, False)
    bs = to_occt(poles, ku, kv, 3, 3, w)
    for u, v in rng.uniform(0.05, 0.95, size=(50, 2)):
        n = s.normal(u, v)
        assert np.allclose(n, np.array(bs.normal(u, v)), atol=1e-10)
        c = s.curvature(u, v)
        for ours, name in ((c["mean"], "Mean"), (c["gauss"], "Gauss"), (c["max"], "Max"), (c["min"], "Min")):
            ref = bs.curvature(u, v, name)
            assert abs(ours - ref) <= 1e-9 * max(1.0, abs(ref)), (name, ours, ref)


@pytest.mark.parametrize("rational", [False, True])
def test_d_equals_A_p_and_rows_sum_to_one(rational):
    rng = np.random.default_rng(7)
    s, poles, ku, kv, w = random_surface(rng, 3, 2, rational, True)
    ds = core.DynamicSurface(s, (17, 13))
    indptr, indices, data, shape = ds.sampling_matrix()
    A = np.zeros(shape)
    for r in range(shape[0]):
        A[r, indices[indptr[r]:indptr[r + 1]]] = data[indptr[r]:indptr[r + 1]]
    assert np.allclose(A.sum(axis=1), 1.0, atol=1e-14)
    d = A @ ds.poles.reshape(-1, 3)
    assert np.allclose(d, ds.mesh.reshape(-1, 3), atol=1e-12 * np.abs(poles).max())
    # and the mesh points lie on the surface at their parameters
    us, vs = ds.mesh_parameters_u, ds.mesh_parameters_v
    for a in (0, 5, 16):
        for b in (0, 7, 12):
            assert np.allclose(ds.mesh[a, b], s.evaluate(us[a], vs[b])["point"], atol=1e-11)


def test_curvature_grid_matches_pointwise():
    ds = core.patch((6, 6), (3, 3), (9, 11))
    rng = np.random.default_rng(1)
    p = ds.poles.copy()
    p[..., 2] += rng.normal(size=p.shape[:2])
    ds.set_poles(p)
    grid = ds.curvature_grid()
    s = ds.surface
    for a in range(9):
        for b in range(11):
            c = s.curvature(ds.mesh_parameters_u[a], ds.mesh_parameters_v[b])
            assert np.allclose(grid[a, b], [c["u"], c["v"], c["min"], c["max"], c["mean"], c["gauss"]], atol=1e-12)


def test_views_share_memory_and_are_read_only():
    ds = core.patch((5, 5), (3, 3), (10, 10))
    poles, mesh = ds.poles, ds.mesh
    assert not poles.flags.writeable and not mesh.flags.writeable
    ds.set_cursor([0, 0, 3], grab=True)
    ds.step(1e-3, 20)
    assert np.array_equal(poles, ds.poles) and np.array_equal(mesh, ds.mesh)  # same memory, updated
    assert mesh[..., 2].max() > 0
    with pytest.raises(ValueError):
        poles[0, 0, 0] = 1.0


def test_fit_poles_in_plane_weighs_moves_not_places():
    """Points the surface passes through already: the fit leaves the poles where they are, and the
    in-plane weight (which weighs a pole's move, not its place) changes nothing; a bad weight is
    refused by name."""
    rng = np.random.default_rng(3)
    flat = core.BSplineSurface.plane((8, 7), (3, 3), (80.0, 60.0))
    poles = flat.poles.copy()
    poles[..., 2] = 5 * np.sin(poles[..., 0] / 20) * np.cos(poles[..., 1] / 25)
    s = core.DynamicSurface(core.BSplineSurface(poles), (24, 24))
    (u0, u1), (v0, v1) = s.surface.domain
    uv = rng.uniform(0.02, 0.98, (4000, 2))
    uv = np.c_[u0 + uv[:, 0] * (u1 - u0), v0 + uv[:, 1] * (v1 - v0)]
    pts = np.array([s.surface.evaluate(u, v)["point"] for u, v in uv])
    normals = np.array([s.surface.normal(u, v) for u, v in uv])
    plain = s.fit_poles(pts, uv, normals, np.ones(len(pts)), 0.02, 0.0, 0.0)  # (smoothing weighs the shape)
    held = s.fit_poles(pts, uv, normals, np.ones(len(pts)), 0.02, 0.0, 1.0)
    np.testing.assert_allclose(plain.reshape(poles.shape), poles, atol=1e-3)
    np.testing.assert_allclose(held.reshape(poles.shape), poles, atol=1e-3)  # (on places it pulled them mm)
    with pytest.raises(ValueError, match="in_plane"):
        s.fit_poles(pts, uv, normals, np.ones(len(pts)), 0.02, 0.0, -1.0)


def _fit_beyond(points: np.ndarray, beyond: float) -> np.ndarray:
    """Poles of a flat 100 mm 8 x 8 sheet fitted to ``points`` in one solve, with ``beyond``."""
    s = core.DynamicSurface(core.BSplineSurface.plane((8, 8), (3, 3), (100.0, 100.0)), (32, 32))
    r = s.surface.project(points)
    return s.fit_poles(points, r["uv"], r["normal"], np.ones(len(points)), 0.02, 1e-5, 0.0, beyond).reshape(8, 8, 3)


def test_fit_poles_beyond_levels_the_change_past_the_scan_and_nowhere_else():
    """A scan of a 2.3 mm bump over the central 60 mm of a 100 mm sheet: the curvature variation alone
    carries the bump's curvature out to the corners; weighed beyond the points, the change levels off
    there. A scan over the whole sheet with a hole inside gets the same fit with it as without."""
    rng = np.random.default_rng(5)
    xy = rng.uniform(-30, 30, (20000, 2))
    bump = np.c_[xy, 2 * np.exp(-(xy ** 2).sum(1) / 300) + 0.3]
    loose, level = _fit_beyond(bump, 0.0), _fit_beyond(bump, 1e-2)
    corners = [(0, 0), (0, 7), (7, 0), (7, 7)]
    assert max(loose[c][2] for c in corners) > 2.0
    assert max(abs(level[c][2]) for c in corners) < 0.8
    xy = rng.uniform(-50, 50, (20000, 2))
    xy = xy[np.hypot(xy[:, 0] - 10, xy[:, 1] + 5) > 15]
    holed = np.c_[xy, 2 * np.exp(-(xy ** 2).sum(1) / 300)]
    np.testing.assert_array_equal(_fit_beyond(holed, 0.0), _fit_beyond(holed, 1e-2))
    with pytest.raises(ValueError, match="beyond"):
        _fit_beyond(bump, -1.0)
