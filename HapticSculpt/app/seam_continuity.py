"""Curvature continuity (G2) across a seam between faces sculpted together.

Joined along u (:mod:`face_chain`), the faces meet at a knot of full multiplicity: pole row ``r``
is the seam. With the weights fixed (the core never changes them) every derivative of the surface
across the seam is linear in the poles, one column of poles at a time when the weights are a
product ``w_ij = a_i b_j`` (as the exact forms of planes, cylinders and B-spline faces are): for
column j, ``S_u^(k)`` from the left is ``cL_k . P[:, j]`` and from the right ``cR_k . P[:, j]``
(coefficients from the knots and the row weights, :func:`across_coefficients`). With the ratio of
speeds ``alpha`` the faces meet with (constant along the seam, as G1 needs) and ``beta_j`` (the
tangential part of the jump, free in G2), the seam is G2 where, per column,

    (cR_1 - alpha cL_1) . P = 0                     (G1: the tangent planes match)
    (cR_2 - alpha^2 cL_2 - beta_j cL_1) . P = 0     (G2: the normal curvature across matches)

Two poles of each column follow from the others (linked poles in the core: the seam row and the
row two past it on a side that is free), so every stroke keeps them exactly, in every integrator.
When a seam is made G2 the net first moves as little as possible (least squares over the free
poles of each column) so that the conditions hold. ``beta_j`` is the least-squares value at that
time (the jump's part along the tangent, which changes no curvature), so a seam that is G2 already
does not move.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .face_in_solid import basis_derivatives

#: A seam whose normal-curvature jump is at most this share of the larger curvature (or the floor)
#: is G2 already: it is held G2 by default.
G2_SHARE = 0.01


def _spans(knots: np.ndarray, u: float) -> tuple[int, int]:
    """The spans ending and starting at the seam knot u."""
    return int(np.searchsorted(knots, u, side="left") - 1), int(np.searchsorted(knots, u, side="right") - 1)


def across_coefficients(knots_u: np.ndarray, p: int, u: float, row_weights: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per row of poles (all rows of the net), the coefficients of the first and second derivatives
    across the seam at u, from the left and from the right: (c1L, c1R, c2L, c2R), each of length
    ``len(row_weights)``. Rational with the row weights ``a_i`` (fixed): for C = A / W with
    A = sum N_i a_i P_i and W = sum N_i a_i, C' = (A' - W' C) / W and C'' = (A'' - 2 W' C' - W'' C) / W."""
    knots = np.asarray(knots_u, float)
    n = len(row_weights)
    out = []
    for k in _spans(knots, u):
        ders = basis_derivatives(knots, p, u, k, 2)
        rows = np.arange(k - p, k + 1)
        a = np.asarray(row_weights, float)[rows]
        w0, w1, w2 = (float((ders[d] * a).sum()) for d in range(3))
        c0 = ders[0] * a / w0
        c1 = (ders[1] * a - w1 * c0) / w0
        c2 = (ders[2] * a - 2 * w1 * c1 - w2 * c0) / w0
        full1, full2 = np.zeros(n), np.zeros(n)
        full1[rows], full2[rows] = c1, c2
        out.append((full1, full2))
    (c1L, c2L), (c1R, c2R) = out
    return c1L, c1R, c2L, c2R


def _row_weights(weights: np.ndarray | None, nu: int, rows: np.ndarray, edge: str) -> np.ndarray:
    """The row weights a_i of a product w_ij = a_i b_j over ``rows`` (1 for a non-rational net);
    ValueError where the weights are no such product there (the derivatives across would then
    differ from column to column in a way no link can follow)."""
    if weights is None:
        return np.ones(nu)
    w = np.asarray(weights, float)
    a = w[:, 0] / w[0, 0]
    ratio = w[rows] / (a[rows, None] * w[0][None, :])
    if np.ptp(ratio) > 1e-9 * float(np.abs(ratio).max()):
        raise ValueError(f"boundary: the weights across {edge} are not the same in every column; G2 cannot be "
                         f"held there by the net (hold it G1)")
    return a


def _coefficients(poles: np.ndarray, weights: np.ndarray | None, knots_u: np.ndarray, p: int, row: int, u: float,
                  edge: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """across_coefficients for the net's seam at ``row`` (its row weights checked around it)."""
    nu = poles.shape[0]
    a = _row_weights(weights, nu, np.arange(max(row - p - 1, 0), min(row + p + 2, nu)), edge)
    return across_coefficients(knots_u, p, u, a)


def conditions(poles: np.ndarray, weights: np.ndarray | None, knots_u: np.ndarray, p: int, row: int, u: float,
               edge: str) -> tuple[np.ndarray, np.ndarray, float]:
    """The G1 and G2 conditions of every column as coefficient rows over the net's rows: (g1 of
    shape (nu,), g2 of shape (nv, nu): its beta differs per column), and alpha. ValueError when
    the faces do not meet tangentially with one ratio of speeds (G1 is the least G2 needs)."""
    c1L, c1R, c2L, c2R = _coefficients(poles, weights, knots_u, p, row, u, edge)
    d1L, d1R = np.einsum("i,ijk->jk", c1L, poles), np.einsum("i,ijk->jk", c1R, poles)
    nL, nR = np.linalg.norm(d1L, axis=1), np.linalg.norm(d1R, axis=1)
    if np.any(nL <= 0) or np.any(nR <= 0):
        raise ValueError(f"boundary: the surface is degenerate across {edge}; G2 cannot be held there")
    angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(d1L, d1R), axis=1), np.einsum("jk,jk->j", d1L, d1R)))
    if angle.max() > 1e-4:
        raise ValueError(f"boundary: the faces meet at {angle.max():.3g} degrees along {edge}, not tangentially: "
                         f"G2 cannot hold there (hold it G0)")
    ratio = nR / nL
    if np.ptp(ratio) > 1e-6 * ratio.max():
        raise ValueError(f"boundary: the faces meet tangentially along {edge} but with speeds in no fixed ratio; "
                         f"G2 cannot be held there by the net (hold it G1)")
    alpha = float(np.mean(ratio))
    jump = np.einsum("i,ijk->jk", c2R - alpha ** 2 * c2L, poles)
    beta = np.einsum("jk,jk->j", jump, d1L) / nL ** 2  # (the part along the tangent: no curvature)
    g2 = (c2R - alpha ** 2 * c2L)[None, :] - beta[:, None] * c1L[None, :]
    return c1R - alpha * c1L, g2, alpha


