"""The SculptedSolid document object: a ``Part::FeaturePython`` whose Shape is a solid (its Base)
with some of its faces replaced by their sculpted surfaces, bounded by the faces' own wires and
sewn back into one closed solid.

The sculpting itself is a Sculpt object (see :mod:`sculpt_feature`), hidden, made from the face
in its exact B-spline form with the poles that hold its edges fixed (see :mod:`face_in_solid`);
everything that works on a Sculpt (sessions, strokes, constraints, Undo) works on it. Each time
the sculpt's geometry is written, the solid rebuilds in the same transaction, so one Undo restores
both; a recompute (the Base changed, a file was opened) rebuilds it too. All state is in the
properties: the base link, the face names, the boundary per edge (JSON), the seam report (JSON).
"""
from __future__ import annotations

import json
from typing import Any

from . import face_in_solid
from .face_chain import FaceChain, single
from .sculpt_properties import read_state, surface_of
from .tagged_proxy import TaggedProxy
from .view_provider_hook import ViewProviderHook

TYPE = "HapticSculpt::SculptedSolid"
GROUP = "SculptedSolid"
#: What gives a new SculptedSolid its view provider while the GUI runs (installed by HapticSculpt.gui).
_VIEW_PROVIDER = ViewProviderHook()
set_view_provider = _VIEW_PROVIDER.install
attach_view_provider = _VIEW_PROVIDER.attach


def ensure_properties(obj: Any) -> None:
    """The properties of a SculptedSolid (older files gain the ones they lack)."""
    for kind, name, doc, mode in (
            ("App::PropertyLink", "Base", "The solid whose faces are sculpted", 0),
            ("App::PropertyStringList", "SculptFaces", "The faces of the base that are sculpted (FaceN)", 1),
            ("App::PropertyString", "Boundary", "How each edge of those faces is held: free, G0, G1, G2 or G3 (JSON)", 1),
            ("App::PropertyLinkList", "Sculpts", "The sculpts of those faces (hidden)", 1),
            ("App::PropertyString", "SeamReport", "Per edge: the largest gap (mm), for G1 edges the largest "
                                                  "normal angle (degrees) between the sculpted face and the seam, and "
                                                  "the largest jump of the normal curvature across it (g2_pct: percent "
                                                  "of the larger |curvature| of the two sides) (JSON)", 1),
            ("App::PropertyString", "RebuildError", "Why the solid could not be rebuilt (empty when it could)", 1),
            ("App::PropertyString", "Symmetry", "The mirror plane the sculpt stays symmetric in: null, or its point, "
                                                "normal and the parameter direction it reverses (JSON)", 1),
            ("App::PropertyString", "Layout", "Where each sculpted face sits in the one surface they are sculpted "
                                              "as, and the seams between them (JSON; empty for one face)", 2),
            ("App::PropertyString", "Resolution", "The least net the faces were converted to (JSON)", 2),
            ("App::PropertyFloatList", "SourcePoles", "The poles of the face the sculpt was made from (the base "
                                                     "changed: the sculpt follows it)", 2)):
        if name not in obj.PropertiesList:
            obj.addProperty(kind, name, GROUP, doc)
        obj.setEditorMode(name, mode)


