"""Workbench commands (GUI only; registered from InitGui through FreeCADGui.addCommand)."""
from __future__ import annotations

import functools
import json
from typing import Any

import numpy as np

import FreeCAD
import FreeCADGui as Gui

from .. import core
from .view_provider import icon

#: What a greyed-out command waits for, said at the end of its tool tip (shown on the greyed button too).
NEEDS_SCULPT = "Needs a sculpt: select one (or have only one in the document), or make one with New patch or Sculpt face."
NEEDS_TARGET = "Needs a sculpt with a scan target: select a mesh or point cloud and the sculpt, then Set scan target."
NEEDS_CURSOR = "Needs a sculpt and the mouse over it (or a session's cursor)."


#: The drop-down command groups (FreeCAD group commands, as Draft's and PartDesign's): name ->
#: (menu text, tool tip, the commands, the one the button runs until another entry is picked).
GROUPS = {
    # (clamped first: a free sheet pulled at its middle lifts whole, and a designer's first stroke
    # on the button's patch made no bump)
    "HapticSculpt_NewGroup": ("New patch", "A new sculpt patch: flat with held edges (a clamped sheet: a pull makes a "
                              "bump) or free edges (a free sheet), or through selected curves",
                              ["HapticSculpt_NewPatch", "HapticSculpt_NewClampedPatch", "HapticSculpt_NewFromCurves"], 1),
    "HapticSculpt_OutputGroup": ("Output", "Export STEP, or thicken the selected sculpt into a solid",
                                 ["HapticSculpt_ExportStep", "HapticSculpt_Thicken"], 0),
    "HapticSculpt_ToolGroup": ("Tools", f"Choose the sculpting tool: {', '.join(core.TOOLS)}; and the falloff of "
                               f"those that have one. {NEEDS_SCULPT}",
                               [*(f"HapticSculpt_Tool{core.TOOL_INFO[t]['title']}" for t in core.TOOLS),
                                "HapticSculpt_Falloff"], 0),
    "HapticSculpt_MaterialGroup": ("Material", "The material: elastic or clay, keep the shape, fair it, airbrush "
                                   f"the mass, damping, stiffness, bending or pull map, the slider panel. {NEEDS_SCULPT}",
                                   ["HapticSculpt_Material", "HapticSculpt_KeepShape", "HapticSculpt_Fair",
                                    "HapticSculpt_PaintMass", "HapticSculpt_PaintDamping",
                                    "HapticSculpt_PaintStiffness", "HapticSculpt_PaintBending", "HapticSculpt_PaintPull",
                                    "HapticSculpt_Panel"],
                                   0),
    "HapticSculpt_ConstraintGroup": ("Constraints and edges", "Hold the edges (free / G0 to G3), follow a curve "
                                     "(G0 / G1), or toggle a point, normal or curvature constraint at the cursor. "
                                     f"{NEEDS_SCULPT}",
                                     ["HapticSculpt_HoldEdges", "HapticSculpt_FollowCurve", "HapticSculpt_PointConstraint",
                                      "HapticSculpt_NormalConstraint", "HapticSculpt_CurvatureConstraint"], 0),
    "HapticSculpt_DisplayGroup": ("Displays", "Analysis displays: material map, curvature, combs, zebra stripes "
                                  "and their settings; a scan: set it as the target, show the deviation, fit to it",
                                  ["HapticSculpt_ShowMap", "HapticSculpt_ShowCurvature", "HapticSculpt_Combs",
                                   "HapticSculpt_ContinuityCheck",
                                   "HapticSculpt_CombDensity", "HapticSculpt_CombScale", "HapticSculpt_Zebra",
                                   "HapticSculpt_ZebraMode", "HapticSculpt_ZebraStripes",
                                   "HapticSculpt_ZebraDirection", "HapticSculpt_DisplaysOff", "HapticSculpt_SetTarget",
                                   "HapticSculpt_ShowDeviation", "HapticSculpt_FitToTarget", "HapticSculpt_FreeEdgesAndFit",
                                   "HapticSculpt_PullToTarget"], 0),
}
#: The toolbars: few buttons, so that all show at 1280 px beside FreeCAD's own. Output is a toolbar
#: of its own: a toolbar squeezed by a narrow window keeps its first button, so Export STEP never
#: hides behind "»" (next to create, as FreeCAD's File toolbar holds New and Save).
TOOLBARS = {
    "HapticSculpt create": ["HapticSculpt_NewGroup", "HapticSculpt_SculptFace"],
    "HapticSculpt output": ["HapticSculpt_OutputGroup"],
    "HapticSculpt sculpt": ["HapticSculpt_Session", "HapticSculpt_ToolGroup", "HapticSculpt_MaterialGroup"],
    "HapticSculpt tools": ["HapticSculpt_ConstraintGroup"],
    "HapticSculpt analysis": ["HapticSculpt_DisplayGroup"],
}
#: The menu: every command, in sections.
MENU = ["HapticSculpt_NewPatch", "HapticSculpt_NewClampedPatch", "HapticSculpt_NewFromCurves", "HapticSculpt_SculptFace", "Separator", "HapticSculpt_Session", "Separator",
        *[name for group in ("HapticSculpt_ToolGroup", "HapticSculpt_MaterialGroup", "HapticSculpt_ConstraintGroup",
                             "HapticSculpt_DisplayGroup", "HapticSculpt_OutputGroup")
          for name in [*GROUPS[group][2], "Separator"]]][:-1]


def _selected_sculpts() -> list[Any]:
    from ..app.sculpt_feature import is_sculpt
    return [o for o in Gui.Selection.getSelection() if is_sculpt(o)]


#: The gap (mm) between a new patch and what the document holds already.
NEW_PATCH_GAP = 20.0


def free_spot(doc: Any, size: float = 100.0) -> tuple[float, float, float]:
    """Where a new flat ``size`` patch is centred in ``doc``: the origin in an empty document, else
    beside (+X) everything shown there, so that a second patch does not lie on the first (two
    coincident sheets look like one, and a stroke catches either)."""
    boxes = [o.Shape.BoundBox for o in doc.Objects
             if getattr(o, "Visibility", True) and not getattr(getattr(o, "Shape", None), "isNull", lambda: True)()]
    boxes = [b for b in boxes if b.isValid()]
    if not boxes:
        return (0.0, 0.0, 0.0)
    x_max = max(b.XMax for b in boxes)
    y_mid = 0.5 * (min(b.YMin for b in boxes) + max(b.YMax for b in boxes))
    z_min = min(b.ZMin for b in boxes)
    return (round(x_max + NEW_PATCH_GAP + 0.5 * size, 3), round(y_mid, 3), round(z_min, 3))


