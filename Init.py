# HapticSculpt console-mode start-up: FreeCAD exec()s this file (no __file__), also in freecadcmd.
# No GUI imports here; only register the tests so `freecadcmd -t TestHapticSculpt` (or -t 0) finds them.
import FreeCAD

FreeCAD.__unit_test__ += ["TestHapticSculpt"]
