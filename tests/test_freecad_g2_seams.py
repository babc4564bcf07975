"""Curvature-continuous (G2) seams between faces sculpted together (issue 26): the derivative
coefficients across a seam against FreeCAD's own curve, the least move that makes a net G2 and the
links that keep it so, a block's top and its round made G2 across their seam and kept so through
strokes, undo and a saved file, the default G2 for faces that meet so already, and the refusals."""
from __future__ import annotations

import json

import FreeCAD
import numpy as np
import Part
from test_freecad_sculpted_solid import SolidChecks, face_named, mass_point_near, pull

import HapticSculpt as hs
from HapticSculpt import core
from HapticSculpt.app import continuity_check, sculpt_state, seam_continuity
from HapticSculpt.app.face_chain import seam_row
from HapticSculpt.app.face_in_solid import face_edges
from HapticSculpt.app.sculpt_properties import surface_of
from HapticSculpt.app.sculpted_solid import sculpted_surface
from HapticSculpt.gui.overlay import continuity_text


def curvature_across(surface, u, v):
    """The normal curvature at (u, v) in the direction across the iso-line u = const, in the tangent
    plane (from the surface's own derivatives)."""
    d = {(a, b): np.array(tuple(surface.getDN(u, v, a, b))) for a, b in ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2))}
    normal = np.cross(d[1, 0], d[0, 1])
    normal /= np.linalg.norm(normal)
    t = np.cross(d[0, 1], normal)
    a, b = np.linalg.lstsq(np.stack([d[1, 0], d[0, 1]], 1), t, rcond=None)[0]
    return float(normal @ (d[2, 0] * a * a + 2 * d[1, 1] * a * b + d[0, 2] * b * b) / (t @ t))


def seam_jumps(surface, u, n=61):
    """At n points along the seam u (v over its whole range): the jump of the normal curvature
    across it as a share of the larger |curvature| (floor 1e-5 /mm), and the v of each point."""
    u0, u1, v0, v1 = surface.bounds()
    e = 1e-7 * (u1 - u0)
    vs = np.linspace(v0, v1, n)
    out = []
    for v in vs:
        left, right = curvature_across(surface, u - e, v), curvature_across(surface, u + e, v)
        out.append(abs(right - left) / max(abs(left), abs(right), 1e-5))
    return np.array(out), vs


def seam_knot(surface):
    return next(k for k, m in zip(surface.getUKnots(), surface.getUMultiplicities())
                if m >= surface.UDegree and surface.bounds()[0] < k < surface.bounds()[1])


def interior(sculpt, vs):
    """Points of the seam where every pole shaping it is one the seam's conditions link (past the
    spans the held columns at its ends reach: the end spans, three of them on a net refined toward
    the ends of a G2 seam)."""
    s = sculpt.Proxy.live.snapshot()
    return within_links(vs, s.linked_poles, s.surface)


def within_links(vs, linked_poles, surface):
    """:func:`interior` for a net ``surface`` held by ``linked_poles``."""
    nv, p = surface.controls[1], surface.degree[1]
    columns = sorted({pole % nv for pole, *_ in linked_poles})
    t = np.asarray(surface.knots_v, float)
    return (vs > t[columns[0] + p]) & (vs < t[columns[-1] + 1])


