"""Workbench commands. Each one checks its preconditions and reports problems in the report
view (and a message box); none may raise into FreeCAD. Every command has its own icon."""
import FreeCAD
import FreeCADGui

import topopt
from topopt.app import api
from topopt.app.errors import TopOptError
from topopt.app.study import is_study


def _icon(name):
    return topopt.resources_dir() + "/icons/" + name


def active_study():
    """The selected study (or the study of a selected constraint), or the only study of the
    active document."""
    doc = FreeCAD.ActiveDocument
    if doc is None:
        return None
    studies = [o for o in doc.Objects if is_study(o)]
    for obj in FreeCADGui.Selection.getSelection():
        if is_study(obj):
            return obj
        for s in studies:
            if obj in s.Constraints:
                return s
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


def _free_task_view(study):
    """Closes the study's panel (keeping its edits) so that another task panel can open; a
    TopOptError when a run is going."""
    from topopt.gui.panels import close_study_panel
    if not close_study_panel(study):
        raise TopOptError("the study is running: wait for the run to end or stop it first", "InvalidParameter")
    if FreeCADGui.Control.activeDialog():
        raise TopOptError("another task panel is open: close it (OK or Cancel) first", "InvalidParameter")


class _Command:
    """A workbench command: its menu text, tooltip and icon as class attributes; active when
    there is a study to act on (subclasses say otherwise)."""
    menu, tip, icon = "", "", ""

    def GetResources(self):
        return {"MenuText": self.menu, "ToolTip": self.tip, "Pixmap": _icon(self.icon)}

    def IsActive(self):
        return active_study() is not None


class NewStudy(_Command):
    menu, icon = "New study", "TopOptNewStudy.svg"
    tip = "Select the part first, then the non-design solids to keep, and create a study"

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and bool(FreeCADGui.Selection.getSelection())

    @_guarded
    def Activated(self):
        sel = [o for o in FreeCADGui.Selection.getSelection() if hasattr(o, "Shape")]
        if not sel:
            raise TopOptError("select the part (a solid) first, then any non-design solids")
        from topopt.gui.waiting import WaitDialog
        with WaitDialog("Checking the shapes", "info") as wait:  # checks, with clear errors
            api.info(sel[0].Shape, [o.Shape for o in sel[1:]] or None, cancel=wait.cancel)
        doc = FreeCAD.ActiveDocument
        from topopt.app.runner import transaction
        with transaction(doc, "New TopOpt study"):
            study = api.new_study(doc, sel[0], sel[1:])
            doc.recompute()
        from topopt.gui.panels import open_study_panel
        open_study_panel(study)


def _selected_refs():
    refs = [(s.Object, tuple(n for n in s.SubElementNames if n.startswith("Face")))
            for s in FreeCADGui.Selection.getSelectionEx()]
    return [r for r in refs if r[1]]


class _AddConstraint(_Command):
    """Creates a constraint on the selected faces of the study's part or non-design solids, then
    opens FreeCAD FEM's own task panel for it (so users keep their habits)."""

    @_guarded
    def Activated(self):
        study = active_study()
        _free_task_view(study)
        refs = _selected_refs()
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
    menu, tip, icon = "Fixed support", "Fix the selected faces", "TopOptFixed.svg"

    def make(self, study):
        import ObjectsFem
        return ObjectsFem.makeConstraintFixed(study.Document, "Fixed")


class AddForce(_Command):
    """A FEM force on the selected faces in TopOpt's force panel, whose direction is always
    given: a vector (x, y, z) or a picked straight edge or planar face. With a force of the
    study selected, edits it in the same panel."""
    menu, icon = "Force", "TopOptForce.svg"
    tip = ("A total force on the selected faces, in a direction you give (x, y, z) or pick; with a force "
           "selected, edit it")

    @_guarded
    def Activated(self):
        study = active_study()
        _free_task_view(study)
        from topopt.gui.force_panel import open_force_panel, selected_faces
        chosen = [o for o in FreeCADGui.Selection.getSelection() if o in study.Constraints
                  and o.TypeId == "Fem::ConstraintForce"]
        if chosen:
            open_force_panel(study, chosen[0], "Edit TopOpt force")
            return
        faces = selected_faces(study)
        doc = study.Document
        doc.openTransaction("TopOpt force")
        import ObjectsFem
        c = ObjectsFem.makeConstraintForce(doc, "Force")
        refs = {}
        for obj, n in faces:
            refs.setdefault(obj, []).append(n)
        c.References = [(obj, tuple(names)) for obj, names in refs.items()]
        study.Constraints = list(study.Constraints) + [c]
        open_force_panel(study, c, "TopOpt force")


