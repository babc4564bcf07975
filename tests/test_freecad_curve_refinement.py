"""Curves the fixed net cannot follow are followed by refining it (issue 48): a smooth arc across a
10 x 10 patch (an interpolated cubic through 9 points, 8 mm high in the middle, at x = -35) was
refused ("comes no closer than 0.00439 mm"); now the net is refined along it until the surface
passes within 0.001 mm, measured with FreeCAD's own surface (distToShape at 200 points), and stays
there through strokes beside it in every integrator, G0 and G1; the insertion leaves the shape as
it was; Undo gives the net back (same poles, same knots); a sculpted solid's top is refined alike."""
from __future__ import annotations

import FreeCAD
import numpy as np
import Part
from test_freecad_curve_constraints import curve_distance, normal_angle
from test_freecad_sculpted_solid import SolidChecks, face_named

import HapticSculpt as hs
from HapticSculpt import core
from HapticSculpt.app import net_refinement, sculpt_state

V = FreeCAD.Vector
TOLERANCE = 0.001


def arc(x=-35.0, z=0.0, half=45.0, height=8.0):
    """The issue's arc: the cubic interpolated through 9 points along y at ``x``, ``height`` mm
    above ``z`` in the middle (a cosine's half wave: no cubic of a coarse net holds it exactly)."""
    curve = Part.BSplineCurve()
    curve.interpolate([V(x, y, z + height * np.cos(np.pi * y / (2 * half))) for y in np.linspace(-half, half, 9)])
    return curve.toShape()


def pull(obj, at, by, integrator=None):
    """A rope stroke: grab at ``at``, pull by ``by`` over 0.5 s, hold 0.3 s, let go."""
    at = np.asarray(at, float)
    dev = hs.ReplayDevice.stroke(tuple(at), tuple(at + np.asarray(by, float)), seconds=0.5, hold=0.3)
    return hs.run(obj, 1.0, device=dev, tool="rope", integrator=integrator)


def section_curvature(face, at, across, n=800):
    """The face's normal curvature (1/mm) along its section by the vertical plane through ``at``
    along ``across`` (a horizontal unit vector), at n points of OCCT's section, ordered by the
    distance along ``across``: (distance, z, curvature), signed with the normal turned up (> 0
    curving up), from FreeCAD's own surface derivatives."""
    across = V(*across)
    plane_normal = across.cross(V(0, 0, 1))
    surface, out = face.Surface, []
    for edge in face.section(Part.Plane(V(*at), plane_normal).toShape()).Edges:
        for p in edge.discretize(Number=n):
            u, v = surface.parameter(p)
            su, sv = surface.getDN(u, v, 1, 0), surface.getDN(u, v, 0, 1)
            normal = su.cross(sv).normalize()
            if normal.z < 0:
                normal = -normal
            t = normal.cross(plane_normal).normalize()  # (the section's direction)
            du, dv = np.linalg.lstsq(np.array([su, sv]).T, np.array(t), rcond=None)[0]
            second = surface.getDN(u, v, 2, 0) * du * du + surface.getDN(u, v, 1, 1) * (2 * du * dv) + \
                surface.getDN(u, v, 0, 2) * dv * dv
            out.append(((p - V(*at)).dot(across), p.z, normal.dot(second) / (su * du + sv * dv).Length ** 2))
    return np.array(sorted(out)).T


def net(obj):
    """The sculpt's stored net: poles, knots in u and in v (the document's properties)."""
    return np.array(obj.Poles), np.array(obj.KnotsU), np.array(obj.KnotsV)


