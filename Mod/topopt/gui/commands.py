"""Workbench commands."""
import FreeCAD
import FreeCADGui

import topopt


class _InfoCommand:
    """Check the selected part and non-design solids and print the classification."""

    def GetResources(self):
        return {"MenuText": "Check inputs",
                "ToolTip": "Check the selected part (first) and non-design solids (the rest)",
                "Pixmap": topopt.resources_dir() + "/icons/TopOptWorkbench.svg"}

    def IsActive(self):
        return len(FreeCADGui.Selection.getSelection()) >= 1

    def Activated(self):
        from topopt.app import api
        sel = [o for o in FreeCADGui.Selection.getSelection() if hasattr(o, "Shape")]
        if not sel:
            FreeCAD.Console.PrintError("TopOpt: select the part first, then the non-design solids\n")
            return
        try:
            report = api.info(sel[0].Shape, [o.Shape for o in sel[1:]] or None)
        except api.TopOptError as e:
            FreeCAD.Console.PrintError("TopOpt: %s\n" % e)
            return
        FreeCAD.Console.PrintMessage("TopOpt: part with %d faces, %d non-design solids\n"
                                     % (report["part"]["faces"], len(report["nondesign"]["solids"])))


def register():
    """Registers the commands; returns their names for the toolbar and menu."""
    FreeCADGui.addCommand("TopOpt_CheckInputs", _InfoCommand())
    return ["TopOpt_CheckInputs"]
