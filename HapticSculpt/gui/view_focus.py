"""The keyboard follows the pointer into a 3D view (GUI only).

Coin sees keys only while the view's widget has the keyboard focus, and FreeCAD leaves it wherever
it was last given: after the Python console was used, P typed a "p" there and ctrl+z undid the
console's text. While the workbench is active, a mouse move over a 3D view gives that view the
keyboard, as a click in it would, unless a task dialog is open (its fields keep what is typed),
another window is active (a dialog) or a field is being typed in (a name in the tree, a value in
the property editor: its letters P, N, C and M went to the view as constraints). The view keeps the
keyboard when the pointer leaves it (FreeCAD's own keys still work there), so the workbench's keys
act only while the pointer is over the view: over the model tree, P took away a pin out of sight.
The widgets are FreeCAD's own, reached through its main window object: no Qt module is imported.
"""
from __future__ import annotations

#: Widgets a person types a value into; they keep the keyboard. The Python console (a text edit
#: too, but a pane that stays open) gives it up: the view's keys were meant for the view.
FIELDS = ("QLineEdit", "QAbstractSpinBox")


def give_keyboard_to_view(view) -> None:
    """Focus to the widget of ``view``, a 3D view the pointer moves over (called from its mouse
    moves). The view's own widget, not the widget under the pointer: FreeCAD 1.1 lays its Tasks panel
    over the 3D view (an overlay that lets the mouse through to the view), and the widget under the
    pointer there is the panel, which took the keys meant for the view."""
    import FreeCADGui as Gui
    main = Gui.getMainWindow()
    if main is None or not main.isActiveWindow() or Gui.Control.activeDialog():
        return
    focus = main.focusWidget()
    if focus is not None and any(focus.inherits(kind) for kind in FIELDS):
        return
    widget = view.graphicsView()
    if widget is not None and not widget.hasFocus():
        widget.setFocus()


def pointer_over(view) -> bool:
    """Whether the pointer is inside ``view`` (or over a panel FreeCAD lays over it). From where
    the view finds the pointer, not from the widget's under-mouse flag, which FreeCAD 1.1's view
    (Qt6) never set."""
    x, y = view.getCursorPos()
    w, h = view.getSize()
    return 0 <= x < w and 0 <= y < h