class TestCoefficients(SolidChecks):
    def test_the_derivatives_across_a_rational_seam_are_freecads(self):
        rng = np.random.default_rng(1)
        p, knots = 3, np.array([0, 0, 0, 0, 0.3, 0.5, 0.5, 0.5, 0.8, 1, 1, 1, 1.0])
        n = len(knots) - p - 1
        poles, weights = rng.normal(size=(n, 3)), rng.uniform(0.5, 2.0, n)
        values, mults = np.unique(knots, return_counts=True)
        curve = Part.BSplineCurve()
        curve.buildFromPolesMultsKnots([FreeCAD.Vector(*x) for x in poles], [int(m) for m in mults],
                                       [float(k) for k in values], False, p, [float(w) for w in weights])
        c1L, c1R, c2L, c2R = seam_continuity.across_coefficients(knots, p, 0.5, weights)
        e = 1e-7
        for coef, at, order in ((c1L, 0.5 - e, 1), (c1R, 0.5 + e, 1), (c2L, 0.5 - e, 2), (c2R, 0.5 + e, 2)):
            exact = np.array(tuple(curve.getD2(at)[order]))
            self.assertLess(np.abs(coef @ poles - exact).max(), 1e-5 * np.abs(exact).max())

    def test_the_least_move_makes_a_tangent_net_g2_and_the_links_keep_it(self):
        rng = np.random.default_rng(3)
        p, knots = 3, np.array([0, 0, 0, 0, 0.25, 0.5, 0.5, 0.5, 0.75, 1, 1, 1, 1.0])
        nu, nv = len(knots) - p - 1, 6
        u = np.linspace(0.0, 1.0, nu)
        poles = np.zeros((nu, nv, 3))
        poles[..., 0], poles[..., 1] = u[:, None] * 100, np.arange(nv)[None, :] * 10.0
        poles[..., 2] = rng.normal(0, 2, (nu, nv))
        row = seam_row(knots, 0.5)  # (the pole the surface passes through at the seam knot)
        poles[row] = 0.5 * (poles[row - 1] + poles[row + 1])  # (tangent, speeds 1:1, a curvature jump)
        held = {j for j in range(nv)}  # (row 0 held, as an edge)
        moved = seam_continuity.project(poles, None, knots, p, row, 0.5, held, "Edge1")
        g1, g2, alpha = seam_continuity.conditions(moved, None, knots, p, row, 0.5, "Edge1")
        self.assertLess(np.abs(g1 @ moved.transpose(1, 0, 2)).max(), 1e-9)
        self.assertLess(max(np.abs(g2[j] @ moved[:, j]).max() for j in range(nv)), 1e-9)
        self.assertTrue(np.array_equal(moved[0], poles[0]), "held poles do not move")
        self.assertLess(seam_continuity.jump_share(moved, None, knots, p, row, 0.5, "Edge1", 1e-5), 1e-9)
        # least: no smaller move of the free poles satisfies the conditions (perturbing along the
        # conditions' null space only adds to it)
        base = np.linalg.norm(moved - poles)
        for _ in range(5):
            links = seam_continuity.links(moved, None, knots, p, row, 0.5, held, "Edge1")
            other = moved.copy()
            other[1:] += rng.normal(0, 0.1, (nu - 1, nv, 3))
            for pole, masters in links:  # the links put the followers where the conditions want them
                other.reshape(-1, 3)[pole] = sum(w * other.reshape(-1, 3)[m] for m, w in masters)
            self.assertLess(seam_continuity.jump_share(other, None, knots, p, row, 0.5, "Edge1", 1e-5), 1e-9)
            self.assertGreaterEqual(np.linalg.norm(other - poles), base * (1 - 1e-9))
        # too few free poles: the rows two past the seam held on both sides
        both = held | {(row + 2) * nv + j for j in range(nv)} | {(row - 2) * nv + j for j in range(nv)}
        with self.assertRaisesRegex(ValueError, "too few free poles across it for G2.*more controls"):
            seam_continuity.project(poles, None, knots, p, row, 0.5, both, "Edge1")