class NewPatch:
    """A flat 8x8 sculpt patch (100 x 100 mm) with free edges in the active document, or in a new one
    when none is open (as Part's primitives do), beside what the document shows already."""

    #: make_sculpt's ``edges``.
    EDGES = "free"

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("NewPatch"), "MenuText": "New sculpt patch",
                "ToolTip": "Create a flat 100 x 100 mm B-spline patch (8 x 8 poles, degree 3) with free edges to "
                           "sculpt (in a new document when none is open)"}

    def IsActive(self) -> bool:
        return True

    def Activated(self) -> None:
        from .echo import run_echoed
        if FreeCAD.ActiveDocument is None:
            run_echoed("App.newDocument()", modules=())
        first = not FreeCAD.ActiveDocument.Objects
        edges = "" if self.EDGES == "free" else f", edges={self.EDGES!r}"
        spot = free_spot(FreeCAD.ActiveDocument)
        at = f", centre={spot!r}" if any(spot) else ""
        # clay: designers expect what they pull to stay
        run_echoed(f"HapticSculpt.make_sculpt(App.getDocument({FreeCAD.ActiveDocument.Name!r}), material='clay'"
                   f"{edges}{at})")
        FreeCAD.ActiveDocument.recompute()
        if first and getattr(Gui.ActiveDocument, "ActiveView", None) is not None:
            # seen from above and aside, as a drag lifts it: a new document opened in the top view on
            # 0.20, where a drag moved the patch in its own plane, unseen
            Gui.ActiveDocument.ActiveView.viewIsometric()  # (view state, as ViewFit: not in a macro)
        Gui.SendMsgToActiveView("ViewFit")


class NewClampedPatch(NewPatch):
    """The same patch with every edge and its tangent plane held (a clamped sheet:
    ``make_sculpt(edges="held")``); Hold edges frees them again."""

    EDGES = "held"

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("NewClampedPatch"), "MenuText": "New clamped patch",
                "ToolTip": "Create a flat 100 x 100 mm B-spline patch (8 x 8 poles, degree 3) whose edges and "
                           "tangent planes are held (a clamped sheet: strokes raise bumps inside it; Hold edges "
                           "frees them)"}


def _network_selection() -> tuple[list[tuple[str, Any]] | None, str]:
    """The selected curves as (how a script names one, the curve) when the selection is curves only
    (sketches, wires, edges of parts; no sculpt, no face) and holds three or more: a sketch or wire
    picked whole is one curve, or its edges when they close into a loop of 3 or 4 (a boundary drawn
    in one sketch), or its wires when it has several; an edge picked in the view is that edge.
    Else None and why, as a designer reads it."""
    from ..app.sculpt_feature import is_sculpt
    from ..app.sculpted_solid import is_sculpted_solid
    from .echo import ref
    curves: list[tuple[str, Any]] = []
    for pick in Gui.Selection.getSelectionEx():
        obj, shape = pick.Object, getattr(pick.Object, "Shape", None)
        if is_sculpt(obj) or is_sculpted_solid(obj) or shape is None or shape.isNull() or not shape.Edges:
            return None, f"'{obj.Label}' is not a curve"
        if pick.SubElementNames:
            if not all(n.startswith("Edge") for n in pick.SubElementNames):
                return None, f"{', '.join(n for n in pick.SubElementNames if not n.startswith('Edge'))} of " \
                             f"'{obj.Label}' is not a curve (pick its edges)"
            curves += [(f"({ref(obj)}, {n!r})", (obj, n)) for n in pick.SubElementNames]
        elif shape.Faces:
            return None, f"'{obj.Label}' has faces: pick its edges"
        elif len(shape.Wires) == 1 and len(shape.Wires[0].Edges) == len(shape.Edges):
            wire = shape.Wires[0]
            # (the boundary drawn as one sketch; picked alone and open, its edges too: the network
            # then says where it does not close, where "1 curve selected" left a designer guessing)
            alone = len(Gui.Selection.getSelectionEx()) == 1
            if (wire.isClosed() or alone) and len(shape.Edges) in (3, 4):
                curves += [(f"({ref(obj)}, 'Edge{k + 1}')", (obj, f"Edge{k + 1}")) for k in range(len(shape.Edges))]
            else:
                curves.append((ref(obj), obj))
        elif len(shape.Edges) == 1:
            curves.append((ref(obj), obj))
        else:
            curves += [(f"({ref(obj)}, 'Wire{k + 1}')", (obj, f"Wire{k + 1}")) for k in range(len(shape.Wires))]
    if len(curves) < 3:
        return None, (f"{len(curves)} curve{'' if len(curves) == 1 else 's'} selected" if curves else "nothing selected")
    return curves, ""


class NewFromCurves:
    """A new patch through the selected curves: 3 or 4 of them closing into its boundary, the
    others inside it (make_sculpt_from_curves: the least bending between them, the curves held
    while it is sculpted)."""

    MENU_TEXT = "New patch from curves"

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("NewFromCurves"), "MenuText": self.MENU_TEXT,
                "ToolTip": "Select 3 or 4 curves that close into a loop (sketches, wires, edges of parts; or one "
                           "sketch drawing the loop) and any curves inside it: a fair patch whose edges follow the "
                           "loop and which passes through every curve inside within 0.001 mm, each held while it "
                           "is sculpted"}

    def IsActive(self) -> bool:
        # (enabled with a document: pressed with the wrong selection it says what to select, where
        # greyed out it left a designer guessing why)
        return FreeCAD.ActiveDocument is not None

    def Activated(self) -> None:
        from ..app.curve_api import curve_constraints_of
        from ..app.curve_network import split_network
        from .echo import run_echoed
        picked, why = _network_selection()
        if picked is None:
            refuse(self.MENU_TEXT, ValueError(f"{why}: select 3 or 4 curves that close into a loop (sketches, "
                                              f"wires or edges of parts, with ctrl+click) and any curves inside it"))
            return
        doc = Gui.Selection.getSelection()[0].Document
        boundary, interior = split_network([curve for _, curve in picked])
        listed = [", ".join(picked[k][0] for k in ks) for ks in (boundary, interior)]
        inside = f", [{listed[1]}]" if interior else ""
        run_echoed(f"HapticSculpt.make_sculpt_from_curves(App.getDocument({doc.Name!r}), [{listed[0]}]{inside})")
        obj = doc.Objects[-1]
        doc.recompute()
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(obj)
        controls = obj.Proxy.surface.surface.controls
        held = curve_constraints_of(obj)
        within = f", each within {max(c['distance_mm'] for c in held):.2g} mm" if held else ""
        inside = f" through {len(interior)} curve{'s' * (len(interior) > 1)} inside{within}" if interior else ""
        FreeCAD.Console.PrintMessage(f"HapticSculpt: {obj.Label}: a patch on {len(boundary)} boundary curves{inside} "
                                     f"({controls[0]} x {controls[1]} controls)\n")