class SculptedSolidFeature(TaggedProxy):
    """Proxy of a SculptedSolid object; no state of its own (see the module docstring)."""

    TYPE = TYPE

    def __init__(self, obj: Any) -> None:
        self.Type = TYPE
        self._preview = (-1.0, 0.0)  # (when the last session preview was drawn, what it cost): not saved
        ensure_properties(obj)
        obj.Proxy = self

    def execute(self, obj: Any) -> None:
        """Recompute: the sculpt follows the base if its face changed, then the solid from the base
        and the sculpt (raises, marking the object, if it cannot be rebuilt)."""
        from .follow_base import follow_base
        try:
            follow_base(obj, base_solid(obj.Base))
        except (RuntimeError, ValueError) as exc:
            obj.RebuildError = f"the sculpt cannot follow the changed base: {exc}"
            raise
        rebuild(obj)

    def sculpt_changed(self, obj: Any) -> None:
        """A sculpt's geometry was written (a stroke, Undo's counterpart, an edit): rebuild now, in
        the same transaction. A solid that cannot be rebuilt keeps its last shape and says why in
        ``RebuildError`` (the stroke itself is kept)."""
        try:
            rebuild(obj)
        except (RuntimeError, ValueError) as exc:
            import FreeCAD
            FreeCAD.Console.PrintError(f"HapticSculpt: {obj.Label}: {exc}\n")

    def sculpt_frame(self, obj: Any, frame: Any) -> None:
        """A session's frame (GUI): show the solid's faces with the sculpted ones from the frame,
        as a compound, not sewn and not stored (the commit at the stroke's end rebuilds the solid).
        A preview costs 12-28 ms (see :func:`frame_preview.show_frame`)."""
        from .frame_preview import show_frame
        show_frame(self, obj, lambda: preview(obj, frame))

    def onDocumentRestored(self, obj: Any) -> None:
        """Opening a file: add properties older files lack; a file saved while a session ran holds
        that session's preview (faces, not a solid): it is rebuilt from the stored sculpt."""
        ensure_properties(obj)
        if obj.Sculpts and obj.Base is not None and len(obj.Shape.Solids) != 1:
            try:
                rebuild(obj)
            except (RuntimeError, ValueError) as exc:
                import FreeCAD
                FreeCAD.Console.PrintError(f"HapticSculpt: {obj.Label}: {exc}\n")


def is_sculpted_solid(obj: Any) -> bool:
    """True for a SculptedSolid document object."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TYPE


def sculpt_of(obj: Any) -> Any:
    """The Sculpt a SculptedSolid sculpts its faces with."""
    if not obj.Sculpts:
        raise ValueError(f"{obj.Label} has no sculpt")
    return obj.Sculpts[0]


def sculpt_for(obj: Any) -> Any:
    """The Sculpt to sculpt when ``obj`` is picked: itself, a SculptedSolid's sculpt, a Thickness's
    (the object a designer sees and selects: its sculpt is hidden behind it), or None."""
    from .sculpt_feature import is_sculpt
    from .thickness import is_thickness
    if is_sculpt(obj):
        return obj
    if is_sculpted_solid(obj) and obj.Sculpts:
        return obj.Sculpts[0]
    if is_thickness(obj) and obj.Source is not None:
        return sculpt_for(obj.Source)
    return None


def solid_of(sculpt: Any) -> Any:
    """The SculptedSolid that sculpts its faces with ``sculpt``, or None."""
    return next((o for o in getattr(sculpt, "InList", []) if is_sculpted_solid(o)), None)


def chain_of_solid(obj: Any, shape: Any = None) -> Any:
    """The FaceChain of a SculptedSolid's faces (one face: placed as it is)."""
    if getattr(obj, "Layout", ""):
        return FaceChain.loads(obj.Layout)
    return single(base_solid(obj.Base) if shape is None else shape, obj.SculptFaces[0])


def trim_mask(sculpt: Any, us: Any, vs: Any) -> Any:
    """Which points of the (us x vs) parameter grid lie on the faces ``sculpt`` sculpts in its
    solid (inside their outer wires, outside their holes): a (len(us), len(vs)) bool array; None
    for a sculpt that is not part of a SculptedSolid (all of its domain is the face)."""
    import numpy as np
    solid = solid_of(sculpt)
    if solid is None or solid.Base is None:
        return None
    shape = solid.Base.Shape
    return chain_of_solid(solid, shape).on_faces(shape, np.asarray(us, float), np.asarray(vs, float))


def boundary_of(obj: Any) -> dict[str, str]:
    """How each edge of the sculpted faces is held ({"EdgeN": "free" | "G0" | "G1" | "G2" | "G3"})."""
    return json.loads(obj.Boundary) if obj.Boundary else {}


