"""Faces sculpted in place keep the part's continuity by default: each edge held as the base meets
its neighbour there (G2 where curvature-continuous, G1 where tangent, G0 at a crease), measured
from FreeCAD's own normals on both sides of every edge after a stroke."""
from __future__ import annotations

import FreeCAD
import numpy as np
import Part
from test_freecad_sculpted_solid import SolidChecks, face_named, pull

import HapticSculpt as hs
from HapticSculpt.app.edge_pick import base_edge_names, edge_said, own_edge_names
from HapticSculpt.app.sculpted_solid import chain_of_solid
from HapticSculpt.app.solid_api import next_holds


def block(doc, rounded=4):
    """The issue's block, 100 x 80 x 30, ``rounded`` of its four top edges rounded 12 mm; its top."""
    box = Part.makeBox(100, 80, 30)
    edges = sorted((e for e in box.Edges if abs(e.CenterOfMass.z - 30) < 1e-9), key=lambda e: e.Length)
    obj = doc.addObject("Part::Feature", "Block")
    obj.Shape = box.makeFillet(12, edges[:rounded])
    doc.recompute()
    top = face_named(obj.Shape, lambda f: isinstance(f.Surface, Part.Plane) and abs(f.CenterOfMass.z - 30) < 1e-9)
    return obj, top


def edge_angles(shape):
    """For each edge of the sculpted face (the solid's one B-spline face): the largest angle
    (degrees) between FreeCAD's normals of the two faces that meet there, at 41 points, and the
    kind of surface on the other side."""
    sculpted = next(f for f in shape.Faces if isinstance(f.Surface, Part.BSplineSurface))
    out = []
    for e in sculpted.Edges:
        other = next(f for f in shape.Faces if not f.isSame(sculpted) and any(g.isSame(e) for g in f.Edges))
        worst = 0.0
        for t in np.linspace(e.FirstParameter, e.LastParameter, 41):
            p = e.valueAt(t)
            a = sculpted.normalAt(*sculpted.Surface.parameter(p))
            b = other.normalAt(*other.Surface.parameter(p))
            worst = max(worst, float(np.degrees(a.getAngle(b))))
        out.append((type(other.Surface).__name__, worst))
    return out


class TestEdgesHeldAsTheBase(SolidChecks):
    def test_a_rounded_blocks_top_stays_tangent_to_its_rounds(self):
        part, top = block(self.doc)
        obj = hs.sculpt_solid(self.doc, part, [top])
        self.assertEqual(set(hs.boundary_of(obj).values()), {"G1"})  # a plane meets a round: tangent, not G2
        pull(obj, (50, 40, 30), (0, 0, 10))
        self.check_sculpted(obj, part, top)
        self.assertGreater(obj.Shape.BoundBox.ZMax, 36.0)  # pulled up
        angles = edge_angles(obj.Shape)
        self.assertEqual([kind for kind, _ in angles], ["Cylinder"] * 4)
        self.assertLessEqual(max(a for _, a in angles), 0.01, angles)

    def test_creases_stay_g0_and_the_round_g1(self):
        part, top = block(self.doc, rounded=1)
        obj = hs.sculpt_solid(self.doc, part, [top])
        pull(obj, (50, 40, 30), (0, 0, 10))
        self.check_sculpted(obj, part, top)
        kinds = sorted(hs.boundary_of(obj).values())
        self.assertEqual(kinds, ["G0", "G0", "G0", "G1"])
        for kind, angle in edge_angles(obj.Shape):
            if kind == "Cylinder":
                self.assertLessEqual(angle, 0.01)
            else:  # the creases (90 degrees in the part) stay creases, held in place only
                self.assertGreater(angle, 45.0)

    def test_holding_g1_after_strokes_held_g0_repairs_the_tangency(self):
        part, top = block(self.doc)
        obj = hs.sculpt_solid(self.doc, part, [top], boundary="G0")
        pull(obj, (50, 40, 30), (0, 0, 10))
        kinked = max(a for _, a in edge_angles(obj.Shape))
        self.assertGreater(kinked, 5.0)  # (17 degrees: the kink)
        undo = self.doc.UndoCount
        self.assertEqual(set(hs.set_boundary(obj, "G1").values()), {"G1"})
        self.assertEqual(self.doc.UndoCount, undo + 1)
        self.assertLessEqual(max(a for _, a in edge_angles(obj.Shape)), 0.01)
        pull(obj, (50, 40, 36), (0, 0, 4))  # and it holds under the next stroke
        self.check_sculpted(obj, part, top)
        self.assertLessEqual(max(a for _, a in edge_angles(obj.Shape)), 0.01)
        self.doc.undo()
        self.doc.undo()
        self.assertEqual(set(hs.boundary_of(obj).values()), {"G0"})
        self.assertAlmostEqual(max(a for _, a in edge_angles(obj.Shape)), kinked, delta=1e-6)
        # "base" goes back to what the part has
        self.assertEqual(set(hs.set_boundary(obj, "base").values()), {"G1"})

    def test_faces_that_continue_each_other_are_held_g2(self):
        """Two blocks side by side, not refined: their tops are two coplanar faces, curvature-
        continuous across the edge between them (G2), creases elsewhere."""
        shape = Part.makeBox(50, 40, 20).fuse(Part.makeBox(50, 40, 20, FreeCAD.Vector(50, 0, 0)))
        part = self.part(Part.Solid(Part.Shell(shape.Faces)) if len(shape.Solids) != 1 else shape.Solids[0])
        tops = [f"Face{k + 1}" for k, f in enumerate(part.Shape.Faces) if abs(f.CenterOfMass.z - 20) < 1e-9]
        self.assertEqual(len(tops), 2)
        obj = hs.sculpt_solid(self.doc, part, [tops[0]])
        kinds = hs.boundary_of(obj)
        between = next(e for e in kinds if part.Shape.getElement(e).CenterOfMass.z == 20
                       and abs(part.Shape.getElement(e).CenterOfMass.x - 50) < 1e-9)
        self.assertEqual(kinds[between], "G2")
        self.assertEqual(sorted(k for e, k in kinds.items() if e != between), ["G0", "G0", "G0"])
        at = part.Shape.getElement(tops[0]).CenterOfMass
        pull(obj, (at.x, at.y, at.z), (0, 0, 6))
        self.check_sculpted(obj, part, tops[0])
        report = {r["edge"]: r for r in hs.seam_report_of(obj)}
        self.assertLessEqual(report[between]["g1_deg"], 0.01)
        self.assertLessEqual(report[between]["g2_pct"], 1.0)

    def test_a_bad_kind_names_what_is_allowed(self):
        part, top = block(self.doc)
        with self.assertRaisesRegex(ValueError, "one of free, G0, G1, G2, G3, base"):
            hs.sculpt_solid(self.doc, part, [top], boundary="tangent")



