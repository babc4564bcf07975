"""The document layer: sculpt state in document properties, the Sculpt feature and its live
surface, conversion of Part faces, curvature analysis and the scripting API. It imports no GUI
and no runtime module; FreeCAD only inside the functions that need it."""
