# HapticSculpt workbench (GUI start-up). At start-up only the package and its GUI layer's hooks
# load (so sculpts made or opened from a script show as they should); commands, overlay and input
# load when the workbench is activated. No Qt/PySide import anywhere in the project.
import FreeCADGui as Gui


class HapticSculptWorkbench(Gui.Workbench):
    """Sculpt dynamic B-spline surfaces with a haptic device, a SpaceMouse or the mouse."""

    MenuText = "HapticSculpt"
    ToolTip = "Sculpt physics-based B-spline surfaces; results are Part.BSplineSurface faces"

    def __init__(self):
        import importlib.util
        import os

        import FreeCAD
        package = os.path.dirname(importlib.util.find_spec("HapticSculpt").origin)
        self.__class__.Icon = os.path.join(package, "resources", "icons", "HapticSculpt.svg")
        # Edit > Preferences > HapticSculpt (a Designer file: FreeCAD builds its widgets; no Qt here)
        Gui.addPreferencePage(os.path.join(package, "resources", "ui", "preferences.ui"), "HapticSculpt")
        try:  # the group's icon, looked up by that name (FreeCAD 1.1 refuses an SVG path here: no icon)
            Gui.addIcon("preferences-hapticsculpt", self.__class__.Icon)
        except Exception:  # noqa: BLE001 - FreeCAD raises its own error type
            pass
        try:
            import HapticSculpt.gui  # noqa: F401  (its hooks: view providers, frame clock, stroke echo)
        except ImportError as exc:  # no native core: say what to do; the workbench stays listed
            FreeCAD.Console.PrintError(f"HapticSculpt: {exc}\n")
        else:
            FreeCAD.Console.PrintLog(f"HapticSculpt: native core: {HapticSculpt.core.NATIVE_ORIGIN}\n")

    def Initialize(self):
        import HapticSculptGui
        from HapticSculpt.gui import commands
        HapticSculptGui.register()
        for name, buttons in commands.TOOLBARS.items():
            self.appendToolbar(name, buttons)
        self.appendMenu("HapticSculpt", commands.MENU)

    def Activated(self):
        from HapticSculpt.gui.workbench import controller
        controller().activate()  # the mouse and the keys P, N, C, M in every 3D view, now and later

    def Deactivated(self):
        import HapticSculpt
        from HapticSculpt.gui.workbench import controller
        controller().shutdown()
        HapticSculpt.stop_all()  # leaving the workbench ends every sculpting session

    def GetClassName(self):
        return "Gui::PythonWorkbench"


Gui.addWorkbench(HapticSculptWorkbench())
