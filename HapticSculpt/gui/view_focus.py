"""The keyboard follows the pointer into a 3D view (GUI only).

Coin sees keys only while the view's widget has the keyboard focus, and FreeCAD leaves it wherever
it was last given: after the Python console was used, P typed a "p" there and ctrl+z undid the
console's text. While the workbench is active, a mouse move over a 3D view gives that view the
keyboard, as a click in it would, unless a task dialog is open (its fields keep what is typed) or
another window is active (a dialog). The widgets are FreeCAD's own, reached through its main window
object: no Qt module is imported.
"""
from __future__ import annotations


def give_keyboard_to_view_under_pointer() -> None:
    """Focus to the widget under the pointer (a 3D view's: called from its mouse moves)."""
    import FreeCADGui as Gui
    main = Gui.getMainWindow()
    if main is None or not main.isActiveWindow() or Gui.Control.activeDialog():
        return
    widget = main.childAt(main.mapFromGlobal(main.cursor().pos()))
    if widget is not None and not widget.hasFocus():
        widget.setFocus()