def _face_selection() -> tuple[Any, list[str], Any] | None:
    """(object, its selected faces, a selected plane or None) when the selection is faces of one
    object, optionally with one plane (a mirror plane for a symmetric sculpt: picked by its face,
    its edge or in the tree); a plane's own face alone is sculpted as a patch. Else None."""
    from ..app.face_symmetry import is_plane
    sel = Gui.Selection.getSelectionEx()
    faces = [s for s in sel if any(n.startswith("Face") for n in s.SubElementNames) and not is_plane(s.Object)]
    planes = [s for s in sel if is_plane(s.Object)]
    if not faces and len(planes) == 1 and len(sel) == 1:
        faces, planes = planes, []
    if len(faces) != 1 or len(planes) > 1 or len(faces) + len(planes) != len(sel):
        return None
    names = [n for n in faces[0].SubElementNames if n.startswith("Face")]
    if not names:
        return None
    return faces[0].Object, names, planes[0].Object if planes else None


def _chain_refusal(picked: tuple[Any, list[str], Any]) -> str:
    """Why Sculpt selected face would refuse the faces of a solid picked together (a ring, faces
    not parameterised alike), '' if the faces make a row: the check sculpt_solid makes first, found
    once per selection and said once in the report view (IsActive runs at every command update)."""
    base, faces, _ = picked
    shape = getattr(base, "Shape", None)
    if len(faces) < 2 or shape is None or len(shape.Solids) != 1:
        return ""
    return _chain_verdict(base.Document.Name, base.Name, tuple(faces), shape.hashCode())


@functools.lru_cache(maxsize=16)
def _chain_verdict(doc: str, name: str, faces: tuple[str, ...], shape_hash: int) -> str:
    """:func:`_chain_refusal` for one selection of one shape (the hash: the shape as it is now)."""
    from ..app import face_chain
    from ..app.sculpted_solid import base_solid
    try:
        face_chain.chain_of(base_solid(FreeCAD.getDocument(doc).getObject(name)), list(faces))
    except ValueError as exc:
        refuse(SculptFace.MENU_TEXT, exc)
        return str(exc)
    return ""


class SculptFace:
    """Sculpt the selected faces in place: faces of a solid become a SculptedSolid (its edges held
    G0, its trims kept, several faces in a row joined into one surface, the solid rebuilt around
    them; with a plane selected too, mirrored in it); a face of anything else a separate patch."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("SculptFace"), "MenuText": self.MENU_TEXT,
                "ToolTip": "Sculpt the selected faces: in place in their solid (each edge held as the part meets "
                           "its other face there: G1 where tangent, G2 where curvature-continuous, G0 at a crease; "
                           "holes kept, faces in a row sculpted as one; Hold edges changes the holds; select a "
                           "plane too for a mirror-symmetric sculpt), or one face as a separate B-spline patch"}

    MENU_TEXT = "Sculpt selected face"

    def IsActive(self) -> bool:
        # (greyed out for faces it would refuse, which the report view then says why)
        picked = _face_selection()
        return picked is not None and not _chain_refusal(picked)

    def Activated(self) -> None:
        from ..app.edge_pick import edge_said, own_edge_names
        from ..app.sculpted_solid import boundary_of, chain_of_solid, held_by_kind
        from .echo import ref, run_echoed
        picked = _face_selection()
        if picked is None:
            return
        base, faces, plane = picked
        doc = base.Document
        if len(base.Shape.Solids) == 1:
            mirror = f", symmetry={ref(plane)}" if plane is not None else ""
            run_echoed(f"HapticSculpt.sculpt_solid(App.getDocument({doc.Name!r}), {ref(base)}, {faces!r}{mirror})")
            obj = doc.Objects[-1]
            kinds = boundary_of(obj)
            seam_names = chain_of_solid(obj).seam_edges()
            own = own_edge_names(obj) if seam_names else {}
            seams = [f"{edge_said(e, obj, own)} {kinds[e]}" for e in sorted(seam_names, key=lambda e: int(e[4:]))]
            outer = {e: k for e, k in kinds.items() if e not in seam_names}
            FreeCAD.Console.PrintMessage(
                f"HapticSculpt: {obj.Label}: {', '.join(faces)} of {base.Label} sculpted in place, edges held as "
                f"the part meets its other faces there ({held_by_kind(outer)})"
                + (f", mirrored in {plane.Label}" if plane is not None else "")
                + (f", seams {', '.join(seams)}" if seams else "") + "\n")
            # The picked faces are gone with the base, hidden under the new solid: nothing stays
            # selected (as after FreeCAD's own features); the commands take the sculpt under the
            # mouse, else the document's only one.
            Gui.Selection.clearSelection()
            return
        run_echoed(f"HapticSculpt.make_sculpt(App.getDocument({doc.Name!r}), source=({ref(base)}, {faces[0]!r}), "
                   "material='clay')")
        obj = doc.Objects[-1]
        Gui.Selection.clearSelection()
        FreeCAD.Console.PrintMessage(f"HapticSculpt: {obj.Label} from {obj.SourceDescription}, "
                                     f"{obj.ConversionMethod}, error {obj.ConversionError:.3g} mm\n")


def _sculpt_to_thicken() -> Any:
    """The selected sculpt, else the active document's only sculpt that is no face of a solid."""
    from ..app.sculpt_feature import is_sculpt
    from ..app.sculpted_solid import is_sculpted_solid
    picked = _selected_sculpts()
    if picked:
        return picked[0] if len(picked) == 1 else None
    doc = FreeCAD.ActiveDocument
    if doc is None:
        return None
    in_solids = {id(s) for o in doc.Objects if is_sculpted_solid(o) for s in o.OutList}
    free = [o for o in doc.Objects if is_sculpt(o) and id(o) not in in_solids]
    return free[0] if len(free) == 1 else None


class Thicken:
    """Thicken the selected sculpt (else the document's only one) into a parametric solid: a task
    panel asks the thickness."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("Thicken"), "MenuText": "Thicken",
                "ToolTip": "Offset the selected sculpt surface (else the only one) into a solid that follows it "
                           "(asks the thickness; double-click the Thickness to change it)"}

    def IsActive(self) -> bool:
        return _sculpt_to_thicken() is not None and not Gui.Control.activeDialog()

    def Activated(self) -> None:
        from .thickness_panel import ThicknessPanel
        sculpt = _sculpt_to_thicken()
        if sculpt is not None:
            Gui.Control.showDialog(ThicknessPanel(sculpt=sculpt))


class ExportStep:
    """Export the selection, else the one visible result built on a sculpt, to a STEP file
    named in a task panel (FreeCAD's file chooser, STEP preselected)."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("ExportStep"), "MenuText": "Export STEP",
                "ToolTip": "Export the selected objects to a STEP file; with nothing selected, what you see of "
                           "your sculpting (the thickened solid, the sculpted solid, or the sculpt)"}

    def IsActive(self) -> bool:
        from .export_panel import exportable
        return bool(exportable(Gui.Selection.getSelection(), FreeCAD.ActiveDocument))

    def Activated(self) -> None:
        from .export_panel import ExportStepPanel, exportable
        objs = exportable(Gui.Selection.getSelection(), FreeCAD.ActiveDocument)
        if objs and not Gui.Control.activeDialog():
            Gui.Control.showDialog(ExportStepPanel(objs))


