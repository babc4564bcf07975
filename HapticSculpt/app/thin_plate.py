"""The thin-plate bending energy of a B-spline net as a quadratic form over its poles: E = tr(P^T K P),
K the integral over the parameters of |S_uu|^2 + 2 |S_uv|^2 + |S_vv|^2 (the term the strokes'
bending uses). A fair fill (:mod:`curve_network`) minimises it; a curve constraint measures in it
which pole moves are smooth (:mod:`curve_constraint`)."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np


def design(knots: np.ndarray, x: np.ndarray, p: int = 3, derivative: int = 0) -> np.ndarray:
    """The B-spline basis of degree ``p`` (or its ``derivative``) at ``x``: (len(x), poles)."""
    from scipy.interpolate import BSpline
    n = len(knots) - p - 1
    out = np.zeros((len(x), n))
    if derivative > p:
        return out
    for j in range(n):
        c = np.zeros(n)
        c[j] = 1.0
        b = BSpline(knots, c, p, extrapolate=False)
        out[:, j] = np.nan_to_num((b.derivative(derivative) if derivative else b)(x))
    return out


def _grams(knots: np.ndarray, p: int, per_span: int) -> list[np.ndarray]:
    """The 1D Gram matrices of the basis's 0th, 1st and 2nd derivatives (Gauss points in every span)."""
    g, w = np.polynomial.legendre.leggauss(per_span)
    breaks = np.unique(knots)
    a, b = breaks[:-1, None], breaks[1:, None]
    x, weight = (0.5 * (a + b) + 0.5 * (b - a) * g).ravel(), (0.5 * (b - a) * w).ravel()
    out = []
    for d in (0, 1, 2):
        n = design(knots, x, p, d)
        out.append(n.T @ (weight[:, None] * n))
    return out


def bending_matrix(surface: Any, poles: Sequence[int] | None = None, per_span: int = 4) -> np.ndarray:
    """K over the poles of the B-spline ``surface`` (a ``core.BSplineSurface``; weights left out:
    a metric, not the exact rational energy), or its rows and columns of ``poles`` alone (pole
    i = iu * nv + iv), built from the 1D Gram matrices without the full matrix."""
    p, q = surface.degree
    nv = surface.controls[1]
    u0, u1, u2 = _grams(np.asarray(surface.knots_u, float), p, per_span)
    v0, v1, v2 = _grams(np.asarray(surface.knots_v, float), q, per_span)
    index = np.arange(surface.controls[0] * nv) if poles is None else np.asarray(poles, int)
    iu, iv = index // nv, index % nv
    pair_u, pair_v = np.ix_(iu, iu), np.ix_(iv, iv)
    return u2[pair_u] * v0[pair_v] + 2.0 * u1[pair_u] * v1[pair_v] + u0[pair_u] * v2[pair_v]