class TestG2Seams(SolidChecks):
    def check_g2(self, obj, at_most):
        surface = sculpted_surface(obj.Sculpts[0])
        jumps, vs = seam_jumps(surface, seam_knot(surface))
        inside = interior(obj.Sculpts[0], vs)
        self.assertLessEqual(float(jumps[inside].max()), at_most, jumps)
        return jumps, inside

    def test_a_top_and_its_round_made_g2_stay_so_through_strokes_undo_and_a_saved_file(self):
        part, top, round_, seam = self.filleted_box((100, 80, 30), 12)
        base = self.doc.getObject("Part")
        tangent = hs.sculpt_solid(self.doc, part, [top, round_], name="Tangent")
        self.assertEqual(hs.boundary_of(tangent)[seam], "G1")  # a round meets its face tangentially, not G2
        jumps, inside = self.check_g2(tangent, 2.0)  # (the base: 0 /mm on the top, 1/12 on the round)
        self.assertGreater(float(jumps[inside].min()), 0.99)
        obj = hs.sculpt_solid(self.doc, part, [top, round_], boundary={seam: "G2"})
        self.assertEqual(hs.boundary_of(obj)[seam], "G2")
        # made G2 by the least move of the net: past the end spans the jump is gone; in them it
        # fades to the base's at the ends, where the sides (held G0, not sculpted) keep the round
        jumps, inside = self.check_g2(obj, 1e-4)
        self.assertGreater(float(jumps[0]), 0.99)
        self.check_sculpted(obj, base, [top, round_], min_volume=0.0)
        moved = max((sculpted_surface(obj.Sculpts[0]).value(u, v) - sculpted_surface(tangent.Sculpts[0]).value(u, v)).Length
                    for u in np.linspace(*sculpted_surface(obj.Sculpts[0]).bounds()[:2], 41)
                    for v in np.linspace(*sculpted_surface(obj.Sculpts[0]).bounds()[2:], 21))
        self.assertLess(moved, 0.5)  # (measured 0.085 mm: the round eased into a G2 blend)
        # a stroke across the seam keeps it G2, and the seam together (G0) and tangent (G1)
        pull(obj, (50, 6, 29), (0, -3, 5))
        self.check_sculpted(obj, base, [top, round_])
        self.check_g2(obj, 0.01)
        report = next(r for r in hs.seam_report_of(obj) if r["edge"] == seam)
        self.assertLessEqual(report["g0_mm"], 1e-7)
        self.assertLessEqual(report["g1_deg"], 0.01)
        # undo and redo, then a saved file opened again, and another stroke on it
        volume = obj.Shape.Volume
        self.doc.undo()
        self.doc.redo()
        self.assertEqual(obj.Shape.Volume, volume)
        again = self.reopened(obj, "g2_seam.FCStd")
        self.assertEqual(hs.boundary_of(again)[seam], "G2")
        pull(again, mass_point_near(again, 30, 8), (0, 0, 4))
        self.check_g2(again, 0.01)

    def test_every_integrator_holds_the_g2_conditions_through_1000_steps(self):
        """The seam's G2 conditions (the normal-curvature jump across it per column of poles) hold
        to 1e-9 of the curvature through 1,000 steps of a rope pull in every integrator."""
        part, top, round_, seam = self.filleted_box((100, 80, 30), 12)
        obj = hs.sculpt_solid(self.doc, part, [top, round_], boundary={seam: "G2"})
        state = sculpt_state.capture(obj.Sculpts[0].Proxy.live.surface)
        for integrator in core.INTEGRATORS:
            s = sculpt_state.restore(state)
            s.integrator = integrator
            poles = np.array(s.poles)
            weights = None if s.surface.weights is None else np.array(s.surface.weights).reshape(poles.shape[:2])
            knots = np.array(s.surface.knots_u)
            u = seam_knot(sculpted_surface(obj.Sculpts[0]))
            row = seam_row(knots, u)
            mesh = np.array(s.mesh)
            start = mesh[mesh.shape[0] // 2, mesh.shape[1] // 2].copy()
            nv = poles.shape[1]
            linked = sorted({pole % nv for pole, *_ in s.linked_poles})  # (the end columns are held)
            worst = 0.0
            for k in range(1000):
                s.set_cursor(list(start + [0.0, 0.0, min(6.0, 0.02 * k)]), grab=True)
                s.step(1e-3)
                if k % 100 == 99:
                    worst = max(worst, seam_continuity.jump_share(np.array(s.poles), weights, knots, s.surface.degree[0],
                                                                  row, u, seam, 1e-5, linked))
            self.assertLess(worst, 1e-9, integrator)
            # and measured apart from the conditions: FreeCAD's own B-spline of the net it ends with
            part_surface = surface_of(sculpt_state.capture(s))
            jumps, vs = seam_jumps(part_surface, u)
            # (2.3e-4 in every integrator alike near the ends of the net refined toward them, where
            # FreeCAD's curvature is small: a tenth of the G2 tolerance, 1 %, bounds it)
            self.assertLess(float(jumps[within_links(vs, s.linked_poles, s.surface)].max()), 1e-3, integrator)
            self.assertGreater(np.abs(np.array(s.poles) - poles).max(), 1.0, f"{integrator}: the pull moved the net")

    def test_set_boundary_makes_a_seam_g2_and_back_each_one_undo_step(self):
        part, top, round_, seam = self.filleted_box((100, 80, 30), 12)
        # (outer edges G0, as this measurement was made: held G1 as the part has them, the pull
        # leaves 1.6e-3 here, the same open question below)
        obj = hs.sculpt_solid(self.doc, part, [top, round_], boundary="G0")
        pull(obj, (50, 6, 29), (0, -3, 5))
        steps, net = self.doc.UndoCount, np.array(obj.Sculpts[0].Poles)
        hs.set_boundary(obj, {seam: "G2"})
        self.assertEqual(self.doc.UndoCount, steps + 1)
        self.assertEqual(hs.boundary_of(obj)[seam], "G2")
        # (refined toward the seam's ends in the same step: 16 x 8 controls became 16 x 13)
        self.assertEqual(tuple(obj.Sculpts[0].Proxy.surface.surface.controls), (16, 13))
        self.assertEqual(json.loads(obj.Resolution)["fit_knots"][1], [3.125, 6.25, 87.5, 93.75, 96.875])
        # (measured 3-5e-4 all along the seam here since clay keeps the whole pull beside it, 9e-5 when
        # it sprang back. The conditions hold at each column of poles (to 1e-13), not between them:
        # there the surface's jump is sum_j m_j(v) beta_j S_u,j, which leaves the tangent plane where
        # beta_j varies along a seam curved along its length. Open: a beta shared by the columns, or
        # its part along S_v too.)
        self.check_g2(obj, 1e-3)
        pull(obj, (60, 10, 29), (0, 0, 4))
        self.check_g2(obj, 0.01)
        hs.set_boundary(obj, {seam: "G1"})
        self.assertEqual(hs.boundary_of(obj)[seam], "G1")
        self.doc.undo()
        self.assertEqual(hs.boundary_of(obj)[seam], "G2")
        self.doc.undo()
        self.doc.undo()  # (the pull, then Hold edges: the net as it was)
        self.assertTrue(np.array_equal(np.array(obj.Sculpts[0].Poles), net))
        self.assertNotIn("fit_knots", json.loads(obj.Resolution))

    def test_the_check_says_over_how_much_of_its_length_a_seam_is_g2(self):
        """A G2 seam ending on edges held to faces that are not sculpted is G2 in its middle and
        fades toward its ends: the edge's level (its worst point) says G1; the share of its length
        within 1 % says how much is G2, as FreeCAD's own derivatives measure it, and the HUD's
        continuity line gives it."""
        part, top, round_, seam = self.filleted_box((100, 80, 30), 12)
        obj = hs.sculpt_solid(self.doc, part, [top, round_], boundary={seam: "G2"})
        pull(obj, (50, 6, 29), (0, -3, 5))
        found = continuity_check.profiles(obj.Sculpts[0])
        profile = next(p for p in found if p.edge == seam)
        self.assertEqual(continuity_check.level(profile), "G1")  # its worst point
        share = {r["edge"]: r for r in continuity_check.shares(found, hs.boundary_of(obj))}[seam]
        self.assertEqual(share["kind"], "G2")
        surface = sculpted_surface(obj.Sculpts[0])
        jumps, _ = seam_jumps(surface, seam_knot(surface), n=len(profile.points))
        self.assertAlmostEqual(share["share"], float(np.mean(jumps <= 0.01)), delta=0.05)
        self.assertTrue(0.5 < share["share"] < 1.0, share)
        # G2 over at least its middle 80 %: the net refined toward the seam's ends (67 % before)
        self.assertGreaterEqual(share["share"], 0.8, share)
        middle = continuity_check.sample_levels(profile)[int(0.1 * len(profile.points)):-int(0.1 * len(profile.points))]
        self.assertTrue(np.all(middle == continuity_check.LEVELS.index("G2")), middle)
        text = continuity_text({**continuity_check.worst(found), "shares": continuity_check.shares(found, hs.boundary_of(obj))})
        self.assertIn(f"of their length: {seam} G2 over {100 * share['share']:.0f} %", text)
        self.assertIn("g2 jump ", text)
        # the SeamReport says it too: worst point and share within G2
        [row] = [r for r in hs.seam_report_of(obj) if r["edge"] == seam]
        self.assertAlmostEqual(row["g2_within_pct"], 100.0 * share["share"], delta=5.0)
        self.assertEqual(row["g1_within_pct"], 100.0)
        self.assertGreater(row["g2_pct"], 1.0)
        levels = continuity_check.sample_levels(profile)  # (what the combs are coloured by, point by point)
        self.assertEqual(levels[len(levels) // 2], continuity_check.LEVELS.index("G2"))
        self.assertEqual(min(levels[0], levels[-1]), continuity_check.LEVELS.index("G1"))

    def test_faces_that_meet_g2_already_get_a_g2_seam_by_default(self):
        """The top of two boxes fused side by side is two coplanar faces: their seam is G2 (and
        flatter still) already, so it is held G2 by default, and a stroke across it keeps it so."""
        left, right = Part.makeBox(50, 80, 30), Part.makeBox(50, 80, 30, FreeCAD.Vector(50, 0, 0))
        part = self.part(left.fuse(right))
        tops = [f"Face{k + 1}" for k, f in enumerate(part.Shape.Faces) if abs(f.CenterOfMass.z - 30) < 1e-9]
        self.assertEqual(len(tops), 2)
        obj = hs.sculpt_solid(self.doc, part, tops)
        seam = next(e.name for e in face_edges(part.Shape, tops[0]) if tops[1] in e.neighbours)
        self.assertEqual(hs.boundary_of(obj)[seam], "G2")
        pull(obj, (50, 40, 30), (0, 0, 8))
        self.check_sculpted(obj, self.doc.getObject("Part"), tops)
        self.check_g2(obj, 0.01)

    def test_what_cannot_be_g2_is_refused_saying_why(self):
        part, top, round_, seam = self.filleted_box((100, 80, 30), 12)
        with self.assertRaisesRegex(ValueError, f"{seam} is a seam between faces sculpted together.*G3"):
            hs.sculpt_solid(self.doc, part, [top, round_], boundary={seam: "G3"})
        # two sides of a box meet at a right angle: not tangent, so neither G1 nor G2
        box = self.part(Part.makeBox(40, 30, 20), "Box")
        front = face_named(box.Shape, lambda f: abs(f.CenterOfMass.y) < 1e-9)
        top2 = face_named(box.Shape, lambda f: abs(f.CenterOfMass.z - 20) < 1e-9)
        crease = next(e.name for e in face_edges(box.Shape, top2) if front in e.neighbours)
        with self.assertRaisesRegex(ValueError, "not tangentially"):
            hs.sculpt_solid(self.doc, box, [top2, front], boundary={crease: "G2"})
        count = len(self.doc.Objects)
        self.assertEqual(len(self.doc.Objects), count)
