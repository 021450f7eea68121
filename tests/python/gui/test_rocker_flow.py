"""The whole user flow on the rocker in a real FreeCAD window (under Xvfb), as a FreeCAD user
goes through it: import the STEP files, pick the part and the rings, New study, supports and
loads with explicit directions (TopOpt's force panel), Mesh, Run, Stop, Run again, the
threshold slider with undo, Result as solid, Export STEP, save, reopen. Screenshots of every
step go to TOPOPT_SCREENSHOTS (default /tmp/topopt-screenshots/rocker) for a person to look at.

The rocker's load case (shared data README): the bore at (0, 0) (Face10) fixed, 1000 N in -Y
on the bore at (80, 10) (Face9), 600 N in +X on the bore at (40, 55) (Face11)."""
import os
import time
import unittest

import FreeCAD
import FreeCADGui
from PySide import QtGui

from gui_helpers import grab_window, texts_cut
from topopt.app.study import is_study

SHARED = os.environ.get("TOPOPT_SHARED_DATA", "")
SHOTS = os.path.join(os.environ.get("TOPOPT_SCREENSHOTS", "/tmp/topopt-screenshots"), "rocker")
TMP = os.environ.get("TOPOPT_TEST_HOME", "/tmp")


def settle(n=20):
    for _ in range(n):
        QtGui.QApplication.processEvents()


def screenshot(name, view=True):
    """The main window with its 3D view painted in (grab_window), and the 3D view alone
    rendered offscreen at a fixed size (*_3d.png)."""
    os.makedirs(SHOTS, exist_ok=True)
    settle()
    grab_window(os.path.join(SHOTS, name + ".png"))
    if view and FreeCADGui.ActiveDocument is not None:
        FreeCADGui.ActiveDocument.ActiveView.saveImage(os.path.join(SHOTS, name + "_3d.png"), 1000, 750, "White")


def report_text():
    settle(40)  # the report view shows new messages from its event loop
    dock = FreeCADGui.getMainWindow().findChild(QtGui.QDockWidget, "Report view")
    edit = dock.findChild(QtGui.QTextEdit) if dock else None
    return edit.toPlainText() if edit else ""


def select(obj, *subs):
    FreeCADGui.Selection.clearSelection()
    for s in subs or [""]:
        FreeCADGui.Selection.addSelection(obj, s) if s else FreeCADGui.Selection.addSelection(obj)
    settle()


def fit(iso=True):
    view = FreeCADGui.ActiveDocument.ActiveView
    view.viewIsometric() if iso else view.viewTop()
    view.fitAll()
    settle()


def close_task_panel():
    if FreeCADGui.Control.activeDialog():
        FreeCADGui.Control.closeDialog()
    settle()