class TestCurveRefinement(SolidChecks):
    def test_an_arc_on_a_coarse_net_is_followed_by_refining_it_through_strokes_in_every_integrator(self):
        curve = arc()
        for integrator in core.INTEGRATORS:
            with self.subTest(integrator=integrator):
                obj = hs.make_sculpt(self.doc, controls=(10, 10), name=f"Arc_{integrator}")
                n = self.doc.UndoCount
                hs.add_curve_constraint(obj, curve)
                self.assertEqual((self.doc.UndoCount, self.doc.UndoNames[0]), (n + 1, "Follow curve"))
                done = obj.Proxy.live.last_curve
                self.assertEqual(done["refined_from"], [10, 10])
                self.assertGreater(done["refined_to"][0] * done["refined_to"][1], 100, done)
                self.assertEqual(list(obj.Proxy.surface.surface.controls), done["refined_to"])
                self.assertLessEqual(curve_distance(obj.Shape.Faces[0], curve), TOLERANCE)
                poles = np.array(obj.Poles)
                pull(obj, (-25.0, 0.0, 6.0), (0.0, 0.0, 10.0), integrator)  # 10 mm beside it
                self.assertGreater(np.abs(np.array(obj.Poles) - poles).max(), 3.0)  # (the stroke moved it)
                face = obj.Shape.Faces[0]
                self.assertLessEqual(curve_distance(face, curve), TOLERANCE)
                self.assertLessEqual(hs.curve_constraints_of(obj)[0]["distance_mm"], TOLERANCE)

    def test_g1_along_the_arc_after_a_stroke(self):
        curve = arc()
        # (G1 holds the normal too: the net is refined further than for G0, past the default mesh's
        # 20 x 20: a finer mesh takes it)
        obj = hs.make_sculpt(self.doc, controls=(10, 10), mesh=(60, 60))
        hs.add_curve_constraint(obj, curve, "G1")
        self.assertGreater(obj.Proxy.live.last_curve["refined_to"][1], 10)
        _, held = normal_angle(obj.Shape.Faces[0], curve)
        pull(obj, (-20.0, 0.0, 5.0), (0.0, 0.0, 12.0))
        face = obj.Shape.Faces[0]
        self.assertLessEqual(curve_distance(face, curve), TOLERANCE)
        worst, _ = normal_angle(face, curve, held)
        self.assertLessEqual(worst, 0.01)
        [info] = hs.curve_constraints_of(obj)
        self.assertLessEqual(info["normal_deg"], 0.01)

    def test_the_insertion_keeps_the_shape_and_undo_gives_the_net_back(self):
        obj = hs.make_sculpt(self.doc, controls=(10, 10))
        pull(obj, (30.0, 5.0, 0.0), (0.0, 0.0, 12.0))  # (a shape to keep: not a flat sheet)
        before = net(obj)
        work = sculpt_state.restore(obj.Proxy.live.stored())
        finer, *_ = net_refinement.refined_work(obj, work, ([0.33, 0.5], [0.21, 0.5, 0.77]))
        self.assertEqual(tuple(finer.surface.controls), (12, 13))
        (was, _), (now, _) = work.surface.grid(23, 29), finer.surface.grid(23, 29)
        self.assertLessEqual(np.abs(now - was).max(), 1e-9 * work.size)
        # (a fresh sheet: the pulled one above happens to hold this arc within 1e-4 mm unrefined)
        obj = hs.make_sculpt(self.doc, controls=(10, 10), name="Fresh")
        before = net(obj)
        curve = arc()
        hs.add_curve_constraint(obj, curve)
        refined = net(obj)
        done = obj.Proxy.live.last_curve
        self.assertGreater(np.prod(done["refined_to"]), np.prod(done["refined_from"]), done)
        self.assertGreater(len(refined[1]) + len(refined[2]), len(before[1]) + len(before[2]))
        self.doc.undo()
        for was, now in zip(before, net(obj)):
            self.assertTrue(np.array_equal(was, now))
        self.assertEqual(hs.curve_constraints_of(obj), [])
        self.assertEqual(tuple(obj.Proxy.surface.surface.controls), (10, 10))
        self.doc.redo()
        for was, now in zip(refined, net(obj)):
            self.assertTrue(np.array_equal(was, now))
        self.assertLessEqual(curve_distance(obj.Shape.Faces[0], curve), TOLERANCE)

    def test_a_tighter_tolerance_refines_further_and_one_past_the_mesh_is_refused(self):
        curve = arc()
        loose = hs.make_sculpt(self.doc, controls=(10, 10), mesh=(60, 60), name="Loose")
        hs.add_curve_constraint(loose, curve)
        tight = hs.make_sculpt(self.doc, controls=(10, 10), mesh=(60, 60), name="Tight")
        hs.add_curve_constraint(tight, curve, tolerance=1e-4)
        a, b = (np.prod(o.Proxy.live.last_curve["refined_to"]) for o in (loose, tight))
        self.assertGreater(b, a)
        self.assertLessEqual(curve_distance(tight.Shape.Faces[0], curve), 1e-4)
        coarse = hs.make_sculpt(self.doc, controls=(10, 10), mesh=(20, 20), name="Coarse")
        n = self.doc.UndoCount
        with self.assertRaisesRegex(ValueError, r"refined from 10 x 10 up to 10 x 10|up to 10 x 10 controls, the most "
                                                r"its 20 x 20 mesh takes"):
            hs.add_curve_constraint(coarse, curve, tolerance=1e-6)
        self.assertEqual(self.doc.UndoCount, n)
        with self.assertRaisesRegex(ValueError, r"tolerance: a length in mm"):
            hs.add_curve_constraint(coarse, curve, tolerance=0.0)

    def test_a_sculpted_solids_top_is_refined_to_follow_an_arc(self):
        box = self.part(Part.makeBox(100, 60, 20), "Block")
        top = face_named(box.Shape, lambda f: abs(f.CenterOfMass.z - 20) < 1e-9)
        obj = hs.sculpt_solid(self.doc, box, [top], controls=(8, 8))
        curve = arc(x=35.0, z=20.0, half=20.0, height=2.0)
        curve.translate(V(0, 30, 0))
        sculpt = obj.Sculpts[0]
        before = net(sculpt)
        hs.add_curve_constraint(obj, curve)
        self.doc.recompute()
        self.assertTrue(obj.Shape.isValid())
        self.assertGreater(len(np.array(sculpt.KnotsV)) + len(np.array(sculpt.KnotsU)), len(before[1]) + len(before[2]))
        top_face = max(obj.Shape.Faces, key=lambda f: f.CenterOfMass.z)
        self.assertLessEqual(curve_distance(top_face, curve), TOLERANCE)
        pull(obj, (70.0, 30.0, 20.0), (0.0, 0.0, 8.0))
        self.doc.recompute()
        top_face = max(obj.Shape.Faces, key=lambda f: f.CenterOfMass.z)
        self.assertTrue(obj.Shape.isValid())
        self.assertLessEqual(curve_distance(top_face, curve), TOLERANCE)
        self.assertLessEqual(max(r["g0_mm"] for r in obj_seams(obj)), 1e-6)
        self.doc.undo()
        self.doc.undo()
        for was, now in zip(before, net(sculpt)):
            self.assertTrue(np.array_equal(was, now))


