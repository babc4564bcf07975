"""HapticSculpt: sculpt dynamic B-spline surfaces in FreeCAD (Dachille, Qin, Kaufman, El-Sana).

The dynamics core is :mod:`HapticSculpt.core`; importing this package never imports FreeCAD or a GUI.
"""
__version__ = "0.1.0"
