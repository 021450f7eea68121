# TopOpt workbench, GUI part: only FreeCAD with its GUI runs this file (with exec(), after
# Init.py has put the package `topopt` on sys.path). Methods import what they use: names
# defined at the top of this file are not visible inside them under exec().
import FreeCADGui


class TopOptWorkbench(FreeCADGui.Workbench):
    MenuText = "Topology Optimization"
    ToolTip = "Topology optimisation: design and non-design solids, supports, loads, SIMP"

    def __init__(self):
        import os

        import topopt
        self.__class__.Icon = os.path.join(topopt.resources_dir(), "icons", "TopOptWorkbench.svg")

    def Initialize(self):
        import topopt.gui.commands as commands
        commands.register()
        for title, names in commands.TOOLBARS:
            self.appendToolbar(title, names)
        self.appendMenu("&Topology Optimization", commands.MENU)

    def Activated(self):
        """The first activation in a session says, in one dialog, if the native core is missing
        and how to build it."""
        if not getattr(self, "core_checked", False):
            import topopt.gui.commands as commands
            commands.tell_if_core_missing()
            self.core_checked = True

    def GetClassName(self):
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(TopOptWorkbench())
