"""How fair a surface is along sections: the exact normal curvature along straight lines of its
parameter domain, how often it changes sign and its total variation (plain numpy, no FreeCAD).

The curvature comes from the surface's exact first and second derivatives, not from differences of
sampled points: along a section (u, v) = (u0, v0) + t (a, b) the section's curve on the surface has
tangent T = a S_u + b S_v and second derivative C'' = a² S_uu + 2ab S_uv + b² S_vv, and its normal
curvature is κ = n · C'' / |T|² (Meusnier), n the unit surface normal. Two sources of derivatives
are taken: the core's own B-spline (``core.BSplineSurface.evaluate``: what a sculpt's poles make)
and FreeCAD's ``Part.BSplineSurface`` (``getDN``: the surface the document holds), so a test can
check that the written surface is as fair as the core's.

A bump pulled out of a sheet is fair when its normal curvature along any section through it changes
sign at most twice (skirt, crown, skirt); a tent, a crease or a wave adds sign changes and
variation. Values below ``tolerance`` times the section's largest |curvature| count as zero, so
rounding on the flat parts does not count as waves.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

#: A section: from (u0, v0) to (u1, v1) in the surface's parameters.
Section = tuple[tuple[float, float], tuple[float, float]]
#: (u, v) -> (S_u, S_v, S_uu, S_uv, S_vv), each a 3-vector.
Derivatives = Callable[[float, float], tuple[Any, Any, Any, Any, Any]]

SAMPLES = 201  # points per section


@dataclass
class Fairness:
    """Sign changes and total variation (over the largest |curvature|) summed over the sections,
    and per section."""

    sign_changes: int
    variation: float
    per_section: list[tuple[int, float]]
    #: Total variation itself (1/length, not over the largest |curvature|) summed over the
    #: sections: what two shapes of the same lift can be compared by.
    absolute_variation: float = 0.0


def core_derivatives(surface: Any) -> Derivatives:
    """The exact derivatives of a ``core.BSplineSurface`` (e.g. ``DynamicSurface.surface``)."""
    def derivatives(u: float, v: float) -> tuple[Any, Any, Any, Any, Any]:
        d = surface.evaluate(u, v)
        return d["du"], d["dv"], d["duu"], d["duv"], d["dvv"]
    return derivatives


def part_derivatives(surface: Any) -> Derivatives:
    """The exact derivatives of a FreeCAD ``Part.BSplineSurface`` (``getDN``; no FreeCAD import
    here: the surface brings it)."""
    def derivatives(u: float, v: float) -> tuple[Any, Any, Any, Any, Any]:
        return tuple(surface.getDN(u, v, nu, nv) for nu, nv in ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2)))
    return derivatives


def section_curvature(derivatives: Derivatives, section: Section, samples: int = SAMPLES) -> np.ndarray:
    """The exact normal curvature at ``samples`` points evenly spaced along ``section``, along its
    direction."""
    if not isinstance(samples, int) or samples < 3:
        raise ValueError(f"samples: an integer of at least 3, got {samples!r}")
    try:
        (u0, v0), (u1, v1) = section
        u0, v0, u1, v1 = (float(x) for x in (u0, v0, u1, v1))
    except (TypeError, ValueError):
        raise ValueError(f"section: ((u0, v0), (u1, v1)), got {section!r}") from None
    a, b = u1 - u0, v1 - v0
    if not np.isfinite([u0, v0, a, b]).all() or a == 0 and b == 0:
        raise ValueError(f"section: two different finite (u, v) points, got {section!r}")
    t = np.linspace(0.0, 1.0, samples)
    d = np.array([[np.asarray(x, dtype=float) for x in derivatives(u0 + a * s, v0 + b * s)] for s in t])
    su, sv, suu, suv, svv = (d[:, k] for k in range(5))
    tangent = a * su + b * sv
    second = a * a * suu + 2 * a * b * suv + b * b * svv
    normal = np.cross(su, sv)
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    return np.einsum("ij,ij->i", normal, second) / np.maximum(np.einsum("ij,ij->i", tangent, tangent), 1e-300)


def summarize(curvatures: Sequence[np.ndarray], tolerance: float = 0.05, flat: float = 0.0) -> Fairness:
    """Sign changes and total variation over the largest magnitude of each curvature profile,
    summed. |curvature| below ``tolerance`` times a profile's largest, or below ``flat`` (a
    curvature radius too large to see: 1 / (1000 size)), counts as zero; a profile that is flat
    throughout has no sign changes and no variation."""
    if not (0 <= tolerance < 1) or not (flat >= 0) or not np.isfinite(flat):
        raise ValueError(f"tolerance: in [0, 1) and flat: finite and >= 0, got {tolerance!r}, {flat!r}")
    per, absolute = [], 0.0
    for k in curvatures:
        k = np.asarray(k, dtype=float)
        if not np.isfinite(k).all():
            raise ValueError("curvatures: not finite")
        top = float(np.abs(k).max()) if k.size else 0.0
        if top == 0 or top <= flat:
            per.append((0, 0.0))
            continue
        signs = np.sign(k[np.abs(k) > max(tolerance * top, flat)])
        tv = float(np.abs(np.diff(k)).sum())
        absolute += tv
        per.append((int(np.count_nonzero(signs[1:] != signs[:-1])), tv / top))
    return Fairness(sum(c for c, _ in per), float(sum(v for _, v in per)), per, absolute)


def measure(derivatives: Derivatives, sections: Sequence[Section], tolerance: float = 0.05,
            flat: float = 0.0, samples: int = SAMPLES) -> Fairness:
    """Sign changes of the exact normal curvature and its total variation (over its largest
    magnitude, and absolute), summed over ``sections``; ``tolerance`` and ``flat`` as
    :func:`summarize` takes them."""
    return summarize([section_curvature(derivatives, s, samples) for s in sections], tolerance, flat)


def central_sections(centre: tuple[float, float], spread: float = 0.05, diagonals: bool = False,
                     domain: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 1.0), (0.0, 1.0))
                     ) -> list[Section]:
    """Three lines along u and three along v through and beside ``centre`` (``spread`` apart in
    the parameters), edge to edge of ``domain``; with ``diagonals``, also the two diagonals
    through it, as far as the domain goes both ways (toward the corners)."""
    (ua, ub), (va, vb) = domain
    cu, cv = centre
    if not (ua < cu < ub and va < cv < vb):
        raise ValueError(f"centre: inside the domain {domain}, got {centre!r}")
    out: list[Section] = []
    for off in (-spread, 0.0, spread):
        out.append(((ua, cv + off), (ub, cv + off)))
        out.append(((cu + off, va), (cu + off, vb)))
    if diagonals:
        for su, sv in ((1, 1), (1, -1)):
            back = min((cu - ua) if su > 0 else (ub - cu), (cv - va) if sv > 0 else (vb - cv))
            ahead = min((ub - cu) if su > 0 else (cu - ua), (vb - cv) if sv > 0 else (cv - va))
            out.append(((cu - su * back, cv - sv * back), (cu + su * ahead, cv + sv * ahead)))
    return out


def fair_text(report: dict[str, float]) -> str:
    """A Fair's report (api.fair) as the report view says it: how far the poles moved and how the
    peak curvature changed, or that nothing moved."""
    moved = report["moved_mm"]
    before, after = report["peak_curvature_before"], report["peak_curvature_after"]
    if moved < 1e-9:
        return "nothing moved (it was fair already)"
    return f"poles moved up to {moved:.2g} mm, peak curvature {before:.3g} -> {after:.3g} 1/mm"
