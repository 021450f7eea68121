"""Workbench commands. Each one checks its preconditions and reports problems in the
report view; none may raise into FreeCAD."""
import FreeCAD
import FreeCADGui

import topopt
from topopt.app import api
from topopt.app.errors import TopOptError
from topopt.app.study import is_study


def _icon(name):
    return topopt.resources_dir() + "/icons/" + name


def active_study():
    """The selected study, or the only study of the active document."""
    doc = FreeCAD.ActiveDocument
    if doc is None:
        return None
    for obj in FreeCADGui.Selection.getSelection():
        if is_study(obj):
            return obj
    studies = [o for o in doc.Objects if is_study(o)]
    return studies[0] if len(studies) == 1 else None


def _guarded(f):
    def wrapper(*args):
        try:
            return f(*args)
        except TopOptError as e:
            from topopt.gui.panels import report_error
            report_error(e)
        except Exception as e:  # a command must never take FreeCAD down
            FreeCAD.Console.PrintError("TopOpt: unexpected error: %s\n" % e)
    return wrapper


class NewStudy:
    def GetResources(self):
        return {"MenuText": "New study", "Pixmap": _icon("TopOptStudy.svg"),
                "ToolTip": "Select the part first, then the non-design solids to keep, and create a study"}

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and bool(FreeCADGui.Selection.getSelection())

    @_guarded
    def Activated(self):
        sel = [o for o in FreeCADGui.Selection.getSelection() if hasattr(o, "Shape")]
        if not sel:
            raise TopOptError("select the part (a solid) first, then any non-design solids")
        from topopt.gui.waiting import WaitDialog
        with WaitDialog("Checking the shapes") as wait:  # checks, with clear errors
            api.info(sel[0].Shape, [o.Shape for o in sel[1:]] or None, cancel=wait.cancel)
        FreeCAD.ActiveDocument.openTransaction("New TopOpt study")
        study = api.new_study(FreeCAD.ActiveDocument, sel[0], sel[1:])
        FreeCAD.ActiveDocument.commitTransaction()
        FreeCAD.ActiveDocument.recompute()
        from topopt.gui.panels import open_study_panel
        open_study_panel(study)


class _AddConstraint:
    """Creates a constraint on the selected faces of the study's part or non-design solids, then
    opens FreeCAD FEM's own task panel for it (so users keep their habits)."""
    menu, tip, icon, maker = "", "", "", None

    def GetResources(self):
        return {"MenuText": self.menu, "ToolTip": self.tip, "Pixmap": self.icon}

    def IsActive(self):
        return active_study() is not None

    @_guarded
    def Activated(self):
        study = active_study()
        refs = [(s.Object, tuple(n for n in s.SubElementNames if n.startswith("Face")))
                for s in FreeCADGui.Selection.getSelectionEx()]
        refs = [r for r in refs if r[1]]
        doc = study.Document
        doc.openTransaction(self.menu)
        c = self.make(study)
        if refs:
            c.References = refs
        study.Constraints = list(study.Constraints) + [c]
        doc.commitTransaction()
        doc.recompute()
        FreeCADGui.ActiveDocument.setEdit(c.Name)


class AddFixed(_AddConstraint):
    menu, tip = "Fixed support", "Fix the selected faces"
    icon = _icon("TopOptFixed.svg")

    def make(self, study):
        import ObjectsFem
        return ObjectsFem.makeConstraintFixed(study.Document, "Fixed")


class AddForce(_AddConstraint):
    menu, tip = "Force", "A total force on the selected faces"
    icon = _icon("TopOptForce.svg")

    def make(self, study):
        import ObjectsFem
        return ObjectsFem.makeConstraintForce(study.Document, "Force")


class AddPressure(_AddConstraint):
    menu, tip = "Pressure", "A pressure on the selected faces"
    icon = _icon("TopOptPressure.svg")

    def make(self, study):
        import ObjectsFem
        return ObjectsFem.makeConstraintPressure(study.Document, "Pressure")


class AddSymmetry(_AddConstraint):
    menu, tip = "Symmetry plane", "The selected planar faces lie on a symmetry plane"
    icon = _icon("TopOptSymmetry.svg")

    def make(self, study):
        from topopt.app.symmetry import make_symmetry_plane
        return make_symmetry_plane(study.Document)

    @_guarded
    def Activated(self):
        study = active_study()
        refs = [(s.Object, tuple(n for n in s.SubElementNames if n.startswith("Face")))
                for s in FreeCADGui.Selection.getSelectionEx()]
        refs = [r for r in refs if r[1]]
        if not refs:
            raise TopOptError("select the planar faces on the symmetry plane first")
        c = self.make(study)
        c.References = refs
        study.Constraints = list(study.Constraints) + [c]
        study.Document.recompute()


class RunStudy:
    def GetResources(self):
        return {"MenuText": "Run", "Pixmap": _icon("TopOptWorkbench.svg"),
                "ToolTip": "Mesh, optimise and show the result shape of the study"}

    def IsActive(self):
        return active_study() is not None

    @_guarded
    def Activated(self):
        from topopt.gui.panels import open_study_panel
        open_study_panel(active_study()).start_run()


class MeshStudy:
    def GetResources(self):
        return {"MenuText": "Mesh", "Pixmap": _icon("TopOptStudy.svg"),
                "ToolTip": "Mesh the part and the non-design solids into one tagged mesh and show it, "
                           "coloured by domain"}

    def IsActive(self):
        return active_study() is not None

    @_guarded
    def Activated(self):
        from topopt.app import runner
        from topopt.gui import display
        study = active_study()
        from topopt.gui.waiting import WaitDialog
        FreeCAD.Console.PrintMessage("TopOpt: meshing %s…\n" % study.Label)
        with WaitDialog("Meshing %s" % study.Label) as wait:
            result = runner.mesh_only(study, wait.on_progress, wait.cancel)
        display.show_domains(study)
        FreeCAD.Console.PrintMessage("TopOpt: %d nodes, %d tets (mean radius ratio %.2f)\n" % (
            len(result["nodes"]), len(result["tets"]), result["mean_radius_ratio"]))


class ExportStl:
    def GetResources(self):
        return {"MenuText": "Export result as STL", "Pixmap": _icon("TopOptStudy.svg"),
                "ToolTip": "Write the study's result shape to an STL file"}

    def IsActive(self):
        s = active_study()
        return s is not None and s.Result is not None

    @_guarded
    def Activated(self):
        from PySide2 import QtWidgets
        path, _ = QtWidgets.QFileDialog.getSaveFileName(FreeCADGui.getMainWindow(), "Export result",
                                                        "", "STL (*.stl)")
        if path:
            api.export_stl(active_study(), path)
            FreeCAD.Console.PrintMessage("TopOpt: result written to %s\n" % path)


COMMANDS = [("TopOpt_NewStudy", NewStudy), ("TopOpt_Fixed", AddFixed), ("TopOpt_Force", AddForce),
            ("TopOpt_Pressure", AddPressure), ("TopOpt_Symmetry", AddSymmetry),
            ("TopOpt_Mesh", MeshStudy), ("TopOpt_Run", RunStudy), ("TopOpt_ExportStl", ExportStl)]


def register():
    """Registers the commands; returns their names for the toolbar and menu."""
    for name, cls in COMMANDS:
        FreeCADGui.addCommand(name, cls())
    return [name for name, _ in COMMANDS]