class AddPressure(_AddConstraint):
    menu, tip, icon = "Pressure", "A pressure on the selected faces", "TopOptPressure.svg"

    def make(self, study):
        import ObjectsFem
        return ObjectsFem.makeConstraintPressure(study.Document, "Pressure")


class AddSymmetry(_Command):
    menu, tip, icon = "Symmetry plane", "The selected planar faces lie on a symmetry plane", "TopOptSymmetry.svg"

    @_guarded
    def Activated(self):
        study = active_study()
        refs = _selected_refs()
        if not refs:
            raise TopOptError("select the planar faces on the symmetry plane first")
        from topopt.app.runner import transaction
        from topopt.app.symmetry import make_symmetry_plane
        with transaction(study.Document, "Symmetry plane"):
            c = make_symmetry_plane(study.Document, refs)
            study.Constraints = list(study.Constraints) + [c]
            study.Document.recompute()


class RunStudy(_Command):
    menu, icon = "Run", "TopOptRun.svg"
    tip = "Mesh, optimise and show the result of the study (its panel opens with the live plot and Stop)"

    @_guarded
    def Activated(self):
        from topopt.gui.panels import open_study_panel
        open_study_panel(active_study()).start_run()


class MeshStudy(_Command):
    menu, icon = "Mesh", "TopOptMesh.svg"
    tip = ("Mesh the part and the non-design solids into one tagged mesh and show it, coloured by domain "
           "(with the study's mesh settings)")

    @_guarded
    def Activated(self):
        from topopt.app import runner
        study = active_study()
        from topopt.gui.waiting import WaitDialog
        FreeCAD.Console.PrintMessage("TopOpt: meshing %s\n" % study.Label)
        with WaitDialog("Meshing %s" % study.Label, "mesh") as wait:
            result = runner.mesh_only(study, wait.on_progress, wait.cancel)
        FreeCAD.Console.PrintMessage("TopOpt: %d nodes, %d tets (mean radius ratio %.2f): %s\n" % (
            len(result["nodes"]), len(result["tets"]), result["mean_radius_ratio"],
            ", ".join(o.Label for o in study.DomainMeshes)))


class _ResultCommand(_Command):
    """A command on the study's result: active when the study has one."""

    def IsActive(self):
        s = active_study()
        return s is not None and s.Result is not None


def _export(title, file_filter, write):
    """Asks for a file name and writes it with write(study, path), reporting where it went."""
    from PySide import QtGui
    study = active_study()
    path, _ = QtGui.QFileDialog.getSaveFileName(FreeCADGui.getMainWindow(), title, "", file_filter)
    if path:
        write(study, path)
        FreeCAD.Console.PrintMessage("TopOpt: %s written to %s\n" % (title.lower().replace("export ", ""), path))


class ExportStl(_ResultCommand):
    menu, tip, icon = "Export result as STL", "Write the study's result shape to an STL file", "TopOptExportStl.svg"

    @_guarded
    def Activated(self):
        _export("Export result", "STL (*.stl)", api.export_stl)


class ExportStep(_ResultCommand):
    menu, icon = "Export result as STEP", "TopOptExportStep.svg"
    tip = ("Write the study's result as one CAD solid to a STEP file, at the threshold the result is shown at "
           "(the threshold slider's)")

    @_guarded
    def Activated(self):
        from topopt.app import asbuilt, threshold_solid
        study = active_study()
        t = threshold_solid.chosen(study)  # the slider's: the shown result's threshold
        asbuilt.step_path(study)  # a run that wrote no STEP has none at any threshold: refused before the dialog
        _export("Export result solid", "STEP (*.step *.stp)", lambda s, path: api.export_step(s, path, threshold=t))