def _ctl() -> Any:
    from .workbench import controller
    return controller()


def _has_sculpt() -> bool:
    return _ctl().active_sculpt() is not None


class _SculptCommand:
    """A command on the active sculpt (selected, else the document's last): active only with one."""

    icon_name = "HapticSculpt"
    menu = tip = ""
    needs = NEEDS_SCULPT

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon(self.icon_name), "MenuText": self.menu, "ToolTip": f"{self.tip}. {self.needs}"
                if not self.tip.endswith(".") else f"{self.tip} {self.needs}"}

    def IsActive(self) -> bool:
        return _has_sculpt()


class Session(_SculptCommand):
    icon_name = "Session"
    menu = "Start/stop sculpting"
    tip = ("Start sculpting the selected sculpt (or the only one) with the first attached force device (Falcon, "
           "Touch/Phantom, Force Dimension), else a SpaceMouse, else the mouse (its left button grabs); run again to "
           "stop, or with another sculpt selected (or in another document) to sculpt that one instead")

    def IsActive(self) -> bool:
        return _ctl().session is not None or _has_sculpt()

    def Activated(self) -> None:
        ctl = _ctl()
        target = None
        if ctl.session is not None:
            target, left = ctl.session_switch_target(), ctl.session.obj
            if target is None:
                ctl.stop_session()
                return
            names = [o.Label if left.Document == target.Document else f"{o.Label} ({o.Document.Label})"
                     for o in (left, target)]  # (two documents may each have a Sculpt)
            ctl.stop_session()
            FreeCAD.Console.PrintMessage(f"HapticSculpt: stopped sculpting {names[0]}; sculpting {names[1]} now\n")
        try:
            ctl.start_session(obj=target)
        except RuntimeError as exc:
            FreeCAD.Console.PrintWarning(f"HapticSculpt: {exc}\n")


class Material(_SculptCommand):
    icon_name, menu = "Material", "Elastic / Clay"
    tip = ("Switch the sculpt's material: clay (what you pull stays) or elastic (springs back to its rest shape "
           "unless held by constraints)")

    def Activated(self) -> None:
        from ..app.api import material_of
        from .echo import ref, run_echoed
        obj = _ctl().active_sculpt()
        new = "elastic" if material_of(obj) == "clay" else "clay"
        run_echoed(f"HapticSculpt.set_material({ref(obj)}, {new!r})")
        FreeCAD.Console.PrintMessage(f"HapticSculpt: {obj.Label} is {new} now\n")


class KeepShape(_SculptCommand):
    icon_name, menu = "KeepShape", "Keep shape"
    tip = "Make the current shape the rest shape: an elastic sculpt stays as it is now (also while sculpting)"

    def Activated(self) -> None:
        from .echo import ref, run_echoed
        run_echoed(f"HapticSculpt.keep_shape({ref(_ctl().active_sculpt())})")


class Fair(_SculptCommand):
    icon_name, menu = "Fair", "Fair"
    tip = ("Relax the curvature variation of the active sculpt (waves, tents, creases) while its held and "
           "linked poles and its symmetry hold; one undo step")

    def Activated(self) -> None:
        from ..app.fairness import fair_text
        from .echo import ref, run_echoed
        obj = _ctl().active_sculpt()
        obj.Proxy.live.last_fair = None
        run_echoed(f"HapticSculpt.fair({ref(obj)})")
        report = obj.Proxy.live.last_fair
        if report is not None:
            FreeCAD.Console.PrintMessage(f"HapticSculpt: {obj.Label} faired: {fair_text(report)}\n")


class HoldEdges(_SculptCommand):
    icon_name, menu = "HoldEdges", "Hold edges: free / G0 / G1 / G2 / G3"
    tip = ("Hold the sculpt's edges exactly (hard constraints): G0 keeps them where they are, G1 their "
           "tangent planes too, G2 the curvature across them too, G3 its rate; each press goes free, G0, G1, "
           "G2, G3, free, skipping what the net cannot hold (a face sculpted in its solid: G0 to G3)")
    needs = NEEDS_SCULPT[:-1] + "; a face sculpted in its solid: with no session running."

    def IsActive(self) -> bool:
        # (a solid's edges change with a rebuilt net, which waits for the session to stop: greyed
        # out meanwhile, where it used to stay enabled and refuse with a warning)
        from ..app.sculpted_solid import solid_of
        obj = _ctl().active_sculpt()
        return obj is not None and not (solid_of(obj) is not None and obj.Proxy.live.session is not None)

    def Activated(self) -> None:
        from ..app.api import BOUNDARIES, boundary_poles, held_boundary
        from ..app.sculpted_solid import solid_of
        from .echo import ref, run_echoed
        obj = _ctl().active_sculpt()
        solid = solid_of(obj)
        if solid is not None:
            _hold_solid_edges(solid)
            return
        now = set(held_boundary(obj).values())
        current = BOUNDARIES.index(now.pop()) if len(now) == 1 else 0
        controls = tuple(obj.Proxy.live.snapshot().surface.controls)

        def holds(kind: str) -> bool:
            try:
                boundary_poles(controls, kind)
            except ValueError:
                return False
            return True
        following = next((k for k in BOUNDARIES[current + 1:] if holds(k)), "free")
        try:
            run_echoed(f"HapticSculpt.hold_boundary({ref(obj)}, {following!r})")
        except Exception as exc:  # noqa: BLE001 - doCommand raises what the call raised (a curve that cannot hold)
            FreeCAD.Console.PrintWarning(f"HapticSculpt: {obj.Label}: {exc}\n")
            return
        FreeCAD.Console.PrintMessage(f"HapticSculpt: {obj.Label}: edges {following}\n")