class RockerFlow(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        FreeCAD.ConfigSet("TopOptNoDialogs", "1")  # errors go to the report view only
        mw = FreeCADGui.getMainWindow()
        mw.show()
        mw.resize(1280, 960)
        settle()
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        settle()

    def test_user_flow(self):
        doc, part, rings = self.step_import_and_pick()
        study = self.step_new_study(doc, part, rings)
        self.step_constraints(study, part)
        self.step_mesh(study)
        panel = self.step_run_stop_run(study)
        self.step_results(study)
        self.step_slider_and_undo(study, panel)
        self.step_result_as_cad(study)
        self.step_save_and_reopen(doc, study)

    # --- the steps, in order ------------------------------------------------------------------
    def step_import_and_pick(self):
        import CompoundTools.Explode
        import ImportGui
        doc = FreeCAD.newDocument("Rocker")
        ImportGui.insert(os.path.join(SHARED, "examples", "rocker.step"), doc.Name)
        part = doc.Objects[-1]
        ImportGui.insert(os.path.join(SHARED, "examples", "rocker_nondesign.step"), doc.Name)
        rings = doc.Objects[-1]
        if len(rings.Shape.Solids) > 1:  # one compound of the three rings: Part > Explode compound
            group = CompoundTools.Explode.explodeCompound(rings)[0]
            doc.recompute()
            rings = list(group.Group)
        else:
            rings = [rings]
        part.Label, part.ViewObject.Transparency = "Rocker", 50
        self.assertEqual(len(rings), 3)
        self.assertEqual(len(part.Shape.Faces), 11)
        select(part)
        for r in rings:
            FreeCADGui.Selection.addSelection(r)
        fit()
        screenshot("01_imported_and_picked")
        return doc, part, rings

    def step_new_study(self, doc, part, rings):
        FreeCADGui.runCommand("TopOpt_NewStudy")
        settle()
        studies = [o for o in doc.Objects if is_study(o)]
        self.assertEqual(len(studies), 1)
        study = studies[0]
        self.assertEqual(study.Part, part)
        self.assertEqual(study.NonDesign, rings)
        self.assertTrue(FreeCADGui.Control.activeDialog())  # the study's panel
        panel = study.ViewObject.Proxy.panel
        self.assertLessEqual(panel.form.minimumSizeHint().width(), 260)  # fits the default combo view
        panel.bindings[2].widget.setValue(2.5)  # mesh size
        panel.bindings[1].widget.setValue(40)  # iterations
        self.assertAlmostEqual(float(study.MeshSize), 2.5)  # the panel writes the study itself
        self.assertEqual(study.MaxIterations, 40)
        screenshot("02_new_study_panel")
        self.assertEqual(texts_cut(panel.form), [])  # every value ("2.50 mm"), item and label shows whole
        return study

    def step_constraints(self, study, part):
        before = report_text()
        select(part, "Face10")
        FreeCADGui.runCommand("TopOpt_Fixed")  # closes the study panel (keeping its edits), opens FEM's
        settle()
        self.assertNotIn("already open", report_text()[len(before):])
        screenshot("03_fixed_fem_panel")
        close_task_panel()
        self.assertEqual(float(study.MeshSize), 2.5)
        self.add_force(study, part, "Face9", 1000.0, preset="-Y")
        count, names = len(study.Constraints), sorted(o.Name for o in study.Document.Objects)
        select(part, "Face11")
        FreeCADGui.runCommand("TopOpt_Force")
        settle()
        study.ViewObject.Proxy.force_panel.reject()  # Cancel takes the new force away
        settle()
        self.assertEqual(len(study.Constraints), count)
        self.assertEqual(sorted(o.Name for o in study.Document.Objects), names)
        self.add_force(study, part, "Face11", 600.0, vector=(1, 0, 0))
        forces = [c for c in study.Constraints if c.TypeId == "Fem::ConstraintForce"]
        self.assertEqual(len(forces), 2)
        self.assertAlmostEqual(forces[0].DirectionVector.y, -1.0)  # what FEM draws and applies
        self.assertAlmostEqual(forces[1].DirectionVector.x, 1.0)
        FreeCADGui.Selection.clearSelection()
        fit(iso=False)
        screenshot("05_loads_with_arrows")
        self.assertNotIn("already open", report_text()[len(before):])

    def add_force(self, study, part, face, newtons, preset=None, vector=None):
        select(part, face)
        FreeCADGui.runCommand("TopOpt_Force")
        settle()
        from topopt.gui.force_panel import ForcePanel
        panels = [w for w in FreeCADGui.getMainWindow().findChildren(QtGui.QWidget, "TopOptForcePanel")
                  if w.isVisible()]
        self.assertEqual(len(panels), 1)
        panel = study.ViewObject.Proxy.force_panel
        panel.magnitude.setValue(newtons)
        if preset:
            [b for b in panel.form.findChildren(QtGui.QPushButton) if b.text() == preset][0].click()
        else:
            panel.set_vector(vector)
        settle()
        if face == "Face9":
            self.assertLessEqual(panel.form.minimumSizeHint().width(), 240)  # fits the default combo view
            screenshot("04_force_panel")
            self.assertEqual(texts_cut(panel.form), [])
        self.assertIsInstance(panel, ForcePanel)
        self.assertTrue(panel.accept())
        settle()

    def step_mesh(self, study):
        select(study)
        FreeCADGui.runCommand("TopOpt_Mesh")
        settle()
        self.assertEqual(len(study.DomainMeshes), 4)  # design + 3 rings
        self.assertIn("non-design 1", study.DomainMeshes[1].Label)
        for o in study.Document.Objects:
            if o.TypeId.startswith("Part::") or o.TypeId.startswith("App::"):  # imported shapes, groups
                o.Visibility = False
        fit()
        screenshot("06_mesh_by_domain")
        for o in study.DomainMeshes:
            o.Visibility = False

    def step_run_stop_run(self, study):
        from topopt.gui.panels import open_study_panel
        doc = study.Document
        panel = open_study_panel(study)
        panel.start_run()
        deadline = time.time() + 300
        while len(panel.plot.compliance) < 3 and panel.thread is not None and time.time() < deadline:
            panel.wait(0.2)
        screenshot("07_running", view=False)
        before = report_text()
        panel.cancel_button.click()
        panel.wait(30)
        self.assertIsNone(panel.thread)
        self.assertIsNone(study.Result)  # the document is as it was
        self.assertIn("stopped", panel.status.text())
        self.assertNotIn("Error", report_text()[len(before):])
        screenshot("08_stopped", view=False)
        panel.start_run()
        panel.wait(900)
        self.assertIsNotNone(study.Result, panel.status.text())
        self.assertTrue(study.Result.Mesh.isSolid())
        self.assertEqual(panel.progress.value(), 100)
        self.assertIn("finished", report_text())  # the run summary
        self.assertIn("TopOpt run", doc.UndoNames)
        fit()
        screenshot("09_result")
        panel.accept()
        return panel

    def step_results(self, study):
        res = study.FemResult
        self.assertEqual(len(res.DisplacementLengths), len(study.MeshNodes))
        self.assertGreater(max(res.DisplacementLengths), 0)
        self.assertGreater(max(res.vonMises), 0)
        on_rings = sum(1 for c in study.Result.FaceColors if c[:3] != study.Result.FaceColors[0][:3])
        self.assertGreater(on_rings, 0)  # the rings are coloured apart
        study.Result.Visibility = False
        study.DensityView.Visibility = True
        fit()
        screenshot("10_density_view")
        study.DensityView.Visibility = False
        FreeCADGui.activateWorkbench("FemWorkbench")  # FEM's own result panel on the last iterate
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(res)
        FreeCADGui.runCommand("FEM_ResultShow")
        settle(40)
        self.assertTrue(FreeCADGui.Control.activeDialog())
        study.AnalysisMesh.Visibility = True
        radios = [b for b in FreeCADGui.getMainWindow().findChildren(QtGui.QRadioButton)
                  if "Mises" in b.text() and b.isVisible()]
        self.assertTrue(radios)
        radios[0].click()
        settle(40)
        fit()
        screenshot("11_fem_result_panel_von_mises")
        close_task_panel()
        study.AnalysisMesh.Visibility = False
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        study.Result.Visibility = True

    def step_slider_and_undo(self, study, panel):
        from topopt.gui.panels import open_study_panel
        doc = study.Document
        panel = open_study_panel(study)
        run_threshold = study.Threshold
        self.assertEqual(panel.threshold.value(), int(round(100 * run_threshold)))  # the run's, not 0.50
        volume = study.Result.Mesh.Volume
        panel.threshold.setValue(25)
        self.assertIn("keeps", panel.threshold_label.text())
        panel.reextract()
        settle()
        self.assertGreater(study.Result.Mesh.Volume, volume)
        self.assertAlmostEqual(study.Threshold, 0.25)
        fit()
        screenshot("12_threshold_025")
        job = __import__("topopt.app.job", fromlist=["study_to_job"]).study_to_job(study)
        self.assertNotIn("threshold", job["optimization"])  # never an input of the next run
        panel.accept()
        doc.undo()  # the threshold change
        settle()
        self.assertAlmostEqual(study.Threshold, run_threshold)
        self.assertAlmostEqual(study.Result.Mesh.Volume, volume, delta=1e-6 * volume)
        doc.redo()
        self.assertAlmostEqual(study.Threshold, 0.25)

    def step_result_as_cad(self, study):
        """Back at the run's threshold, the toolbar's Result as solid gives one valid solid of
        the result mesh's volume, and Export STEP writes a file OCCT reads back as that solid."""
        import Part
        from topopt.app import api
        doc = study.Document
        doc.undo()  # the slider back at the run's threshold
        settle()
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(study)
        FreeCADGui.runCommand("TopOpt_ResultAsSolid")
        settle()
        solid = study.ResultSolid
        self.assertIsNotNone(solid, report_text()[-2000:])
        self.assertTrue(solid.Shape.isValid())
        self.assertEqual(len(solid.Shape.Solids), 1)
        volume = study.Result.Mesh.Volume
        self.assertAlmostEqual(solid.Shape.Volume, volume, delta=0.005 * volume)
        for o in doc.Objects:
            if o.ViewObject is not None and o is not solid:
                o.Visibility = False
        fit()
        screenshot("15_result_as_solid")
        path = api.export_step(study, os.path.join(TMP, "rocker_result.step"))
        back = Part.read(path)
        self.assertTrue(back.isValid())
        self.assertAlmostEqual(back.Volume, volume, delta=0.005 * volume)
        solid.Visibility = False

    def step_save_and_reopen(self, doc, study):
        path = os.path.join(TMP, "rocker_study.FCStd")
        name = study.Name
        doc.saveAs(path)
        FreeCAD.closeDocument(doc.Name)
        settle()
        before = report_text()
        doc = FreeCAD.openDocument(path)
        settle(40)
        study = doc.getObject(name)
        self.assertNotIn("defects", report_text()[len(before):])
        # the colours and views restored after loading are no edit: closing asks nothing
        self.assertFalse(FreeCADGui.getDocument(doc.Name).Modified)
        self.assertEqual(len(study.Result.FaceColors), study.Result.Mesh.CountFacets)
        self.assertTrue(study.Result.ViewObject.Coloring)
        self.assertEqual(study.DensityView.ViewObject.Field, "Density")
        children = study.ViewObject.Proxy.claimChildren()
        for name in ("Result", "FemResult", "AnalysisMesh", "Fields"):
            self.assertIn(getattr(study, name), children)
        for o in doc.Objects:
            o.Visibility = False
        study.Result.Visibility = True
        fit()
        screenshot("13_reopened_result")
        self.assertGreater(self.coloured_pixels(os.path.join(SHOTS, "13_reopened_result_3d.png")), 500)
        study.Result.Visibility = False
        study.DensityView.Visibility = True
        fit()
        screenshot("14_reopened_density")


    @staticmethod
    def coloured_pixels(path):
        """Pixels of a picture that are clearly coloured (not white, grey or black): the rings'
        colours on the result shape."""
        img = QtGui.QImage(path)
        count = 0
        for x in range(0, img.width(), 3):
            for y in range(0, img.height(), 3):
                c = QtGui.QColor(img.pixel(x, y))
                if max(c.red(), c.green(), c.blue()) - min(c.red(), c.green(), c.blue()) > 60:
                    count += 1
        return count


if __name__ == "__main__":
    unittest.main()
