"""How fair a shape is along sections: the normal curvature along straight lines of the mass-point
mesh, how often it changes sign and its total variation (plain numpy, no FreeCAD).

A bump pulled out of a sheet is fair when its normal curvature along any section through it
changes sign at most twice (skirt, crown, skirt); a tent, a crease or a wave adds sign changes and
variation. Values below ``tolerance`` times the section's largest |curvature| count as zero, so
rounding on the flat parts does not count as waves.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .analysis import vertex_normals

Section = tuple[tuple[int, int], tuple[int, int]]


@dataclass
class Fairness:
    """Sign changes and total variation (over the largest |curvature|) summed over the sections,
    and per section."""

    sign_changes: int
    variation: float
    per_section: list[tuple[int, float]]


def section_curvature(mesh: np.ndarray, section: Section, normals: np.ndarray | None = None) -> np.ndarray:
    """Normal curvature at the interior points of the mesh line from ``section[0]`` to
    ``section[1]`` (mesh indices (a, b); the line runs along u, v or a diagonal)."""
    mesh = np.asarray(mesh, dtype=float)
    (a0, b0), (a1, b1) = section
    n = max(abs(a1 - a0), abs(b1 - b0))
    if n < 2 or (a1 != a0 and b1 != b0 and abs(a1 - a0) != abs(b1 - b0)):
        raise ValueError(f"section: a mesh line of at least 3 points along u, v or a diagonal, got {section!r}")
    a = a0 + np.sign(a1 - a0) * np.arange(n + 1)
    b = b0 + np.sign(b1 - b0) * np.arange(n + 1)
    if min(a.min(), b.min()) < 0 or a.max() >= mesh.shape[0] or b.max() >= mesh.shape[1]:
        raise ValueError(f"section: {section!r} leaves the {mesh.shape[0]} x {mesh.shape[1]} mesh")
    p = mesh[a, b]
    nrm = (vertex_normals(mesh) if normals is None else normals)[a[1:-1], b[1:-1]]
    second = p[:-2] - 2 * p[1:-1] + p[2:]
    half = 0.5 * np.linalg.norm(p[2:] - p[:-2], axis=1)
    return np.einsum("ij,ij->i", nrm, second) / np.maximum(half, 1e-300) ** 2


def measure(mesh: np.ndarray, sections: Sequence[Section], tolerance: float = 0.05) -> Fairness:
    """Sign changes of the normal curvature and its total variation over its largest magnitude,
    summed over ``sections``."""
    mesh = np.asarray(mesh, dtype=float)
    normals = vertex_normals(mesh)
    per = []
    for section in sections:
        k = section_curvature(mesh, section, normals)
        top = float(np.abs(k).max())
        if top == 0:
            per.append((0, 0.0))
            continue
        signs = np.sign(k[np.abs(k) > tolerance * top])
        per.append((int(np.count_nonzero(signs[1:] != signs[:-1])), float(np.abs(np.diff(k)).sum() / top)))
    return Fairness(sum(c for c, _ in per), float(sum(v for _, v in per)), per)


def central_sections(g: int, h: int, centre: tuple[int, int], spread: int = 2,
                     diagonals: bool = False) -> list[Section]:
    """Three lines along u and three along v through and beside ``centre`` (``spread`` mesh lines
    apart), edge to edge; with ``diagonals``, also the two diagonals through it, corner to corner
    as far as the mesh goes."""
    ca, cb = centre
    out: list[Section] = []
    for off in (-spread, 0, spread):
        out.append(((0, cb + off), (g - 1, cb + off)))
        out.append(((ca + off, 0), (ca + off, h - 1)))
    if diagonals:
        for sa, sb in ((1, 1), (1, -1)):
            back = min(ca if sa > 0 else g - 1 - ca, cb if sb > 0 else h - 1 - cb)
            ahead = min(g - 1 - ca if sa > 0 else ca, h - 1 - cb if sb > 0 else cb)
            out.append(((ca - sa * back, cb - sb * back), (ca + sa * ahead, cb + sb * ahead)))
    return out
