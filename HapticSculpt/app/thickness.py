"""The Thickness document object: a ``Part::FeaturePython`` whose Shape is a sculpt's face offset
by its ``Thickness`` along the face's normal, the gap closed into one solid (OCCT's offset with
fill, as Part's Offset with Fill does).

It is parametric: it links its Source sculpt, so it is thickened again after each stroke, in the
stroke's undo step (the sculpt's commit tells what is built on it, see
:func:`live_surface.notify_dependents`), shows a session's held stroke as it goes, and recomputes
when its Thickness is edited. All state is in its two properties.
"""
from __future__ import annotations

import math
from typing import Any

from .tagged_proxy import TaggedProxy
from .view_provider_hook import ViewProviderHook

TYPE = "HapticSculpt::Thickness"
GROUP = "Thickness"
#: Offsets closer than this (mm) are one surface for OCCT.
TOLERANCE = 1e-6
#: What gives a new Thickness its view provider while the GUI runs (installed by HapticSculpt.gui).
_VIEW_PROVIDER = ViewProviderHook()
set_view_provider = _VIEW_PROVIDER.install
attach_view_provider = _VIEW_PROVIDER.attach


def ensure_properties(obj: Any) -> None:
    """The properties of a Thickness (older files gain the ones they lack)."""
    for kind, name, doc in (("App::PropertyLink", "Source", "The sculpt whose face is thickened"),
                            ("App::PropertyLength", "Thickness", "How far the face is offset along its normal")):
        if name not in obj.PropertiesList:
            obj.addProperty(kind, name, GROUP, doc)


def thickened(face: Any, thickness: float, tolerance: float = TOLERANCE) -> Any:
    """The one valid solid between ``face`` and its offset by ``thickness`` (mm; negative: to the
    other side); ValueError saying why when there is none (zero, or an offset larger than the
    face's radius of curvature, say)."""
    if not (math.isfinite(thickness) and thickness != 0):
        raise ValueError(f"thickness: must be finite and non-zero, got {thickness}")
    try:
        shape = face.makeOffsetShape(thickness, tolerance, fill=True)
    except Exception as exc:  # noqa: BLE001 - OCCT raises Part.OCCError and others
        raise ValueError(f"thickness: OCCT could not offset the face by {thickness} mm ({exc})") from exc
    solids = shape.Solids
    if len(solids) != 1 or not solids[0].isValid():
        raise ValueError(f"thickness: offsetting by {thickness} mm does not give one valid solid")
    return solids[0]


class ThicknessFeature(TaggedProxy):
    """Proxy of a Thickness object; no state of its own (see the module docstring)."""

    TYPE = TYPE

    def __init__(self, obj: Any) -> None:
        self.Type = TYPE
        ensure_properties(obj)
        obj.Proxy = self

    def execute(self, obj: Any) -> None:
        """Recompute: the Source's face thickened (raises, marking the object, when it cannot be)."""
        obj.Shape = self._solid(obj)

    def sculpt_changed(self, obj: Any) -> None:
        """Its sculpt's geometry was written (a stroke, an edit, the end of a session's preview):
        thickened again now, in the same transaction. One that cannot be keeps its last shape and
        says why in the report view (the stroke itself is kept)."""
        try:
            obj.Shape = self._solid(obj)
        except ValueError as exc:
            import FreeCAD
            FreeCAD.Console.PrintError(f"HapticSculpt: {obj.Label}: {exc}\n")

    def sculpt_frame(self, obj: Any, frame: Any) -> None:
        """A session's frame while a stroke is held (GUI): the frame's face thickened, not stored
        (the sculpt is hidden behind its thickness: a drag showed only the rope until let go). It
        costs about 7 ms (see :func:`frame_preview.show_frame`)."""
        from .frame_preview import show_frame
        from .sculpt_properties import face_of
        show_frame(self, obj, lambda: thickened(face_of(frame), float(obj.Thickness.Value)))

    @staticmethod
    def _solid(obj: Any) -> Any:
        source = obj.Source
        if source is None or not getattr(source, "Shape", None) or not source.Shape.Faces:
            raise ValueError(f"{obj.Label}: its Source has no face to thicken")
        return thickened(source.Shape.Faces[0], float(obj.Thickness.Value))

    def onDocumentRestored(self, obj: Any) -> None:
        ensure_properties(obj)


def is_thickness(obj: Any) -> bool:
    """True for a Thickness document object."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TYPE