class ResultAsSolid(_ResultCommand):
    menu, icon = "Result as solid", "TopOptResultSolid.svg"
    tip = ("Add the study's result as a Part solid, at the threshold the result is shown at (the threshold "
           "slider's), to use in further CAD work")

    @_guarded
    def Activated(self):
        from topopt.app import threshold_solid
        study = active_study()
        t = threshold_solid.chosen(study)
        feature = api.result_solid(study, threshold=t)
        FreeCAD.Console.PrintMessage("TopOpt: %s at threshold %.2f: one solid, %d faces, %.6g mm³\n" % (
            feature.Label, t, len(feature.Shape.Faces), feature.Shape.Volume))
        feature.ViewObject.Visibility = True  # the solid in place of the result mesh
        if study.Result is not None:
            study.Result.ViewObject.Visibility = False


class BuildCore(_Command):
    menu, icon = "Build the native core", "TopOptBuildCore.svg"

    @property
    def tip(self):
        return "Build TopOpt's compiled core in this clone of the repository (%s)" % (
            topopt.build_command() or "not available: this TopOpt was installed")

    def IsActive(self):
        return topopt.source_root() is not None

    @_guarded
    def Activated(self):
        from topopt.gui.build_core import build_native_core
        build_native_core()


COMMANDS = [("TopOpt_NewStudy", NewStudy), ("TopOpt_Fixed", AddFixed), ("TopOpt_Force", AddForce),
            ("TopOpt_Pressure", AddPressure), ("TopOpt_Symmetry", AddSymmetry),
            ("TopOpt_Mesh", MeshStudy), ("TopOpt_Run", RunStudy), ("TopOpt_ExportStl", ExportStl),
            ("TopOpt_ExportStep", ExportStep), ("TopOpt_ResultAsSolid", ResultAsSolid), ("TopOpt_BuildCore", BuildCore)]

_STUDY = ["TopOpt_NewStudy"]
_CONSTRAINTS = ["TopOpt_Fixed", "TopOpt_Force", "TopOpt_Pressure", "TopOpt_Symmetry"]
_SOLVE = ["TopOpt_Mesh", "TopOpt_Run"]
_RESULT = ["TopOpt_ResultAsSolid", "TopOpt_ExportStl", "TopOpt_ExportStep"]

#: toolbars: (title, command names with separators)
TOOLBARS = [("Topology Optimization", _STUDY + ["Separator"] + _CONSTRAINTS + ["Separator"] + _SOLVE
             + ["Separator"] + _RESULT)]
#: the menu: the same groups, then the build of the core
MENU = TOOLBARS[0][1] + ["Separator", "TopOpt_BuildCore"]


def register():
    """Registers the commands; returns their names."""
    for name, cls in COMMANDS:
        FreeCADGui.addCommand(name, cls())
    return [name for name, _ in COMMANDS]


def tell_if_core_missing():
    """When the native core is missing, says so in one dialog with the command that builds it
    (the report view gets the same text). Returns True when something was said."""
    problem = topopt.core_problem()
    if problem is None:
        return False
    FreeCAD.Console.PrintError("TopOpt: %s\n" % problem.replace("\n\n", " ").replace("\n", " "))
    mw = FreeCADGui.getMainWindow()
    if mw is not None and mw.isVisible() and not FreeCAD.ConfigGet("TopOptNoDialogs"):
        from PySide import QtCore, QtGui
        box = QtGui.QMessageBox(QtGui.QMessageBox.Warning, "TopOpt: native core missing", problem,
                                QtGui.QMessageBox.Ok, mw)
        box.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)  # the command can be copied
        (getattr(box, "exec", None) or box.exec_)()  # exec_ in Qt 5 bindings; exec in the Qt 6 ones (FreeCAD 1.x)
    return True