class TestNoFoldBesideACurve(SolidChecks):
    def test_a_pull_beside_a_line_lifts_a_smooth_bump(self):
        """A rope pulled 10 mm up, 2 mm beside a followed line on a clamped clay patch: along the
        section across the line through the grab, curvature under 0.5 1/mm, and its sign (where it
        is above a tenth of its peak along the section) changes at most twice on the pulled side.
        Across the net (an oblique line): held exactly, its conditions locked every pole whose
        support it crosses, and this pull moved nothing (0.00 mm); along a line of the net."""
        lines = {"oblique": ((-45.0, -30.0), (40.0, 35.0)), "along the net": ((-35.0, -45.0), (-35.0, 45.0))}
        for name, (a, b) in lines.items():
            with self.subTest(line=name):
                obj = hs.make_sculpt(self.doc, controls=(10, 10), edges="held", material="clay", name="Pulled")
                a, b = np.array([*a, 0.0]), np.array([*b, 0.0])
                line = Part.LineSegment(V(*a), V(*b)).toShape()
                hs.add_curve_constraint(obj, line)
                along = (b - a) / np.linalg.norm(b - a)
                across, middle = np.array([along[1], -along[0], 0.0]), (a + b) / 2
                pull(obj, middle + 2.0 * across, (0.0, 0.0, 10.0))  # 2 mm beside it, 10 mm up
                face = obj.Shape.Faces[0]
                self.assertLessEqual(curve_distance(face, line), TOLERANCE)
                x, z, k = section_curvature(face, middle, across)
                pulled = x > 0
                self.assertGreater(z[pulled].max(), 0.25, "the pull lifted the surface beside the line")
                self.assertLess(np.abs(k).max(), 0.5, "curvature along the section across the line")
                signs = np.sign(k[pulled & (np.abs(k) > 0.1 * np.abs(k).max())])
                self.assertLessEqual(int((np.diff(signs) != 0).sum()), 2, "the curvature's sign changes")

    def test_an_arc_the_coarse_net_holds_exactly_is_refined_to_leave_room_beside_it(self):
        """A clamped 8 x 8 patch (New clamped patch) and an arc near its held edges, where the net is
        flat: the net held the arc exactly (1e-14 mm) with no refinement and its conditions pinned
        every pole beside it: a pull 15 mm inside the arc moved nothing (a fresh-eyes GUI session).
        The net is refined until a pull there has room, and the pull lifts the surface."""
        obj = hs.make_sculpt(self.doc, controls=(8, 8), edges="held", material="clay", name="Clamped")
        arc = Part.ArcOfCircle(Part.Circle(V(0, 10, 0), V(0, 0, 1), 46.0), np.radians(221), np.radians(319)).toShape()
        hs.add_curve_constraint(obj, arc)
        done = obj.Proxy.live.last_curve
        self.assertEqual(done["refined_from"], [8, 8])
        self.assertGreater(done["refined_to"][0] * done["refined_to"][1], 64, done)
        before = np.array(obj.Poles).reshape(-1, 3)[:, 2]
        pull(obj, (8.3, -20.1, 0.0), (0.0, 0.0, 16.0))
        moved = np.abs(np.array(obj.Poles).reshape(-1, 3)[:, 2] - before).max()
        self.assertGreater(moved, 2.0, "the pull beside the arc moved it")
        self.assertLessEqual(curve_distance(obj.Shape.Faces[0], arc), TOLERANCE)