def jump_share(poles: np.ndarray, weights: np.ndarray | None, knots_u: np.ndarray, p: int, row: int, u: float,
               edge: str, floor: float, columns: np.ndarray | None = None) -> float:
    """The largest jump of the normal curvature across the seam over the columns of poles (or the
    ``columns`` given), as a share of the larger of the two curvatures there (at least ``floor``,
    1/length)."""
    c1L, c1R, c2L, c2R = _coefficients(poles, weights, knots_u, p, row, u, edge)
    d1L, d1R = np.einsum("i,ijk->jk", c1L, poles), np.einsum("i,ijk->jk", c1R, poles)
    d2L, d2R = np.einsum("i,ijk->jk", c2L, poles), np.einsum("i,ijk->jk", c2R, poles)
    normal = np.cross(d1L, np.gradient(poles[row], axis=0))
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    kL = np.einsum("jk,jk->j", d2L, normal) / np.einsum("jk,jk->j", d1L, d1L)
    kR = np.einsum("jk,jk->j", d2R, normal) / np.einsum("jk,jk->j", d1R, d1R)
    share = np.abs(kR - kL) / np.maximum(np.maximum(np.abs(kL), np.abs(kR)), floor)
    return float(np.max(share if columns is None else share[columns]))


def _slaves(held_rows: set[int], row: int, nu: int) -> tuple[int, int] | None:
    """The two poles of a column that follow the others: the seam's, and the one two rows past it
    on a side where it is free; None if both are held."""
    for other in (row + 2, row - 2):
        if 0 <= other < nu and other not in held_rows and row not in held_rows:
            return row, other
    return None


def project(poles: np.ndarray, weights: np.ndarray | None, knots_u: np.ndarray, p: int, row: int, u: float,
            held: set[int], edge: str) -> np.ndarray:
    """The poles moved as little as possible (least squares over each column's free poles) so
    that the G2 conditions hold exactly; columns whose two followers are held stay as they are.
    ValueError when no column is free enough (too few poles across the seam)."""
    nu, nv = poles.shape[:2]
    g1, g2, _ = conditions(poles, weights, knots_u, p, row, u, edge)
    out = np.array(poles, float)
    free_columns = 0
    for j in range(nv):
        held_rows = {i for i in range(nu) if i * nv + j in held}
        if _slaves(held_rows, row, nu) is None:
            continue
        free_columns += 1
        c = np.stack([g1, g2[j]])
        free = np.array([i for i in range(nu) if i not in held_rows and (c[:, i] != 0).any()])
        cf = c[:, free]
        residual = c @ out[:, j]  # (2, 3)
        out[free, j] -= cf.T @ np.linalg.solve(cf @ cf.T, residual)
    if free_columns == 0:
        raise ValueError(f"boundary: {edge} has too few free poles across it for G2 (the held edges hold the "
                         f"rows two past the seam on both sides): give the faces more controls")
    return out


def links(poles: np.ndarray, weights: np.ndarray | None, knots_u: np.ndarray, p: int, row: int, u: float,
          held: set[int], edge: str) -> list[tuple[int, list[tuple[int, float]]]]:
    """The linked poles that keep the seam G2 (and G1) as the net moves: per column the seam's pole
    and the one two rows past it follow the column's other poles. The poles must satisfy the
    conditions already (:func:`project`)."""
    nu, nv = poles.shape[:2]
    g1, g2, _ = conditions(poles, weights, knots_u, p, row, u, edge)
    out = []
    for j in range(nv):
        held_rows = {i for i in range(nu) if i * nv + j in held}
        pair = _slaves(held_rows, row, nu)
        if pair is None:
            continue
        c = np.stack([g1, g2[j]])
        s = list(pair)
        others = [i for i in range(nu) if i not in s and (c[:, i] != 0).any()]
        # c_s P_s + c_o P_o = 0  ->  P_s = -c_s^-1 c_o P_o
        m = -np.linalg.solve(c[:, s], c[:, others])
        for k, slave in enumerate(s):
            out.append((slave * nv + j, [(i * nv + j, float(m[k, t])) for t, i in enumerate(others) if m[k, t] != 0]))
    return out