def _hold_solid_edges(solid: Any) -> None:
    """Hold edges on a SculptedSolid: the edges and seams of it the designer picked go one step
    further (all its outer edges when none is picked), through set_boundary, echoed; the report
    view says what each now holds, or in one line why nothing changed."""
    from ..app.edge_pick import base_edge_names, edge_said, own_edge_names
    from ..app.sculpted_solid import boundary_of, chain_of_solid, held_by_kind
    from ..app.solid_api import next_holds
    from .echo import ref, run_echoed
    if solid.Sculpts[0].Proxy.live.session is not None:
        FreeCAD.Console.PrintWarning(f"HapticSculpt: {solid.Label}: stop the sculpting session to change how "
                                     "its edges are held\n")
        return
    picked = [n for s in Gui.Selection.getSelectionEx() if s.Object == solid
              for n in s.SubElementNames if n.startswith("Edge")]
    try:
        edges = base_edge_names(solid, picked) if picked else []
        plan = next_holds(solid, edges)
        if not plan:
            FreeCAD.Console.PrintWarning(f"HapticSculpt: {solid.Label}: {', '.join(edges) or 'its edges'} cannot be "
                                         "held any other way on this net\n")
            return
        run_echoed(f"HapticSculpt.set_boundary({ref(solid)}, {plan!r})")
    except (ValueError, RuntimeError) as exc:  # (doCommand raises what the call raised)
        FreeCAD.Console.PrintWarning(f"HapticSculpt: {solid.Label}: {exc}\n")
        return
    kinds = boundary_of(solid)
    seams = chain_of_solid(solid).seam_edges()
    own = own_edge_names(solid) if edges else {}
    what = ", ".join(f"{'seam ' if e in seams else ''}{edge_said(e, solid, own)} held {kinds[e]}" for e in plan) if edges else \
        f"edges held {held_by_kind({e: kinds[e] for e in plan})}"
    FreeCAD.Console.PrintMessage(f"HapticSculpt: {solid.Label}: {what}\n")


def _curve_selection() -> tuple[Any, str, Any, str] | None:
    """(the sculpt, how a script names the curve, the curve, how messages name it) when the selection is one curve (a
    sketch or a wire, whole wherever it was clicked, or an edge of a part) and at most one sculpt or
    sculpted solid (else the one under the mouse or the document's only one); else None."""
    from ..app.sculpt_feature import is_sculpt
    from ..app.sculpted_solid import is_sculpted_solid, sculpt_for
    from .echo import ref
    sel = Gui.Selection.getSelectionEx()
    sculpts = [s.Object for s in sel if is_sculpt(s.Object) or is_sculpted_solid(s.Object)]
    others = [s for s in sel if s.Object not in sculpts]
    if len(sculpts) > 1 or len(others) != 1:
        return None
    pick = others[0]
    edges = [n for n in pick.SubElementNames if n.startswith("Edge")]
    shape = getattr(pick.Object, "Shape", None)
    if shape is None or shape.isNull() or not shape.Edges or (pick.SubElementNames and len(edges) != 1):
        return None
    whole = not shape.Faces and (len(shape.Wires) == 1 and len(shape.Wires[0].Edges) == len(shape.Edges)
                                 or len(shape.Edges) == 1)
    if whole or (not shape.Faces and not edges):  # a sketch or a wire: the whole curve, wherever clicked
        code, curve, label = ref(pick.Object), pick.Object, pick.Object.Label  # (several wires: the call says why not)
    elif edges:  # an edge of a part (or of a sketch of several wires)
        code, curve = f"{ref(pick.Object)}.Shape.{edges[0]}", getattr(shape, edges[0])
        label = f"{pick.Object.Label} {edges[0]} (that edge alone)"
    else:
        return None
    target = sculpts[0] if sculpts else _ctl().active_sculpt()
    if target is None or sculpt_for(target) is None:
        return None
    return target, code, curve, label


