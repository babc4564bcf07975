"""Class-A analysis colours and geometry (HapticSculpt/analysis.py), in console mode."""
import numpy as np

from HapticSculpt import core
from HapticSculpt.app import analysis


def dome(n=30):
    s = core.patch((8, 8), (3, 3), (n, n))
    p = np.array(s.poles)
    p[..., 2] = 20 * (1 - ((p[..., 0] / 50) ** 2 + (p[..., 1] / 50) ** 2) / 2)
    s.set_poles(p)
    return s, np.array(s.mesh), s.curvature_grid().reshape(n, n, 6)


def test_pseudo_colour_ends_and_range():
    rgb, rng = analysis.pseudo_colour(np.array([0.0, 0.5, 1.0]))
    assert rng == (0.0, 1.0)
    assert np.allclose(rgb[0], [0, 0, 1]) and np.allclose(rgb[-1], [1, 0, 0]) and np.allclose(rgb[1], [0, 1, 0])


def test_curvature_channels_put_u_in_green_and_v_in_blue():
    curv = np.zeros((2, 2, 6))
    curv[0, 0, 0] = 0.1  # u only
    curv[1, 1, 1] = 0.1  # v only
    rgb, (_, top) = analysis.curvature_channels(curv)
    assert top > 0 and rgb[..., 0].max() == 0
    assert rgb[0, 0, 1] > 0.9 and rgb[0, 0, 2] == 0 and rgb[1, 1, 2] > 0.9 and rgb[1, 1, 1] == 0


def test_mean_and_gaussian_of_a_dome_have_one_sign():
    _, _, curv = dome()
    inner = curv[5:-5, 5:-5]
    assert np.all(inner[..., 5] > 0)  # a dome is synclastic
    rgb, (lo, hi) = analysis.gaussian_curvature_colours(curv)
    assert lo < 0 < hi and rgb.shape == (30, 30, 3)


def test_zebra_has_both_bands_on_a_dome_and_none_on_a_plane():
    _, mesh, _ = dome()
    rgb, _ = analysis.zebra_colours(mesh, np.array([0.3, -0.5, -0.8]), stripes=10)
    assert 0.1 < rgb[..., 0].mean() < 0.9
    flat = np.array(core.patch((8, 8), (3, 3), (30, 30)).mesh)
    rgb_flat, _ = analysis.zebra_colours(flat, np.array([0.3, -0.5, -0.8]), stripes=10)
    assert np.all(np.ptp(rgb_flat, axis=(0, 1)) == 0)  # a mirror plane reflects one direction: one band


def test_combs_point_along_the_normal_and_scale_with_curvature():
    _, mesh, curv = dome()
    segs, envelope, scale = analysis.curvature_combs(mesh, curv, every=5)
    assert segs.shape[1:] == (2, 3) and scale > 0
    teeth = np.linalg.norm(segs[:, 1] - segs[:, 0], axis=1)
    size = np.linalg.norm(mesh.reshape(-1, 3).max(0) - mesh.reshape(-1, 3).min(0))
    assert np.isclose(teeth.max(), 0.1 * size, rtol=1e-6)
    # the envelope joins each comb line's tips in order: one segment fewer than teeth per line
    g, h = mesh.shape[:2]
    lines = len(range(0, g, 5)) + len(range(0, h, 5))
    assert len(envelope) == len(segs) - lines
    tips = {tuple(np.round(t, 9)) for t in segs[:, 1]}
    assert all(tuple(np.round(p, 9)) in tips for p in envelope.reshape(-1, 3))
    first = segs[:h, 1]  # the first iso-u line's tips, in order
    assert np.allclose(envelope[: h - 1, 0], first[:-1]) and np.allclose(envelope[: h - 1, 1], first[1:])
    # the GUI's scale (gain) and density (every) controls
    longer, _, doubled = analysis.curvature_combs(mesh, curv, every=5, gain=2.0)
    assert np.isclose(doubled, 2 * scale) and len(longer) == len(segs)
    denser, _, _ = analysis.curvature_combs(mesh, curv, every=2)
    assert len(denser) > 2 * len(segs)


def test_map_colours_resample_a_painted_map():
    s = core.patch((8, 8), (3, 3), (20, 20))
    s.stiffness_map.resize(16, 16)
    s.stiffness_map.dab((0.5, 0.5), 0.2, 1000.0, "spherical", 1.0)
    rgb, (lo, hi) = analysis.map_colours(np.array(s.stiffness_map.values), (20, 20))
    assert hi > lo and rgb.shape == (20, 20, 3)
    assert rgb[10, 10, 0] > rgb[0, 0, 0]  # hotter where painted
    rgb_u, _ = analysis.map_colours(np.array([5.0]), (4, 4))
    assert np.all(np.ptp(rgb_u, axis=(0, 1)) == 0)  # one colour


def test_the_deviation_range_spans_the_largest_deviation_shown():
    """A legend that ended at the 98th percentile left the worst points (a scan's crown, a few
    outliers) unread: the range reaches the largest deviation, and at least twice the tolerance."""
    signed = np.concatenate([np.linspace(-0.05, 0.05, 990), [0.8, -0.3, np.nan] * 3 + [1.2]])
    lo, hi = analysis.deviation_range(signed, 0.1)
    assert (lo, hi) == (-1.2, 1.2)
    colours, rng = analysis.deviation_colours(signed, 0.1)
    assert rng == (-1.2, 1.2) and np.allclose(colours[-1], analysis.deviation_colours(np.array([1.2]), 0.1, rng)[0][0])
    assert analysis.deviation_range(np.full(5, 0.01), 0.1) == (-0.2, 0.2)
    assert analysis.deviation_range(np.full(5, np.nan), 0.1) == (-0.2, 0.2)
