# Started with FreeCAD's GUI by the real-input tests (`freecad observer.py`): every 100 ms it writes
# what a test asserts on (documents, sculpts, undo lists, the workbench's state, where the 3D views
# are) to $HS_OBSERVER_OUT as JSON. It only reads: every action in those tests is a real X event.
import json
import os
import sys

import FreeCAD
import FreeCADGui as Gui
from pivy import coin

import HapticSculpt

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HapticSculpt.__file__)), "tests", "gui_input"))
from observer_digest import digest  # noqa: E402

OUT = os.environ["HS_OBSERVER_OUT"]


def _sculpts(doc):
    out = []
    for o in doc.Objects:
        if getattr(getattr(o, "Proxy", None), "Type", None) != "HapticSculpt::Sculpt":
            continue
        settings = json.loads(o.SculptSettings)
        face = o.Shape.Faces[0].Surface if o.Shape.Faces else None
        out.append({"name": o.Name, "poles": list(o.Poles), "strokes": o.Strokes,
                    "shape_poles": [[p.x, p.y, p.z] for row in face.getPoles() for p in row] if face else [],
                    "constraints": [[c["kind"], c["index"]] for c in settings.get("constraints", [])],
                    "plasticity": settings.get("plasticity"), "tool": settings.get("tool", {}).get("name"),
                    "stiffness_map": [min(o.StiffnessMap), max(o.StiffnessMap), len(o.StiffnessMap)],
                    "stiffness_values": list(o.StiffnessMap),
                    "session": o.Proxy.live.session is not None if getattr(o.Proxy, "live", None) else False,
                    "device": o.Proxy.live.session.device_name
                    if getattr(o.Proxy, "live", None) and o.Proxy.live.session else "",
                    "selected": o in Gui.Selection.getSelection(), "screen": _on_screen(o), "digest": digest(o)})
    return out


def _solids(doc):
    out = []
    for o in doc.Objects:
        if getattr(getattr(o, "Proxy", None), "Type", None) != "HapticSculpt::SculptedSolid":
            continue
        shape = o.Shape
        out.append({"name": o.Name, "valid": shape.isValid(), "solids": len(shape.Solids),
                    "closed": all(sh.isClosed() for sh in shape.Shells), "volume": shape.Volume,
                    "faces": len(shape.Faces), "wires": sorted(len(f.Wires) for f in shape.Faces),
                    "seams": json.loads(o.SeamReport or "[]"), "error": o.RebuildError,
                    "sculpt_faces": list(o.SculptFaces), "mirror_mm": _mirror_distance(o),
                    "base_visible": bool(o.Base.ViewObject.Visibility) if o.Base is not None else None})
    return out


def _mirror_distance(o):
    """How far a symmetric SculptedSolid's sculpted face is from its own mirror image (None if it
    has no mirror plane), on a 21 x 21 grid."""
    sym = json.loads(getattr(o, "Symmetry", "") or "null")
    if not sym or not o.Sculpts:
        return None
    from HapticSculpt.app.sculpted_solid import sculpted_surface
    s = sculpted_surface(o.Sculpts[0])
    p0, n = FreeCAD.Vector(*sym["point"]), FreeCAD.Vector(*sym["normal"])
    u0, u1, v0, v1 = s.bounds()
    worst = 0.0
    for i in range(21):
        for j in range(21):
            u, v = u0 + (u1 - u0) * i / 20, v0 + (v1 - v0) * j / 20
            p = s.value(u, v)
            q = s.value(u0 + u1 - u, v) if sym["direction"] == 0 else s.value(u, v0 + v1 - v)
            worst = max(worst, (p - n * (2 * (p - p0).dot(n)) - q).Length)
    return worst


def _on_screen(o):
    """Where the sculpt's centre and corners are in the active 3D view's viewport (its pixels)."""
    try:
        view = Gui.ActiveDocument.ActiveView
        bb = o.Shape.BoundBox
        pts = [FreeCAD.Vector(bb.Center.x, bb.Center.y, bb.ZMax)]
        pts += [FreeCAD.Vector(bb.Center.x + fx * bb.XLength / 2, bb.Center.y + fy * bb.YLength / 2, bb.ZMax)
                for fx, fy in ((0.5, 0), (-0.5, 0), (0, 0.5), (0, -0.5))]
        return [list(view.getPointOnScreen(p)) for p in pts]
    except Exception:  # noqa: BLE001 - no active 3D view
        return []


def _views():
    out = []
    for name in FreeCAD.listDocuments():
        gdoc = Gui.getDocument(name)
        for v in gdoc.mdiViewsOfType("Gui::View3DInventor") if gdoc else []:
            try:
                out.append({"doc": name, "size": list(v.getSize()), "cursor": list(v.getCursorPos()),
                            "camera": v.getCamera(),
                            "active": v is getattr(Gui.ActiveDocument, "ActiveView", None), "id": id(v),
                            "redirect": bool(v.getViewer().isRedirectedToSceneGraph())})
            except Exception:  # noqa: BLE001 - a view closing
                pass
    return out


def write(*_):
    state = {"version": [int(x) for x in FreeCAD.Version()[:2]],
             "workbench": Gui.activeWorkbench().name() if Gui.activeWorkbench() else "",
             "active": FreeCAD.ActiveDocument.Name if FreeCAD.ActiveDocument else None, "docs": {}, "views": _views()}
    for name, doc in FreeCAD.listDocuments().items():
        state["docs"][name] = {"undo": list(doc.UndoNames), "redo": list(doc.RedoNames), "file": doc.FileName,
                               "modified": bool(getattr(doc, "isTouched", lambda: False)()),
                               "gui_modified": bool(getattr(Gui.getDocument(name), "Modified", False)),
                               "sculpts": _sculpts(doc), "objects": [o.Name for o in doc.Objects],
                               "solids": _solids(doc),
                               "screen": {o.Name: _on_screen(o) for o in doc.Objects if hasattr(o, "Shape")}}
    try:
        import HapticSculpt.gui.workbench as hg
        ctl = hg.controller()
        state["painting"] = ctl.painting
        state["inputs"] = len(ctl.inputs)
        state["mouse_point"] = None if ctl.mouse_point is None else [float(x) for x in ctl.mouse_point]
        state["overlays"] = [{"display": ov.display, "frames": ov.frames, "view_size": list(ov.view.getSize()),
                              "hud": ov.hud.boxes() if ov.hud is not None else {},
                              "view": id(ov.view), "object": ov.obj.Name, "cursor": ov.cursor_shown,
                              "drawn": ov._root.getNumChildren() > 0}
                             for ov in ctl.overlays.values()]
    except Exception as exc:  # noqa: BLE001 - the workbench not loaded yet
        state["controller_error"] = str(exc)
    tmp = OUT + ".tmp"
    with open(tmp, "w") as f:
        json.dump(state, f)
    os.replace(tmp, OUT)


_sensor = coin.SoTimerSensor(write, None)
_sensor.setInterval(coin.SbTime(0.1))
_sensor.schedule()
