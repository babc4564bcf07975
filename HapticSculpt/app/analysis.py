"""Class-A analysis colours and geometry for the overlay, as plain numpy (no FreeCAD, no Coin), so
they are tested in console mode and cost nothing until a display asks for them.

Every function takes the mesh (g, h, 3) and, where needed, the core's curvature grid (g, h, 6:
u and v normal curvature, min and max principal, mean, Gaussian) and returns per-vertex RGB in
[0, 1] plus the range it shows (for the legend).
"""
from __future__ import annotations

import numpy as np

# Pseudo-colour ramp (blue, cyan, green, yellow, red) for maps and signed quantities.
_RAMP = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0]])


def pseudo_colour(values: np.ndarray, lo: float | None = None, hi: float | None = None) -> tuple[np.ndarray, tuple[float, float]]:
    """Values mapped onto the blue-to-red ramp; returns colours (..., 3) and the (lo, hi) shown."""
    v = np.asarray(values, dtype=float)
    lo = float(np.nanmin(v)) if lo is None else lo
    hi = float(np.nanmax(v)) if hi is None else hi
    t = np.zeros_like(v) if hi <= lo else np.clip((v - lo) / (hi - lo), 0.0, 1.0)
    x = t * (len(_RAMP) - 1)
    i = np.minimum(x.astype(int), len(_RAMP) - 2)
    f = (x - i)[..., None]
    return _RAMP[i] * (1 - f) + _RAMP[i + 1] * f, (lo, hi)


def symmetric_range(values: np.ndarray) -> tuple[float, float]:
    """A range centred on zero covering the 98th percentile of |values| (outliers saturate)."""
    a = float(np.percentile(np.abs(values), 98)) if np.size(values) else 0.0
    a = a if a > 0 else 1.0
    return -a, a