def held_by_kind(kinds: dict[str, str]) -> str:
    """Edges grouped by how they are held, strongest first: "G1 Edge2, Edge5; G0 Edge1"."""
    groups = []
    for kind in ("G3", "G2", "G1", "G0", "free"):
        names = sorted((e for e, k in kinds.items() if k == kind), key=lambda e: int(e[4:]))
        if names:
            groups.append(f"{kind} {', '.join(names)}")
    return "; ".join(groups)


def seam_report_of(obj: Any) -> list[dict[str, Any]]:
    """The parsed ``SeamReport``."""
    return json.loads(obj.SeamReport) if obj.SeamReport else []


def base_solid(base: Any) -> Any:
    """The one valid closed solid of ``base``'s Shape (ValueError saying what it is instead)."""
    shape = getattr(base, "Shape", None)
    if shape is None or shape.isNull():
        raise ValueError(f"{getattr(base, 'Label', base)} has no shape")
    if len(shape.Solids) != 1:
        raise ValueError(f"{base.Label} has {len(shape.Solids)} solids, not one")
    if not shape.isValid() or not all(s.isClosed() for s in shape.Solids[0].Shells):
        raise ValueError(f"{base.Label} is not a valid closed solid")
    return shape


def sculpted_surface(sculpt: Any, state: Any = None) -> Any:
    """The Part.BSplineSurface of a Sculpt's stored state (or of ``state``, a SculptState)."""
    return surface_of(read_state(sculpt) if state is None else state)


def _pieces(obj: Any, shape: Any, state: Any = None) -> tuple[Any, dict[str, Any]]:
    """The chain and each sculpted face's surface in its own parameters."""
    chain = chain_of_solid(obj, shape)
    return chain, chain.split(sculpted_surface(sculpt_of(obj), state))


def preview(obj: Any, frame: Any) -> Any:
    """The base's faces with the sculpted ones from ``frame`` (a SculptState), as a compound."""
    import Part
    shape = base_solid(obj.Base)
    chain, pieces = _pieces(obj, shape, frame)
    new = {f: face_in_solid.trimmed_face(pieces[f], face_in_solid.nurbs_face(shape.getElement(f))) for f in pieces}
    kept = [f for k, f in enumerate(shape.Faces) if f"Face{k + 1}" not in new]
    return Part.Compound(kept + list(new.values()))


def rebuild(obj: Any) -> None:
    """Sets the Shape (the base with the sculpted faces in) and the SeamReport; RuntimeError or
    ValueError (recorded in ``RebuildError``) when the solid cannot be made."""
    try:
        if obj.Base is None:
            raise ValueError("no base solid")
        shape = base_solid(obj.Base)
        kinds = boundary_of(obj)
        for face_name in obj.SculptFaces:
            try:
                shape.getElement(face_name)
            except Exception as exc:  # noqa: BLE001 - FreeCAD raises several types for a missing element
                raise ValueError(f"{obj.Base.Label} has no {face_name} any more") from exc
        chain, pieces = _pieces(obj, shape)
        seams = frozenset(chain.seam_edges())
        replaced, report = {}, []
        for face_name in chain.faces:
            nface = face_in_solid.nurbs_face(shape.getElement(face_name))
            replaced[face_name] = face_in_solid.trimmed_face(pieces[face_name], nface)
            report += face_in_solid.seam_report(pieces[face_name], shape, face_name, kinds, seams)
        for seam in chain.seams:
            report.append(face_in_solid.seam_between(pieces, shape, seam.faces, seam.edge, kinds.get(seam.edge, "G0")))
        report.sort(key=lambda r: int(r["edge"][4:]))
        solid = face_in_solid.solid_with(shape, replaced)
    except (RuntimeError, ValueError) as exc:
        if obj.RebuildError != str(exc):
            obj.RebuildError = str(exc)
        raise
    obj.Shape = solid
    text = json.dumps(report)
    if obj.SeamReport != text:
        obj.SeamReport = text
    if obj.RebuildError:
        obj.RebuildError = ""
