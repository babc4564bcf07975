"""Held edges (hs.hold_boundary): a sculpt's edges kept exactly (G0), with their tangent planes
(G1), the curvature across them (G2) and its rate (G3) through strokes, as hard constraints; undo,
redo, save and reopen; clear errors."""
from __future__ import annotations

import math
import os
import time

import FreeCAD
import numpy as np
from freecad_support import DocumentTestCase
from test_freecad_layer import stroke

import HapticSculpt as hs


def edge_lines(face, n):
    """(u, v) at n points along each of the face's four edges, by edge."""
    (u0, u1, v0, v1) = face.ParameterRange
    return {"u0": [(u0, v0 + (v1 - v0) * k / (n - 1)) for k in range(n)],
            "u1": [(u1, v0 + (v1 - v0) * k / (n - 1)) for k in range(n)],
            "v0": [(u0 + (u1 - u0) * k / (n - 1), v0) for k in range(n)],
            "v1": [(u0 + (u1 - u0) * k / (n - 1), v1) for k in range(n)]}


def edge_samples(face, n=100):
    """Points and unit normals at n points along each of the face's four edges, by edge."""
    surface = face.Surface
    return {edge: (np.array([tuple(surface.value(u, v)) for u, v in uvs]),
                   np.array([tuple(surface.normal(u, v)) for u, v in uvs])) for edge, uvs in edge_lines(face, n).items()}


def edge_derivatives(face, order, n=60):
    """(edge, k) -> the derivatives of order k (every d^k/du^a dv^b, a + b = k) at n points along
    each of the face's four edges, from the B-spline itself (getDN)."""
    surface = face.Surface
    out = {}
    for edge, uvs in edge_lines(face, n).items():
        for k in range(order + 1):
            if k == 0:
                out[edge, 0] = np.array([tuple(surface.value(u, v)) for u, v in uvs])
            else:
                out[edge, k] = np.array([[tuple(surface.getDN(u, v, a, k - a)) for a in range(k + 1)]
                                         for u, v in uvs])
    return out


def seams(before, after):
    """Per edge: the largest gap (mm) and normal angle (degrees) between two samplings."""
    out = {}
    for edge in before:
        gap = float(np.max(np.linalg.norm(after[edge][0] - before[edge][0], axis=1)))
        cos = np.clip(np.sum(after[edge][1] * before[edge][1], axis=1), -1.0, 1.0)
        out[edge] = (gap, float(np.degrees(np.max(np.arccos(cos)))))
    return out