def curvature_channels(curv: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
    """The paper's display: |u curvature| in the green channel, |v curvature| in the blue, scaled by
    the larger 98th percentile; red stays 0."""
    ku, kv = np.abs(curv[..., 0]), np.abs(curv[..., 1])
    top = float(max(np.percentile(ku, 98), np.percentile(kv, 98)))
    top = top if top > 0 else 1.0
    rgb = np.zeros(curv.shape[:-1] + (3,))
    rgb[..., 1] = np.clip(ku / top, 0, 1)
    rgb[..., 2] = np.clip(kv / top, 0, 1)
    return rgb, (0.0, top)


def mean_curvature_colours(curv: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
    lo, hi = symmetric_range(curv[..., 4])
    return pseudo_colour(curv[..., 4], lo, hi)


def gaussian_curvature_colours(curv: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
    lo, hi = symmetric_range(curv[..., 5])
    return pseudo_colour(curv[..., 5], lo, hi)


def vertex_normals(mesh: np.ndarray) -> np.ndarray:
    """Unit normals of a (g, h, 3) grid by central differences (one-sided at the border)."""
    du = np.gradient(mesh, axis=0)
    dv = np.gradient(mesh, axis=1)
    n = np.cross(du, dv)
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def zebra_colours(mesh: np.ndarray, view_direction: np.ndarray, stripes: float = 12.0) -> tuple[np.ndarray, tuple[float, float]]:
    """Zebra stripes: black and white bands of parallel light strips seen in the surface as in a
    mirror, so G1 and G2 breaks show as kinks and jumps in the bands. The band index comes from the
    angle of the reflected eye ray across the strips (which run along the view's up direction)."""
    n = vertex_normals(mesh)
    d = np.asarray(view_direction, dtype=float)
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 0.0, 1.0]) if abs(d[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    side = np.cross(d, up)
    side /= np.linalg.norm(side)
    reflected = d - 2 * (n @ d)[..., None] * n  # mirror image of the eye ray
    phase = np.arcsin(np.clip(reflected @ side, -1.0, 1.0))
    band = (np.floor(phase / np.pi * stripes) % 2).astype(float)
    return np.repeat(band[..., None], 3, axis=-1), (0.0, 1.0)


def curvature_combs(mesh: np.ndarray, curv: np.ndarray, every: int = 4, scale: float | None = None,
                    gain: float = 1.0) -> tuple[np.ndarray, np.ndarray, float]:
    """Curvature combs along the u and v iso-lines (every `every`-th line): for each mesh point on
    those lines a tooth from the point along the normal, of length scale * normal curvature along the
    line, and the envelope joining each line's tips (what a designer reads the curvature's flow
    from: teeth alone read as a fence). Returns the teeth (n, 2, 3), the envelope's segments
    (m, 2, 3) and the scale used (mm per 1/mm): ``scale``, else one that makes the longest tooth
    ``gain`` tenths of the patch size."""
    n = vertex_normals(mesh)
    g, h = mesh.shape[:2]
    size = float(np.linalg.norm(mesh.reshape(-1, 3).max(0) - mesh.reshape(-1, 3).min(0)))
    k_max = float(np.abs(curv[..., :2]).max()) if curv.size else 0.0
    if scale is None:
        scale = 0.1 * gain * size / k_max if k_max > 0 else 0.0
    teeth, envelope = [], []
    lines = [(mesh[i], n[i], curv[i, :, 1]) for i in range(0, g, every)]  # iso-u lines: curvature along v
    lines += [(mesh[:, j], n[:, j], curv[:, j, 0]) for j in range(0, h, every)]  # iso-v: along u
    for points, normals, kappa in lines:
        tips = points + normals * (scale * kappa)[:, None]
        teeth.append(np.stack([points, tips], axis=1))
        envelope.append(np.stack([tips[:-1], tips[1:]], axis=1))
    if not teeth:
        return np.zeros((0, 2, 3)), np.zeros((0, 2, 3)), scale
    return np.concatenate(teeth), np.concatenate(envelope), scale


def map_colours(values: np.ndarray, shape: tuple[int, int]) -> tuple[np.ndarray, tuple[float, float]]:
    """A material map (any resolution, or 1x1 uniform) resampled bilinearly onto a (g, h) mesh and
    pseudo-coloured."""
    v = np.asarray(values, dtype=float)
    if v.size == 1:
        v = np.full((2, 2), float(v.ravel()[0]))
    v = v.reshape(v.shape[0], -1)
    g, h = shape
    u = np.linspace(0, v.shape[0] - 1, g)
    w = np.linspace(0, v.shape[1] - 1, h)
    i0 = np.minimum(u.astype(int), v.shape[0] - 2)
    j0 = np.minimum(w.astype(int), v.shape[1] - 2)
    fu = (u - i0)[:, None]
    fw = (w - j0)[None, :]
    out = (v[i0][:, j0] * (1 - fu) * (1 - fw) + v[i0 + 1][:, j0] * fu * (1 - fw) +
           v[i0][:, j0 + 1] * (1 - fu) * fw + v[i0 + 1][:, j0 + 1] * fu * fw)
    lo, hi = float(v.min()), float(v.max())
    if hi <= lo:
        hi = lo + max(abs(lo), 1.0) * 1e-9
    return pseudo_colour(out, lo, hi)


#: The deviation display's colours: within the tolerance, and the ends of the two sides beyond it.
WITHIN_COLOUR = np.array([0.15, 0.8, 0.25])
NO_SCAN_COLOUR = np.array([0.55, 0.55, 0.55])
_ABOVE = np.array([[1.0, 0.95, 0.0], [1.0, 0.0, 0.0]])  # just past +tolerance .. the range's top
_BELOW = np.array([[0.0, 0.9, 1.0], [0.0, 0.0, 1.0]])  # just past -tolerance .. the range's bottom


def deviation_range(signed: np.ndarray, tolerance: float) -> tuple[float, float]:
    """A range centred on zero covering the largest |deviation| shown (a legend that ended below it
    left the worst points unread), at least twice the tolerance, so the band within it is always seen."""
    finite = np.asarray(signed, float)
    finite = finite[np.isfinite(finite)]
    a = float(np.abs(finite).max()) if finite.size else 0.0
    a = max(a, 2.0 * tolerance)
    return -a, a


def deviation_colours(signed: np.ndarray, tolerance: float, rng: tuple[float, float] | None = None
                      ) -> tuple[np.ndarray, tuple[float, float]]:
    """Signed deviations (mm; NaN: no scan there) as colours: green within +-``tolerance``, yellow
    to red beyond it on the positive side, cyan to blue on the negative, grey where there is no
    scan; returns them (..., 3) and the range shown."""
    d = np.asarray(signed, float)
    lo, hi = rng if rng is not None else deviation_range(d, tolerance)
    out = np.broadcast_to(WITHIN_COLOUR, d.shape + (3,)).copy()
    span = max(hi - tolerance, 1e-12)
    with np.errstate(invalid="ignore"):
        above, below = d > tolerance, d < -tolerance
    t = np.clip((np.abs(d) - tolerance) / span, 0.0, 1.0)[..., None]
    out[above] = (_ABOVE[0] * (1 - t) + _ABOVE[1] * t)[above]
    out[below] = (_BELOW[0] * (1 - t) + _BELOW[1] * t)[below]
    out[~np.isfinite(d)] = NO_SCAN_COLOUR
    return out, (lo, hi)