class TestCurveAcrossEarlierWork(SolidChecks):
    def test_a_line_across_a_bump_keeps_the_bump_beside_it(self):
        """A clamped 8 x 8 clay patch with a bump pulled up at its middle, and a line at z = 0 along
        it: on the crest, 40 mm and 20 mm off. The least pole move of the 8 x 8 net held the line
        and took the bump with it: on the crest its flanks 20 mm beside fell from 2.9 to 0.5 mm; 40 mm
        off, its crest fell from 4.4 to 2.3 mm (a fresh-eyes GUI session: 10.1 to 6.7 mm). The net is
        refined until the pull stays near the line: heights 20 mm and more beside it kept."""
        def height(obj, x):
            hits = obj.Shape.Faces[0].section(Part.LineSegment(V(x, 0, -100), V(x, 0, 100)).toShape()).Vertexes
            return max(v.Z for v in hits)

        # (and a bump pulled 25 mm up, 17 mm high, as a fresh-eyes GUI session made one: its flanks
        # were flattened with the line on its crest, and, 20 mm off, with a rule that gave up refining
        # after one finer net that did no better)
        cases = ((10.0, 0.0, (-20.0, 20.0)), (10.0, 40.0, (-20.0, 0.0, 20.0)), (10.0, 20.0, (-20.0, 0.0)),
                 (25.0, 0.0, (-30.0, 30.0)), (25.0, 20.0, (-20.0, 0.0)))
        for up, off, kept in cases:
            with self.subTest(pulled=up, line_x=off):
                obj = hs.make_sculpt(self.doc, controls=(8, 8), edges="held", material="clay", name="Bump")
                pull(obj, (0.0, 0.0, 0.0), (0.0, 0.0, up))
                before = {x: height(obj, x) for x in kept}
                self.assertGreater(min(before.values()), 2.0)
                line = Part.LineSegment(V(off, -45, 0), V(off, 45, 0)).toShape()
                hs.add_curve_constraint(obj, line)
                self.assertLessEqual(curve_distance(obj.Shape.Faces[0], line), TOLERANCE)
                self.assertGreater(np.prod(obj.Proxy.live.last_curve["refined_to"]), 64)
                for x, was in before.items():
                    self.assertGreater(height(obj, x), 0.85 * was, f"the bump's height at x = {x:g} mm")


def obj_seams(obj):
    """The sculpted solid's seam report (its edges with the base's faces)."""
    import json
    return json.loads(obj.SeamReport or "[]")