class FollowCurve:
    """The sculpt follows the selected curve exactly: each press on the same curve goes G0 (through
    it), G1 (along it with the normal it has), off."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("FollowCurve"), "MenuText": "Follow curve: G0 / G1 / off",
                "ToolTip": "Select a sketch, a wire or an edge (and the sculpt): the surface passes exactly through "
                           "it from now on (G0; pulled onto it if it is near), through every stroke; press again "
                           "with the same curve for G1 (its normal along the curve kept too), again to free it"}

    def IsActive(self) -> bool:
        return _curve_selection() is not None

    def Activated(self) -> None:
        from ..app.curve_api import constraint_along, not_in_session
        from ..app.sculpted_solid import sculpt_for
        from .echo import ref, run_echoed
        picked = _curve_selection()
        if picked is None:
            return
        target, code, curve, label = picked
        try:
            # (refused before its call is echoed: a console line for a call that did nothing read
            # as done, and a session's designer looks at the HUD, where refuse() says it too)
            not_in_session(sculpt_for(target), f"following {label}")
            now = constraint_along(target, curve)
        except (TypeError, ValueError, RuntimeError) as exc:  # (a sketch of several wires: which one is meant?)
            refuse(f"{target.Label} cannot follow {label}", exc)
            return
        if now is None:
            call = f"HapticSculpt.add_curve_constraint({ref(target)}, {code})"
        elif now["continuity"] == "G0":
            call = f"HapticSculpt.add_curve_constraint({ref(target)}, {code}, 'G1', replace={now['id']})"
        else:
            call = f"HapticSculpt.remove_constraint({ref(target)}, {now['id']})"
        try:
            run_echoed(call)
        except Exception as exc:  # noqa: BLE001 - doCommand raises what the call raised, as its own type
            refuse(f"{target.Label} cannot follow {label}", exc)
            return
        sculpt = sculpt_for(target)
        _ctl().refresh(sculpt)  # (the curve drawn on the surface)
        done = sculpt.Proxy.live.last_curve if now is None or now["continuity"] == "G0" else None
        if done is not None and done["refined_to"] != done["refined_from"]:
            # (a finer net is no change the designer sees: said in the report view and the HUD)
            text = (f"refined to {done['refined_to'][0]} x {done['refined_to'][1]} controls to follow {label} within "
                    f"{done['tolerance_mm']:g} mm")
            FreeCAD.Console.PrintMessage(f"HapticSculpt: {target.Label}: {text}\n")
            for overlay in _ctl().overlays_of(sculpt):
                overlay.notice(text)
            _ctl().refresh(sculpt)
        after = constraint_along(target, curve)
        # (the distance now, beside the tolerance it is held to: "within 2.2e-14 mm" beside the
        # HUD's "within 0.001 mm" read as two claims that disagree)
        FreeCAD.Console.PrintMessage(f"HapticSculpt: {target.Label} follows {label} {after['continuity']}: "
                                     f"{after['distance_mm']:.2g} mm from it now (held within "
                                     f"{(sculpt.Proxy.live.last_curve or {}).get('tolerance_mm', 0.001):g} mm)\n" if after else
                                     f"HapticSculpt: {target.Label} no longer follows it\n")


def _target_selection() -> tuple[Any, Any] | None:
    """(the sculpt or sculpted solid, the mesh or point cloud) when the selection is one of each,
    or a mesh or cloud alone with a sculpt under the mouse or alone in the document; else None."""
    from ..app.scan_target import is_target_object
    from ..app.sculpt_feature import is_sculpt
    from ..app.sculpted_solid import is_sculpted_solid
    sel = Gui.Selection.getSelection()
    scans = [o for o in sel if is_target_object(o)]
    sculpts = [o for o in sel if is_sculpt(o) or is_sculpted_solid(o)]
    if len(scans) != 1 or len(sculpts) > 1 or len(scans) + len(sculpts) != len(sel):
        return None
    target = sculpts[0] if sculpts else _ctl().active_sculpt()
    return (target, scans[0]) if target is not None else None


def _with_target() -> Any:
    """The active sculpt if it has a target, else None."""
    sculpt = _ctl().active_sculpt()
    return sculpt if sculpt is not None and getattr(sculpt, "Target", None) is not None else None


class SetTarget:
    """The selected mesh or point cloud (an imported scan) becomes the sculpt's target; the
    deviation display shows at once."""

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": icon("SetTarget"), "MenuText": "Set scan target",
                "ToolTip": "Select a mesh or point cloud (a scan imported with File > Import: STL, OBJ, PLY) and "
                           "the sculpt: the sculpt is measured against it, and the deviation shows in colour"}

    def IsActive(self) -> bool:
        return _target_selection() is not None

    def Activated(self) -> None:
        from ..app.sculpted_solid import sculpt_for
        from .echo import ref, run_echoed
        picked = _target_selection()
        if picked is None:
            return
        sculpt, scan = picked
        try:
            run_echoed(f"HapticSculpt.set_target({ref(sculpt)}, {ref(scan)})")
        except Exception as exc:  # noqa: BLE001 - doCommand raises what the call raised
            FreeCAD.Console.PrintWarning(f"HapticSculpt: {scan.Label} cannot be {sculpt.Label}'s target: {exc}\n")
            return
        Gui.Selection.clearSelection()
        _ctl().refresh(sculpt_for(sculpt))
        _ctl().set_display("deviation")
        report = json.loads(sculpt_for(sculpt).Deviation or "{}")
        if "p95_mm" in report:
            FreeCAD.Console.PrintMessage(f"HapticSculpt: {scan.Label} lies within {report['tolerance_mm']:g} mm of "
                                         f"{sculpt.Label} at {report['within_pct']:.1f} % of its points (p95 "
                                         f"{report['p95_mm']:.3g} mm, max {report['max_mm']:.3g} mm)\n")


class ShowDeviation(_SculptCommand):
    icon_name, menu, needs = "ShowDeviation", "Show deviation", NEEDS_TARGET
    tip = ("Toggle the deviation display: the scan's signed distance from the surface in colour, green within "
           "the tolerance, yellow to red on the normal's side (outside a solid), cyan to blue on the other, grey "
           "where there is no scan; on the scan's points too")

    def IsActive(self) -> bool:
        return _with_target() is not None

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            _ctl().set_display("shading" if ov.display == "deviation" else "deviation")


class FitToTarget(_SculptCommand):
    icon_name, menu = "FitToTarget", "Fit to scan"
    needs = NEEDS_TARGET[:-1] + ", with no session running."
    tip = ("Fit the surface to its scan target within its tolerance (TargetTolerance): outliers and holes are "
           "ignored and bridged, held edges, seams, symmetry and curves kept, the net refined where it must be; "
           "one undo step")

    def IsActive(self) -> bool:
        return _with_target() is not None and _ctl().session is None

    def Activated(self) -> None:
        sculpt = _with_target()
        if sculpt is not None:
            _fit_and_say(sculpt)


def _fit_and_say(sculpt: Any) -> None:
    """Fits the sculpt to its scan (echoed) and says how it went: "fitted" where it met its
    tolerance, else a warning with what kept it short (the held edges: Free edges and fit)."""
    from ..app.sculpted_solid import sculpt_for
    from .echo import ref, run_echoed
    sculpt.Proxy.live.last_fit = None
    run_echoed(f"report = HapticSculpt.fit_to_target({ref(sculpt)}, {float(sculpt.TargetTolerance)!r})")
    _ctl().refresh(sculpt_for(sculpt))
    fit = sculpt.Proxy.live.last_fit or {}
    report = json.loads(sculpt_for(sculpt).Deviation or "{}")
    if "p95_mm" not in report:
        return
    said = (f"{report['within_pct']:.1f} % of the scan within {report['tolerance_mm']:g} mm "
            f"(p95 {report['p95_mm']:.3g} mm)")
    if fit.get("met", True):
        FreeCAD.Console.PrintMessage(f"HapticSculpt: fitted: {said}\n")
    else:
        FreeCAD.Console.PrintWarning(f"HapticSculpt: {sculpt.Label} not fitted to its tolerance: {said}; "
                                     f"{fit.get('message', '')}\n")


class FreeEdgesAndFit(_SculptCommand):
    icon_name, menu = "FreeEdgesAndFit", "Free edges and fit"
    needs = NEEDS_TARGET[:-1] + ", after a fit its held edges kept short, with no session running."
    tip = ("The remedy a fit names when held edges keep part of the scan out of reach: takes that fit back, lets "
           "those edges go (a sheet's free, a solid's held G0 only: still on their neighbours) and fits again, as "
           "the fit's report measured it; one undo step")

    def IsActive(self) -> bool:
        sculpt = _with_target()
        return (sculpt is not None and _ctl().session is None
                and bool((sculpt.Proxy.live.last_fit or {}).get("blocked_by")))

    def Activated(self) -> None:
        from ..app.sculpted_solid import solid_of
        from .echo import ref, run_echoed
        sculpt = _with_target()
        if sculpt is None:
            return
        solid = solid_of(sculpt)
        doc = f"App.getDocument({sculpt.Document.Name!r})"
        blocked = sculpt.Proxy.live.last_fit["blocked_by"]
        if sculpt.Document.UndoNames and sculpt.Document.UndoNames[0] == "Fit to target":
            run_echoed(f"{doc}.undo()", modules=())  # (the fit that fell short: from where it began)
        # one undo step: FreeCAD joins the calls' own steps into the one a command opens
        run_echoed(f"{doc}.openTransaction('Free edges and fit')", modules=())
        try:
            if solid is None:
                run_echoed(f"HapticSculpt.hold_boundary({ref(sculpt)}, 'free')")
            else:
                run_echoed(f"HapticSculpt.set_boundary({ref(solid)}, {dict((e['edge'], 'G0') for e in blocked)!r})")
            _fit_and_say(sculpt)
        finally:
            run_echoed(f"{doc}.commitTransaction()", modules=())


class PullToTarget(_SculptCommand):
    icon_name, menu, needs = "PullToTarget", "Pull toward scan (on/off)", NEEDS_TARGET
    tip = ("Switch the pull toward the scan target on or off: while sculpting (a session or HapticSculpt.run) the "
           "surface is drawn onto the scan where it is near, bridging holes; the Paint pull airbrush takes it away "
           "where it sprays; one undo step")

    def IsActive(self) -> bool:
        return _with_target() is not None

    def Activated(self) -> None:
        from .echo import ref, run_echoed
        sculpt = _with_target()
        if sculpt is None:
            return
        on = not sculpt.Proxy.live.snapshot().pull["enabled"]
        run_echoed(f"HapticSculpt.set_pull({ref(sculpt)}, {on!r})")
        FreeCAD.Console.PrintMessage(f"HapticSculpt: the pull toward {sculpt.Target.Label} is {'on' if on else 'off'}\n")


class _Tool(_SculptCommand):
    tool = "rope"

    def Activated(self) -> None:
        _ctl().set_tool(self.tool)


def _tool_commands() -> dict[str, type]:
    """One command per tool of the core, from what the tool declares (core.TOOL_INFO): its title
    names the command (HapticSculpt_ToolRope) and its icon (Rope.svg), its tip is the tool tip."""
    out = {}
    for name in core.TOOLS:
        info = core.TOOL_INFO[name]
        out[f"HapticSculpt_Tool{info['title']}"] = type(
            f"Tool{info['title']}", (_Tool,),
            {"tool": name, "icon_name": info["title"], "menu": f"{info['title']} tool", "tip": info["tip"]})
    return out


class Falloff(_SculptCommand):
    icon_name, menu = "Falloff", "Falloff"
    tip = (f"Cycle the current tool's falloff ({', '.join(t for t in core.TOOLS if core.TOOL_INFO[t]['falloff'])}): "
           "constant, spherical, cylindrical (about the cursor axis), conical")

    def Activated(self) -> None:
        ctl = _ctl()
        if not core.TOOL_INFO[ctl.tool]["falloff"]:
            with_one = [t for t in core.TOOLS if core.TOOL_INFO[t]["falloff"]]
            FreeCAD.Console.PrintWarning(f"HapticSculpt: the {ctl.tool} tool has no falloff (choose the "
                                         f"{', '.join(with_one)} tool first)\n")
            return
        nxt = core.FALLOFFS[(core.FALLOFFS.index(ctl.falloff) + 1) % len(core.FALLOFFS)]
        ctl.set_tool(ctl.tool, nxt)
        FreeCAD.Console.PrintMessage(f"HapticSculpt: {ctl.tool} falloff {nxt}\n")


class _Constraint(_SculptCommand):
    kind, needs = "point", NEEDS_CURSOR

    def IsActive(self) -> bool:
        return _has_sculpt() and _ctl().cursor() is not None

    def Activated(self) -> None:
        _ctl().toggle_constraint(self.kind)


class PointConstraint(_Constraint):
    kind, icon_name, menu = "point", "PointConstraint", "Point constraint (P)"
    tip = "Toggle a point constraint at the mass point nearest the cursor (key P)"


class NormalConstraint(_Constraint):
    kind, icon_name, menu = "normal", "NormalConstraint", "Normal constraint (N)"
    tip = "Toggle a normal constraint at the mass point nearest the cursor (key N)"


class CurvatureConstraint(_Constraint):
    kind, icon_name, menu = "curvature", "CurvatureConstraint", "Curvature constraint (C)"
    tip = "Toggle a curvature constraint at the mass point nearest the cursor (key C)"


class _Paint(_SculptCommand):
    """Airbrush: switches spraying this map on or off; the left button sprays along the mouse path,
    or during a session the device's button along the device's path (instead of grabbing)."""

    which = "mass"

    def Activated(self) -> None:
        state = _ctl().set_painting(self.which)
        FreeCAD.Console.PrintMessage(f"HapticSculpt: airbrush {'on: ' + state if state else 'off'}\n")


class PaintMass(_Paint):
    which, icon_name, menu = "mass", "PaintMass", "Paint mass"
    tip = "Airbrush on the mass map: hold the left button (or the device's button during a session) and move over the surface"


class PaintDamping(_Paint):
    which, icon_name, menu = "damping", "PaintDamping", "Paint damping"
    tip = "Airbrush on the damping map: hold the left button (or the device's button during a session) and move over the surface"


class PaintStiffness(_Paint):
    which, icon_name, menu = "stiffness", "PaintStiffness", "Paint stiffness"
    tip = "Airbrush on the stiffness map: hold the left button (or the device's button during a session) and move over the surface"


class PaintBending(_Paint):
    which, icon_name, menu = "bending", "PaintBending", "Paint bending"
    tip = ("Airbrush on the bending map (the plate's stiffness over the springs': higher is fairer and stiffer): "
           "hold the left button (or the device's button during a session) and move over the surface")


class PaintPull(_Paint):
    which, icon_name, menu = "pull", "PaintPull", "Paint pull (erase)"
    tip = ("Airbrush on the pull map: takes the pull toward the target away where it sprays (the panel's pull "
           "slider puts it back everywhere); hold the left button (or the device's button during a session)")


class ShowMap(_SculptCommand):
    icon_name, menu = "ShowMap", "Show map (M)"
    tip = "Cycle the material map display in pseudo-colour: mass, damping, stiffness, bending, pull, off (key M toggles)"

    def Activated(self) -> None:
        from .workbench import MAP_CYCLE
        _ctl().cycle(MAP_CYCLE)


class ShowCurvature(_SculptCommand):
    icon_name, menu = "ShowCurvature", "Show curvature"
    tip = "Cycle curvature displays: u green / v blue (as in the paper), mean, Gaussian, off (Displays off: at once)"

    def Activated(self) -> None:
        from .workbench import CURVATURE_CYCLE
        _ctl().cycle(CURVATURE_CYCLE)


class Combs(_SculptCommand):
    icon_name, menu = "Combs", "Curvature combs"
    tip = "Toggle curvature combs along the u and v iso-lines"

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            ov.combs = not ov.combs
            ov.refresh()


class ContinuityCheck(_SculptCommand):
    icon_name, menu = "ContinuityCheck", "Continuity check"
    tip = ("Toggle curvature combs across every edge, seam and followed curve of the sculpt, on both sides, "
           "coloured by what holds there (green G2, yellow G1, orange G0, red: apart); the HUD gives the worst "
           "g0, g1 and g2 over the smooth edges")

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            ov.continuity = not ov.continuity
            ov.refresh()


class CombDensity(_SculptCommand):
    icon_name, menu = "CombDensity", "Combs: density"
    tip = "Cycle how many iso-lines carry a curvature comb: every 2nd, 4th or 8th"

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            ov.comb_every = {2: 4, 4: 8}.get(ov.comb_every, 2)
            ov.combs = True
            ov.refresh()


class CombScale(_SculptCommand):
    icon_name, menu = "CombScale", "Combs: scale"
    tip = "Cycle the combs' length: the longest tooth 0.5, 1 or 2 tenths of the patch size"

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            ov.comb_gain = {0.5: 1.0, 1.0: 2.0}.get(ov.comb_gain, 0.5)
            ov.combs = True
            ov.refresh()


class Zebra(_SculptCommand):
    icon_name, menu = "Zebra", "Zebra stripes"
    tip = "Toggle zebra stripes (reflection lines) for class-A continuity inspection"

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            _ctl().set_display("shading" if ov.display == "zebra" else "zebra")


class DisplaysOff(_SculptCommand):
    icon_name, menu = "DisplaysOff", "Displays off"
    tip = ("Plain shading: turn off the sculpt's display (map, curvature, zebra, deviation), its curvature combs "
           "and its continuity check at once")

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            ov.combs = ov.continuity = False
            _ctl().set_display("shading")
            ov.refresh()


class ZebraMode(_SculptCommand):
    icon_name, menu = "ZebraMode", "Zebra: reflection / isophote"
    tip = ("Switch the zebra stripes between reflection lines (view-dependent: the eye ray mirrored in the "
           "surface) and isophotes (world-fixed: bands of equal angle to the z axis)")

    def Activated(self) -> None:
        from .stripes import MODES
        ov = _ctl().overlay()
        if ov is not None:
            ov.stripe_mode = MODES[(MODES.index(ov.stripe_mode) + 1) % len(MODES)]
            _ctl().set_display("zebra")


class ZebraStripes(_SculptCommand):
    icon_name, menu = "ZebraStripes", "Zebra: stripe count"
    tip = "Cycle the number of zebra stripes over a half turn: 6, 12, 24"

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            ov.stripes = {6.0: 12.0, 12.0: 24.0}.get(ov.stripes, 6.0)
            _ctl().set_display("zebra")


class ZebraDirection(_SculptCommand):
    icon_name, menu = "ZebraDirection", "Zebra: direction"
    tip = ("Turn the zebra stripes: the reflection lines' light strips vertical, horizontal or diagonal on "
           "the screen; the isophotes' direction +Z, +X, +Y or the space diagonal")

    def Activated(self) -> None:
        from .stripes import DIRECTIONS
        ov = _ctl().overlay()
        if ov is not None:
            turns = [(angle, direction) for _, angle, direction in DIRECTIONS]
            now = (ov.stripe_angle, tuple(ov.stripe_direction))
            ov.stripe_angle, ov.stripe_direction = turns[(turns.index(now) + 1) % len(turns)] if now in turns \
                else turns[0]
            _ctl().set_display("zebra")


class Panel(_SculptCommand):
    icon_name, menu = "Panel", "Slider panel"
    tip = "Toggle the slider panel (mass, damping, stiffness, curvature targets) in the view's corner: drag a knob"

    def Activated(self) -> None:
        ov = _ctl().overlay()
        if ov is not None:
            ov.panel_visible = not ov.panel_visible
            ov.refresh()


class Group:
    """A drop-down of commands on a toolbar (FreeCAD's Python group command): the button runs the
    entry picked last (at first the default), its arrow lists every entry."""

    def __init__(self, menu: str, tip: str, commands: list[str], default: int) -> None:
        self.menu, self.tip, self.commands, self.default = menu, tip, tuple(commands), default

    def GetResources(self) -> dict[str, Any]:
        return {"MenuText": self.menu, "ToolTip": self.tip, "DropDownMenu": True, "Exclusive": False}

    def GetCommands(self) -> tuple[str, ...]:
        return self.commands

    def GetDefaultCommand(self) -> int:
        return self.default

    def IsActive(self) -> bool:
        """FreeCAD enables a group's entries together: while any of them can run."""
        return any(COMMANDS[name]().IsActive() for name in self.commands)


def refuse(what: str, exc: BaseException) -> None:
    """A refusal as a designer reads it (see workbench.refuse)."""
    from .workbench import refuse as say
    say(what, exc)


def _refusals_said_plainly(command: type) -> type:
    """``command`` whose Activated reports what the scripting API refused (ValueError, TypeError,
    RuntimeError: the API's refusals, each saying why) through :func:`refuse`; anything else is a
    bug and still shows as one."""
    activated = getattr(command, "Activated", None)
    if activated is None or getattr(activated, "said_plainly", False):
        return command

    def run(self: Any) -> None:
        try:
            activated(self)
        except (ValueError, TypeError, RuntimeError) as exc:
            refuse(self.GetResources()["MenuText"], exc)
    run.__doc__, run.said_plainly = activated.__doc__, True  # type: ignore[attr-defined]
    command.Activated = run
    return command


COMMANDS = {"HapticSculpt_NewPatch": NewPatch, "HapticSculpt_NewClampedPatch": NewClampedPatch,
            "HapticSculpt_NewFromCurves": NewFromCurves,
            "HapticSculpt_SculptFace": SculptFace, "HapticSculpt_Session": Session,
            "HapticSculpt_Material": Material, "HapticSculpt_KeepShape": KeepShape,
            "HapticSculpt_HoldEdges": HoldEdges, "HapticSculpt_FollowCurve": FollowCurve, "HapticSculpt_Fair": Fair,
            **_tool_commands(), "HapticSculpt_Falloff": Falloff, "HapticSculpt_PointConstraint": PointConstraint,
            "HapticSculpt_NormalConstraint": NormalConstraint, "HapticSculpt_CurvatureConstraint": CurvatureConstraint,
            "HapticSculpt_PaintMass": PaintMass, "HapticSculpt_PaintDamping": PaintDamping,
            "HapticSculpt_PaintStiffness": PaintStiffness, "HapticSculpt_PaintBending": PaintBending,
            "HapticSculpt_PaintPull": PaintPull,
            "HapticSculpt_ShowMap": ShowMap, "HapticSculpt_SetTarget": SetTarget,
            "HapticSculpt_ShowDeviation": ShowDeviation, "HapticSculpt_FitToTarget": FitToTarget,
            "HapticSculpt_FreeEdgesAndFit": FreeEdgesAndFit,
            "HapticSculpt_PullToTarget": PullToTarget,
            "HapticSculpt_ShowCurvature": ShowCurvature, "HapticSculpt_Combs": Combs, "HapticSculpt_ContinuityCheck": ContinuityCheck, "HapticSculpt_Zebra": Zebra, "HapticSculpt_DisplaysOff": DisplaysOff,
            "HapticSculpt_ZebraMode": ZebraMode, "HapticSculpt_ZebraStripes": ZebraStripes,
            "HapticSculpt_ZebraDirection": ZebraDirection,
            "HapticSculpt_CombDensity": CombDensity, "HapticSculpt_CombScale": CombScale,
            "HapticSculpt_Panel": Panel, "HapticSculpt_Thicken": Thicken, "HapticSculpt_ExportStep": ExportStep}
COMMANDS = {name: _refusals_said_plainly(command) for name, command in COMMANDS.items()}