def solid_edge_at(obj, base_edge):
    """The SculptedSolid's own name ("EdgeN") of the edge that runs where ``base_edge`` (a base edge
    name) runs now, found independently of edge_pick: the solid edge nearest its base edge's middle
    (outer edges stay in place) or, for a seam, nearest its sculpted middle (given)."""
    mid = obj.Base.Shape.getElement(base_edge)
    point = mid.valueAt(0.5 * (mid.FirstParameter + mid.LastParameter))
    return min((f"Edge{k + 1}" for k in range(len(obj.Shape.Edges))),
               key=lambda n: obj.Shape.getElement(n).distToShape(Part.Vertex(point))[0])


class TestHoldEdgesStepByStep(SolidChecks):
    def test_all_outer_edges_go_round_from_as_the_part_has_them(self):
        part, top = block(self.doc, rounded=1)
        for controls, expected in (((10, 10), ["G0", "G1", "G2", "G3", "base"]),
                                   ((8, 8), ["G0", "G1", "G2", "base", "G0"])):  # (G3 would hold every pole of 8)
            obj = hs.sculpt_solid(self.doc, part, [top], controls=controls)
            base = hs.boundary_of(obj)
            seen = []
            for _ in range(5):
                plan = next_holds(obj)
                hs.set_boundary(obj, plan)
                kinds = hs.boundary_of(obj)
                seen.append("base" if kinds == base else "/".join(sorted(set(kinds.values()))))
            self.assertEqual(seen, expected, controls)

    def test_messages_name_each_edge_as_the_solid_names_it_too(self):
        """The Report view and the HUD name edges as the base does ("seam Edge8"), and the designer
        picking that edge on the SculptedSolid found its Edge15 (a fresh-eyes GUI session): each
        name said comes with the solid's own name of the edge at that place."""
        part, top = block(self.doc, rounded=1)
        round_ = face_named(part.Shape, lambda f: isinstance(f.Surface, Part.Cylinder))
        obj = hs.sculpt_solid(self.doc, part, [top, round_])
        own = own_edge_names(obj)
        self.assertEqual(set(own), set(hs.boundary_of(obj)))  # (every edge and seam held)
        for base, mine in own.items():
            self.assertEqual(mine, solid_edge_at(obj, base), base)
            self.assertEqual(base_edge_names(obj, [mine]), [base])
        differ = [b for b, m in own.items() if b != m]
        self.assertTrue(differ, own)  # (else this part shows nothing)
        self.assertEqual(edge_said(differ[0], obj, own), f"{differ[0]} ({obj.Label} {own[differ[0]]})")
        same = [b for b, m in own.items() if b == m]
        for b in same:
            self.assertEqual(edge_said(b, obj, own), b)

    def test_picked_edges_and_seams_change_alone(self):
        part, top = block(self.doc, rounded=1)
        round_ = face_named(part.Shape, lambda f: isinstance(f.Surface, Part.Cylinder))
        obj = hs.sculpt_solid(self.doc, part, [top, round_], boundary={})
        kinds = hs.boundary_of(obj)
        seam = next(iter(chain_of_solid(obj).seam_edges()))
        self.assertEqual(kinds[seam], "G1")
        # the designer picks the seam on the solid (the solid's own edge name): it goes G2, then G0
        picked = solid_edge_at(obj, seam)
        pull(obj, (50, 40, 30), (0, 0, 4))  # (the seam has moved: found where it runs now)
        self.assertEqual(base_edge_names(obj, [picked]), [seam])
        for expected in ("G2", "G0", "G1"):
            plan = next_holds(obj, [seam])
            self.assertEqual(plan, {seam: expected})
            hs.set_boundary(obj, plan)
            after = hs.boundary_of(obj)
            self.assertEqual(after, {**kinds, seam: expected})  # nothing else changed
        # all outer edges at once leave the seam as it is
        hs.set_boundary(obj, next_holds(obj, [seam]))  # (G2 again)
        plan = next_holds(obj)
        self.assertNotIn(seam, plan)
        hs.set_boundary(obj, plan)
        self.assertEqual(hs.boundary_of(obj)[seam], "G2")
        # an edge of a face that is not sculpted is refused, naming it
        bottom = next(f"Edge{k + 1}" for k, e in enumerate(obj.Shape.Edges) if e.BoundBox.ZMax < 1e-6)
        with self.assertRaisesRegex(ValueError, f"{bottom} is not an edge of its sculpted faces"):
            base_edge_names(obj, [bottom])
