"""STEP files written by FreeCAD read back by an independent OCCT (cadquery's OCP, in its own virtual
environment), and ``to_cadquery``."""
from __future__ import annotations

import numpy as np

from freecad_support import ROOT, DocumentTestCase, run_ocp

import HapticSculpt as hs
from HapticSculpt.app.part_surface import compress_knots

READ_STEP = """
import json
from OCP.STEPControl import STEPControl_Reader
from OCP.IFSelect import IFSelect_RetDone
from OCP.TopExp import TopExp_Explorer
from OCP.TopAbs import TopAbs_FACE
from OCP.TopoDS import TopoDS
from OCP.BRep import BRep_Tool
reader = STEPControl_Reader()
assert reader.ReadFile(PATH) == IFSelect_RetDone
reader.TransferRoots()
explorer = TopExp_Explorer(reader.OneShape(), TopAbs_FACE)
faces = []
while explorer.More():
    s = BRep_Tool.Surface_s(TopoDS.Face_s(explorer.Current()))
    nu, nv = s.NbUPoles(), s.NbVPoles()
    faces.append({
        "type": s.DynamicType().Name(),
        "degree": [s.UDegree(), s.VDegree()],
        "poles": [[list(s.Pole(i, j).Coord()) for j in range(1, nv + 1)] for i in range(1, nu + 1)],
        "weights": [[s.Weight(i, j) for j in range(1, nv + 1)] for i in range(1, nu + 1)],
        "uknots": [s.UKnot(k) for k in range(1, s.NbUKnots() + 1)],
        "vknots": [s.VKnot(k) for k in range(1, s.NbVKnots() + 1)],
        "umults": [s.UMultiplicity(k) for k in range(1, s.NbUKnots() + 1)],
        "vmults": [s.VMultiplicity(k) for k in range(1, s.NbVKnots() + 1)],
        "periodic": [s.IsUPeriodic(), s.IsVPeriodic()],
        "values": [list(s.Value(u, v).Coord()) for u, v in PARAMS[len(faces)]],
    })
    explorer.Next()
print(json.dumps(faces))
"""


class TestStepIndependentReader(DocumentTestCase):
    def check(self, obj, face, params):
        s = obj.Proxy.surface
        bs = s.surface
        self.assertEqual(face["type"], "Geom_BSplineSurface")
        self.assertEqual(face["degree"], list(bs.degree))
        uk, um = compress_knots(bs.knots_u)
        vk, vm = compress_knots(bs.knots_v)
        poles = np.asarray(s.poles)
        w = np.ones(bs.controls) if bs.weights is None else np.asarray(bs.weights)
        # OCCT's STEP reader turns a closed direction whose ends meet smoothly into a periodic one:
        # the same distinct knots, one pole row fewer (the repeated one), end multiplicities one less.
        if face["periodic"][0]:
            self.assertLess(np.abs(poles[0] - poles[-1]).max(), 1e-12 * s.size)
            poles, w, um = poles[:-1], w[:-1], [um[0] - 1, *um[1:-1], um[-1] - 1]
        if face["periodic"][1]:
            poles, w, vm = poles[:, :-1], w[:, :-1], [vm[0] - 1, *vm[1:-1], vm[-1] - 1]
        self.assertEqual(face["umults"], um)
        self.assertEqual(face["vmults"], vm)
        self.assertLess(np.abs(np.array(face["uknots"]) - uk).max(), 1e-9)
        self.assertLess(np.abs(np.array(face["vknots"]) - vk).max(), 1e-9)
        self.assertLess(np.abs(np.array(face["poles"]) - poles).max(), 1e-9 * s.size)
        self.assertLess(np.abs(np.array(face["weights"]) - w).max(), 1e-9)
        ours = np.array([bs.evaluate(u, v)["point"] for u, v in params])
        self.assertLess(np.abs(np.array(face["values"]) - ours).max(), 1e-9 * s.size)

    @staticmethod
    def params(obj, n=200, seed=5):
        (u0, u1), (v0, v1) = obj.Proxy.surface.surface.domain
        rng = np.random.default_rng(seed)
        return list(zip(rng.uniform(u0, u1, n).tolist(), rng.uniform(v0, v1, n).tolist()))

    def test_sculpt_and_rational_faces_read_back_by_ocp(self):
        plane = hs.make_sculpt(self.doc, controls=(10, 7), mesh=(30, 28), name="Plane")
        hs.run(plane, 1.2, device=hs.ReplayDevice.stroke((0, 0, 0), (10.0, 5.0, 30.0)))
        cyl = self.doc.addObject("Part::Cylinder", "Cyl")
        self.doc.recompute()
        rational = hs.make_sculpt(self.doc, source=(cyl, "Face1"), name="Rational")
        path = hs.export_step([plane, rational], f"{self.tmp}/two.step")
        params = [self.params(plane), self.params(rational)]
        faces = run_ocp(f"PATH = {path!r}\nPARAMS = {params!r}\n" + READ_STEP, self.tmp)
        self.assertEqual(len(faces), 2)
        self.check(plane, faces[0], params[0])
        self.check(rational, faces[1], params[1])


TO_CADQUERY = """
import json, sys
sys.path[:0] = [ROOT, "/usr/lib/freecad-python3/lib"]
import FreeCAD, Part
import HapticSculpt as hs
doc = FreeCAD.openDocument(PATH)
obj = doc.getObject("Sculpt")
face = hs.to_cadquery(obj)
import cadquery as cq
assert isinstance(face, cq.Face), type(face)
fc = obj.Shape.Faces[0]
u0, u1, v0, v1 = fc.ParameterRange
worst = 0.0
for i in range(11):
    for j in range(11):
        u, v = u0 + (u1 - u0) * i / 10, v0 + (v1 - v0) * j / 10
        p = face._geomAdaptor().Value(u, v)
        q = fc.Surface.value(u, v)
        worst = max(worst, ((p.X() - q.x) ** 2 + (p.Y() - q.y) ** 2 + (p.Z() - q.z) ** 2) ** 0.5)
print(json.dumps({"worst": worst, "area": face.Area(), "fc_area": fc.Area, "valid": face.isValid()}))
"""


class TestToCadquery(DocumentTestCase):
    def test_cadquery_face_is_the_same_surface(self):
        obj = hs.make_sculpt(self.doc, mesh=(24, 24))
        hs.run(obj, 1.0, device=hs.ReplayDevice.stroke((0, 0, 0), (0, 0, 20.0)))
        path = f"{self.tmp}/cq.FCStd"
        self.doc.saveAs(path)
        got = run_ocp(f"ROOT = {ROOT!r}\nPATH = {path!r}\n" + TO_CADQUERY, self.tmp)
        self.assertTrue(got["valid"])
        self.assertLess(got["worst"], 1e-12 * obj.Proxy.surface.size)
        self.assertAlmostEqual(got["area"], got["fc_area"], delta=1e-6 * got["fc_area"])

    def test_without_cadquery_the_error_says_how_to_get_it(self):
        import importlib.util
        if importlib.util.find_spec("cadquery") is not None:
            self.skipTest("cadquery is installed in this interpreter")
        obj = hs.make_sculpt(self.doc)
        with self.assertRaisesRegex(ImportError, "pip install cadquery"):
            hs.to_cadquery(obj)

