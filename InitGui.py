# TopOpt workbench, GUI part: only FreeCAD with its GUI runs this file.
import os

import FreeCAD
import FreeCADGui


class TopOptWorkbench(FreeCADGui.Workbench):
    MenuText = "Topology Optimization"
    ToolTip = "Topology optimisation: design and non-design solids, supports, loads, SIMP"

    def __init__(self):
        import topopt
        self.__class__.Icon = os.path.join(topopt.resources_dir(), "icons", "TopOptWorkbench.svg")

    def Initialize(self):
        import topopt.gui.commands as commands
        names = commands.register()
        self.appendToolbar("Topology Optimization", names)
        self.appendMenu("&Topology Optimization", names)

    def GetClassName(self):
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(TopOptWorkbench())