class TestCurveRefusals(SolidChecks):
    def test_a_curve_off_the_face_is_refused_and_changes_nothing(self):
        """A line 35 mm past a 100 mm patch's edge is within a quarter of its size, and was followed
        by dragging the edge out to it; a curve to follow lies over the face."""
        obj = hs.make_sculpt(self.doc, controls=(10, 10))
        n, poles = self.doc.UndoCount, np.array(obj.Poles)
        with self.assertRaisesRegex(ValueError, r"runs off the face, 35 mm past its edge at \(.*, 85, 0\)"):
            hs.add_curve_constraint(obj, Part.LineSegment(V(-30, 85, 0), V(30, 85, 0)).toShape())
        with self.assertRaisesRegex(ValueError, r"runs off the face"):  # (partly over it, partly past)
            hs.add_curve_constraint(obj, Part.LineSegment(V(0, 20, 0), V(0, 70, 0)).toShape())
        self.assertEqual(self.doc.UndoCount, n)
        self.assertTrue(np.array_equal(np.array(obj.Poles), poles))
        # its edge itself is on the face: followed
        hs.add_curve_constraint(obj, Part.LineSegment(V(-30, 50, 0), V(30, 50, 0)).toShape())
        self.assertLessEqual(hs.curve_constraints_of(obj)[0]["distance_mm"], TOLERANCE)

    def test_a_line_under_a_clamped_patchs_bumps_pulls_it_straight_down_onto_the_line(self):
        """A designer's first try (a new designer's GUI session): a clamped patch with two bumps
        pulled up 15 and 20 mm, a sketch line at z = 0 across it through them. The surface's
        closest points to the line lie on the bumps' slopes, and pulling them there threw poles 700 m
        sideways (the view zoomed out to 95 m, the followed curve drawn looping off the patch). It is
        pulled straight down onto the line: within 0.001 mm, the poles moved across the sheet, not
        sideways, the face within its held edges."""
        obj = hs.make_sculpt(self.doc, controls=(8, 8), edges="held", name="Bumped")
        pull(obj, (10.0, 15.0, 0.0), (0.0, 0.0, 20.0))
        pull(obj, (5.0, 25.0, 0.0), (0.0, 0.0, 15.0))
        before = np.array(obj.Poles).reshape(-1, 3)
        self.assertGreater(before[:, 2].max(), 5.0)  # (the bumps)
        line = Part.LineSegment(V(-44.27, 22.13, 0), V(44.51, 21.90, 0)).toShape()
        hs.add_curve_constraint(obj, line)
        after = np.array(obj.Poles).reshape(-1, 3)
        self.assertLessEqual(curve_distance(obj.Shape.Faces[0], line), TOLERANCE)
        if after.shape == before.shape:  # (no refinement was needed: the same poles, moved)
            down = np.abs(after[:, 2] - before[:, 2]).max()
            self.assertGreater(down, 1.0)
            # across the sheet (along the normal of the plane its net lies nearest, here 0.2 degrees
            # off z): sideways by under 1 % of the pull
            self.assertLess(np.abs(after[:, :2] - before[:, :2]).max(), 0.01 * down)
        box = obj.Shape.Faces[0].BoundBox
        self.assertLessEqual(max(abs(box.XMin), abs(box.XMax), abs(box.YMin), abs(box.YMax)), 50.0 + 1e-6, box)
        self.assertLess(box.ZMax, before[:, 2].max())  # (pulled down onto the line, not up)

    def test_a_line_over_a_fresh_clamped_patch_is_followed_by_refining_its_free_middle(self):
        """A clamped 8 x 8 patch leaves 4 x 4 poles free; a line 5 mm over it across its middle needs
        more, and was refused as "no pole is left free" without trying a finer net (a new designer's
        GUI session). It is refined like any net too coarse, and followed."""
        obj = hs.make_sculpt(self.doc, controls=(8, 8), edges="held", name="Clamped")
        line = Part.LineSegment(V(-30, -20, 5), V(30, 20, 5)).toShape()
        hs.add_curve_constraint(obj, line)
        done = obj.Proxy.live.last_curve
        self.assertGreater(done["refined_to"][0] * done["refined_to"][1], 64, done)
        self.assertLessEqual(curve_distance(obj.Shape.Faces[0], line), TOLERANCE)
