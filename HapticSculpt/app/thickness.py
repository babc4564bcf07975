"""The Thickness document object: a ``Part::FeaturePython`` whose Shape is a sculpt's face offset
by its ``Thickness`` along the face's normal, the gap closed into one solid (OCCT's offset with
fill, as Part's Offset with Fill does).

It is parametric: it links its Source sculpt, so it recomputes after each stroke (the sculpt's
commit recomputes what is built on it, see :func:`live_surface.recompute_dependents`) and when its
Thickness is edited. All state is in its two properties.
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
        source = obj.Source
        if source is None or not getattr(source, "Shape", None) or not source.Shape.Faces:
            raise ValueError(f"{obj.Label}: its Source has no face to thicken")
        obj.Shape = thickened(source.Shape.Faces[0], float(obj.Thickness.Value))

    def onDocumentRestored(self, obj: Any) -> None:
        ensure_properties(obj)


def is_thickness(obj: Any) -> bool:
    """True for a Thickness document object."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TYPE
