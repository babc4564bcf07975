"""Puts the checkout and Debian's FreeCAD library on sys.path for plain pytest runs."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)
FREECAD_LIB = "/usr/lib/freecad-python3/lib"
if os.path.isdir(FREECAD_LIB) and FREECAD_LIB not in sys.path:
    sys.path.append(FREECAD_LIB)
TESTS = os.path.dirname(os.path.abspath(__file__))
if TESTS not in sys.path:
    sys.path.insert(0, TESTS)  # freecad_support
