"""Build a FreeCAD ``Part.BSplineSurface`` from poles, full knot vectors, degrees and weights."""
from __future__ import annotations

from typing import Sequence

import numpy as np


def compress_knots(knots: Sequence[float]) -> tuple[list[float], list[int]]:
    """Full knot vector -> (distinct knots, multiplicities), the form Part expects."""
    values: list[float] = []
    mults: list[int] = []
    for x in knots:
        if values and x == values[-1]:
            mults[-1] += 1
        else:
            values.append(float(x))
            mults.append(1)
    return values, mults


def part_bspline(poles: np.ndarray, knots_u: Sequence[float], knots_v: Sequence[float],
                 degree: tuple[int, int], weights: np.ndarray | None = None):
    """A ``Part.BSplineSurface`` with exactly these poles (nu, nv, 3), knots, degrees and weights."""
    import FreeCAD
    import Part
    uk, um = compress_knots(knots_u)
    vk, vm = compress_knots(knots_v)
    vec = [[FreeCAD.Vector(*map(float, poles[i, j])) for j in range(poles.shape[1])] for i in range(poles.shape[0])]
    bs = Part.BSplineSurface()
    if weights is None:
        bs.buildFromPolesMultsKnots(vec, um, vm, uk, vk, False, False, degree[0], degree[1])
    else:
        bs.buildFromPolesMultsKnots(vec, um, vm, uk, vk, False, False, degree[0], degree[1],
                                    [[float(x) for x in row] for row in weights])
    return bs
