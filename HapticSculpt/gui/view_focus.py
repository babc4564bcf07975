"""The keyboard follows the pointer into a 3D view (GUI only).

Coin sees keys only while the view's widget has the keyboard focus, and FreeCAD leaves it wherever
it was last given: after the Python console was used, P typed a "p" there and ctrl+z undid the
console's text. While the workbench is active, a mouse move over a 3D view gives that view the
keyboard, as a click in it would, unless a task dialog is open (its fields keep what is typed) or
another window is active (a dialog). The widgets are FreeCAD's own, reached through its main window
object: no Qt module is imported.
"""
from __future__ import annotations


def give_keyboard_to_view(view) -> None:
    """Focus to the widget of ``view``, a 3D view the pointer moves over (called from its mouse
    moves). The view's own widget, not the widget under the pointer: FreeCAD 1.1 lays its Tasks panel
    over the 3D view (an overlay that lets the mouse through to the view), and the widget under the
    pointer there is the panel, which took the keys meant for the view."""
    import FreeCADGui as Gui
    main = Gui.getMainWindow()
    if main is None or not main.isActiveWindow() or Gui.Control.activeDialog():
        return
    widget = view.graphicsView()
    if widget is not None and not widget.hasFocus():
        widget.setFocus()