class TestHeldEdges(DocumentTestCase):
    def test_g1_keeps_edges_and_tangent_planes_through_a_stroke(self):
        obj = hs.make_sculpt(self.doc, controls=(8, 8), mesh=(30, 30))
        held = hs.hold_boundary(obj, "G1")
        self.assertEqual(len(held), 64 - 16)  # two rings of an 8 x 8 net
        before = edge_samples(obj.Shape.Faces[0])
        middle = obj.Shape.Faces[0].Surface.value(0.5, 0.5).z
        stroke(obj)
        after = edge_samples(obj.Shape.Faces[0])
        for edge, (gap, angle) in seams(before, after).items():
            self.assertLessEqual(gap, 1e-9, edge)
            self.assertLessEqual(angle, 0.01, edge)
        self.assertGreater(obj.Shape.Faces[0].Surface.value(0.5, 0.5).z - middle, 2.0)  # the inside moved
        self.assertEqual(hs.held_boundary(obj), {"u0": "G1", "u1": "G1", "v0": "G1", "v1": "G1"})

    def test_g2_and_g3_keep_the_derivatives_across_the_edges_through_a_stroke(self):
        """G2 keeps every derivative up to the second along the edges (so the curvature across
        them: a neighbour meets the face as before, to second order), G3 up to the third."""
        obj = hs.make_sculpt(self.doc, controls=(10, 10), mesh=(40, 40))
        held = hs.hold_boundary(obj, "G2")
        self.assertEqual(len(held), 100 - 16)  # three rings of a 10 x 10 net
        self.assertEqual(hs.held_boundary(obj), {"u0": "G2", "u1": "G2", "v0": "G2", "v1": "G2"})
        before = edge_derivatives(obj.Shape.Faces[0], 3)
        middle = obj.Shape.Faces[0].Surface.value(0.5, 0.5).z
        stroke(obj)
        after = edge_derivatives(obj.Shape.Faces[0], 3)
        self.assertGreater(obj.Shape.Faces[0].Surface.value(0.5, 0.5).z - middle, 2.0)  # the inside moved
        third = 0.0
        for (edge, order), values in before.items():
            change = float(np.max(np.abs(after[edge, order] - values)))
            if order <= 2:
                self.assertLessEqual(change, 1e-9, (edge, order))
            else:
                third = max(third, change)
        self.assertGreater(third, 1e-6, "G2 leaves the third derivative free")
        # G3 on two opposite edges (four rows each, two left free between them)
        hs.hold_boundary(obj, {"u0": "G3", "u1": "G3"})
        self.assertEqual(hs.held_boundary(obj), {"u0": "G3", "u1": "G3", "v0": "free", "v1": "free"})
        before = edge_derivatives(obj.Shape.Faces[0], 3)
        stroke(obj, lift=10.0)
        after = edge_derivatives(obj.Shape.Faces[0], 3)
        for edge in ("u0", "u1"):
            for order in range(4):
                self.assertLessEqual(float(np.max(np.abs(after[edge, order] - before[edge, order]))), 1e-9,
                                     (edge, order))
        # too few poles: refused, saying what would make it possible; nothing changed
        with self.assertRaisesRegex(ValueError, r"u0 and u1 hold 8 rows of the 8 poles along u.*use more controls"):
            hs.hold_boundary(hs.make_sculpt(self.doc, controls=(8, 8)), "G3")
        with self.assertRaisesRegex(ValueError, "G4"):
            hs.hold_boundary(obj, "G4")

    def test_g0_on_some_edges_keeps_those_and_frees_the_others(self):
        obj = hs.make_sculpt(self.doc, controls=(8, 8), mesh=(30, 30))
        hs.hold_boundary(obj, {"u0": "G0", "v1": "G1"})
        self.assertEqual(hs.held_boundary(obj), {"u0": "G0", "u1": "free", "v0": "free", "v1": "G1"})
        before = edge_samples(obj.Shape.Faces[0])
        stroke(obj)
        result = seams(before, edge_samples(obj.Shape.Faces[0]))
        self.assertLessEqual(result["u0"][0], 1e-9)
        self.assertGreater(result["u0"][1], 0.01)  # G0 only: the surface turns along the edge
        self.assertLessEqual(result["v1"][0], 1e-9)
        self.assertLessEqual(result["v1"][1], 0.01)
        self.assertGreater(result["u1"][0], 0.1)  # a free edge follows the stroke

    def test_undo_redo_save_and_reopen(self):
        obj = hs.make_sculpt(self.doc, controls=(8, 8), mesh=(24, 24))
        n = self.doc.UndoCount
        hs.hold_boundary(obj, "G0")
        self.assertEqual(self.doc.UndoCount, n + 1)
        self.assertEqual(self.doc.UndoNames[0], "Hold edges")
        self.doc.undo()
        self.assertEqual(list(obj.Proxy.surface.held_poles), [])
        self.doc.redo()
        self.assertEqual(len(obj.Proxy.surface.held_poles), 28)
        stroke(obj)
        poles, name = np.array(obj.Proxy.surface.poles), obj.Name
        path = os.path.join(self.tmp, "held.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        back = self.doc.getObject(name)
        self.assertEqual(hs.held_boundary(back), {"u0": "G0", "u1": "G0", "v0": "G0", "v1": "G0"})
        self.assertTrue(np.array_equal(np.array(back.Proxy.surface.poles), poles))
        stroke(back, lift=-10.0)  # still held after reopening
        self.assertTrue(np.array_equal(np.array(back.Proxy.surface.poles)[0], poles[0]))

    def test_bad_boundaries_are_refused_by_name_and_change_nothing(self):
        obj = hs.make_sculpt(self.doc, controls=(4, 8), mesh=(20, 20))
        n = self.doc.UndoCount
        for boundary, message in (("G4", "one of free, G0, G1, G2, G3"), ({"w0": "G0"}, "unknown edge 'w0'"),
                                  ({"u0": "G1", "u1": "G1"}, "too few to leave any free"), (3, "boundary: one of")):
            with self.assertRaises((ValueError, TypeError)) as ctx:
                hs.hold_boundary(obj, boundary)
            self.assertIn(message, str(ctx.exception))
        self.assertEqual(self.doc.UndoCount, n)
        self.assertEqual(list(obj.Proxy.surface.held_poles), [])
        self.assertTrue(math.isfinite(obj.Shape.Area))


class TestHeldEdgesInSessions(DocumentTestCase):
    def test_a_session_keeps_held_edges_and_takes_a_hold_made_during_it(self):
        obj = hs.make_sculpt(self.doc, controls=(8, 8), mesh=(24, 24), material="clay")
        hs.hold_boundary(obj, {"u0": "G0"})
        rows = np.array(obj.Proxy.surface.poles)
        pull = hs.ReplayDevice.stroke((10.0, 10.0, 0.0), (10.0, 10.0, 20.0), seconds=0.5, hold=30.0)
        session = hs.Session().start(obj, pull)
        try:
            end = time.monotonic() + 30
            while np.linalg.norm(session.status()["force"]) < 1.0 or session.status()["elapsed"] < 0.8:
                self.assertLess(time.monotonic(), end, "the rope never pulled")
                time.sleep(0.01)
            hs.hold_boundary(obj, {"u0": "G0", "u1": "G1"})  # through the session's edit queue
            while not session.applied_edits:
                self.assertLess(time.monotonic(), end, "the hold never applied")
                session.poll()
                time.sleep(0.01)
        finally:
            session.stop()
        poles = np.array(obj.Proxy.surface.poles)
        self.assertTrue(np.array_equal(poles[0], rows[0]))  # held before the session: never moved
        self.assertGreater(np.abs(poles[3:5] - rows[3:5]).max(), 0.5)  # the rope pulled the inside
        self.assertEqual(hs.held_boundary(obj), {"u0": "G0", "u1": "G1", "v0": "free", "v1": "free"})
        # the hold made during the session stays: another stroke moves the inside, not the u1 rows.
        # It starts where the surface is: the plate (bending on by default) lifted the first bump
        # broadly, so (-10, 0) already stands about 12.5 mm up (8.3 with springs alone) and a
        # stroke from z = 0 to 15, as this test made when it was written, moved it 0.1 mm.
        mesh = np.array(obj.Proxy.surface.mesh).reshape(-1, 3)
        z = float(mesh[np.argmin(np.linalg.norm(mesh[:, :2] - (-10.0, 0.0), axis=1)), 2])
        again = hs.ReplayDevice.stroke((-10.0, 0.0, z), (-10.0, 0.0, z + 15.0), seconds=0.5, hold=0.3)
        hs.Session().start(obj, again, stop_when_finished=True).wait(timeout=30)
        after = np.array(obj.Proxy.surface.poles)
        self.assertTrue(np.array_equal(after[-2:], poles[-2:]))
        self.assertTrue(np.array_equal(after[0], rows[0]))
        self.assertGreater(np.abs(after[2:6] - poles[2:6]).max(), 0.5)
