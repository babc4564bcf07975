"""Registers the workbench's commands with FreeCAD (called from InitGui).

FreeCAD names the module that registers a command after the file the registration is in, and a
recorded macro imports that module before the command's scripting calls. So the registration lives
in this top-level module of the addon folder (on FreeCAD's module path in the GUI and in console
mode, as FreeCAD's own ``PartGui`` and the like are), and importing it has no effect by itself: a
recorded macro replays in ``freecadcmd``."""


def register() -> None:
    """Adds every HapticSculpt command and drop-down group to FreeCAD (once, from the workbench's Initialize)."""
    import FreeCADGui as Gui

    from HapticSculpt.gui import commands
    for name, cls in commands.COMMANDS.items():
        Gui.addCommand(name, cls())
    for name, group in commands.GROUPS.items():  # (after their commands: a group reads theirs)
        Gui.addCommand(name, commands.Group(*group))
