"""The study panel's design controls and objective/limits, and the result as CAD, in a real
FreeCAD window (under Xvfb): values set in the panel (planes and axes picked from faces and
edges) reach the study and its job on OK; a refused value keeps the panel open and the study
unchanged; "Result as solid" and "Export result as STEP" work from the toolbar's commands;
the verification's von Mises shows in FEM's post-processing. Screenshots go to
TOPOPT_SCREENSHOTS (default /tmp/topopt-screenshots) for a person to look at."""
import json
import os
import tempfile
import unittest

import FreeCAD
import FreeCADGui
from PySide import QtGui

from gui_helpers import BoxPanelCase, grab_window, open_workbench, select, settle, texts_cut
from app.helpers import top_loaded_box_study
from topopt.app import api
from topopt.gui import panels

SHOTS = os.environ.get("TOPOPT_SCREENSHOTS", "/tmp/topopt-screenshots")


def screenshot(name, fit=True):
    """The main window with its 3D view (grab_window), and the 3D view alone rendered offscreen.
    Returns both paths."""
    os.makedirs(SHOTS, exist_ok=True)
    mw = FreeCADGui.getMainWindow()
    mw.resize(1280, 960)
    if fit:
        FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
        FreeCADGui.ActiveDocument.ActiveView.fitAll()
    settle()
    window = os.path.join(SHOTS, name)
    grab_window(window)
    view = os.path.join(SHOTS, name.replace(".png", "_3d.png"))
    FreeCADGui.ActiveDocument.ActiveView.saveImage(view, 1000, 750, "White")
    return window, view


class Panel(BoxPanelCase):
    DOCUMENT = "PanelControls"

    def test_values_set_in_the_panel_reach_the_study_and_its_job(self):
        p, part = self.panel, self.study.Part
        select(part, "Face3")  # y = 0: the plane y = 0, normal -y
        p.controls.add_plane()
        select(part, "Edge1")  # a straight edge along z at x = y = 0
        p.controls.sectors.setValue(2)
        p.controls.add_cyclic()
        p.controls.pattern_on.setChecked(True)
        p.controls.pattern_dir.set((1, 0, 0))
        p.controls.pattern_pitch.setValue(20.0)
        p.controls.pattern_count.setValue(3)
        select(part, "Face6")  # z = 10: extrusion along +z
        p.controls.pick_extrusion()
        p.responses.objective.setCurrentText("mass")
        p.responses.stress_limit.setValue(250.0)
        p.responses.limit_dir.set((0, 0, -1))
        p.responses.limit_value.setValue(0.5)
        select(part, "Face2")
        p.responses.add_limit()
        settle()
        combo = FreeCADGui.getMainWindow().findChild(QtGui.QDockWidget, "Combo View")
        if combo is not None:  # the panel fits FreeCAD's default combo view, nothing clipped
            widths = {b.title(): b.minimumSizeHint().width() for b in p.form.findChildren(QtGui.QGroupBox)}
            self.assertLessEqual(p.form.minimumSizeHint().width(), combo.width(), widths)
        screenshot("panel_controls.png")
        self.assertEqual(texts_cut(p.form), [])  # every value, item and label shows whole
        form = p.form
        form.resize(max(form.width(), 330), form.sizeHint().height())
        form.grab().save(os.path.join(SHOTS, "panel_controls_whole.png"))  # the whole panel, unscrolled
        self.assertTrue(p.accept())
        self.assertFalse(p.is_open())
        c = json.loads(self.study.GeometryControls)
        plane = c["symmetry_planes"][0]
        self.assertEqual(len(c["symmetry_planes"]), 1)
        self.assertVector(plane["point"], [30, 0, 5])
        self.assertVector(plane["normal"], [0, -1, 0])
        self.assertEqual(c["cyclic"][0]["sectors"], 2)
        self.assertVector([abs(x) for x in c["cyclic"][0]["axis"]], [0, 0, 1])
        self.assertEqual(c["patterns"], [{"direction": [1.0, 0.0, 0.0], "pitch": 20.0, "count": 3}])
        self.assertEqual(c["extrusion"], [0.0, 0.0, 1.0])
        opt = api.job_of(self.study)["optimization"]
        self.assertEqual(opt["controls"], c)
        self.assertEqual(opt["objective"], "mass")
        self.assertEqual(opt["stress_limit"], 250.0)
        self.assertEqual(opt["update"], "mma")
        self.assertEqual(opt["displacement_limits"], [{"faces": ["Face2"], "direction": [0.0, 0.0, -1.0],
                                                       "limit": 0.5}])
        reopened = panels.open_study_panel(self.study)  # the panel shows what the study holds
        self.assertEqual(len(reopened.controls.planes.items), 1)
        self.assertEqual(reopened.responses.objective.currentText(), "mass")
        self.assertEqual(len(reopened.responses.limits.items), 1)
        self.assertTrue(reopened.accept())  # unchanged values are written back unchanged
        self.assertEqual(json.loads(self.study.GeometryControls), c)
        self.panel = reopened

    def assertVector(self, got, expected):
        for g, e in zip(got, expected):
            self.assertAlmostEqual(g, e, places=9)
        self.assertEqual(len(got), len(expected))

    def test_a_refused_value_keeps_the_panel_open_and_the_study_unchanged(self):
        self.panel.responses.objective.setCurrentText("mass")  # no limit: the job parser refuses
        self.assertFalse(self.panel.accept())
        self.assertTrue(self.panel.is_open())
        self.assertEqual(self.study.Responses, "")
        self.assertEqual(self.study.Update, "oc")

    def test_picking_the_wrong_kind_of_element_is_said_not_added(self):
        select(self.study.Part, "Edge1")
        self.panel.controls.add_plane_button.click()  # an edge is no plane: reported, nothing added
        select(self.study.Part, "Face1")
        self.panel.controls.add_cyclic_button.click()  # a planar face has no axis
        self.assertEqual(self.panel.controls.planes.items, [])
        self.assertEqual(self.panel.controls.cyclic.items, [])


class ResultAsCad(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        open_workbench()
        cls.doc, cls.study = top_loaded_box_study("ResultAsCad")
        api.run(cls.study, verbose=False)
        settle()

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def test_result_as_solid_command(self):
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(self.study)
        FreeCADGui.runCommand("TopOpt_ResultAsSolid")
        settle()
        solid = self.study.ResultSolid
        self.assertIsNotNone(solid)
        self.assertEqual(len(solid.Shape.Solids), 1)
        self.assertTrue(solid.ViewObject.Visibility)
        self.assertFalse(self.study.Result.ViewObject.Visibility)
        for obj in self.doc.Objects:  # the part (coincident faces) and the arrows would hide the solid
            if obj is not solid and obj.ViewObject is not None:
                obj.ViewObject.Visibility = False
        self.assertEqual(self.doc.UndoNames[0] if self.doc.UndoMode else "TopOpt result as solid",
                         "TopOpt result as solid")
        screenshot("result_solid.png")

    def test_z_the_solid_follows_the_threshold_slider(self):
        # the slider moved in the study's panel re-extracts the shown result; Result as solid then
        # makes the solid at that threshold (its volume the shown result's), not the run's
        run = self.study.RunThreshold
        self._select()
        FreeCADGui.runCommand("TopOpt_ResultAsSolid")
        settle()
        at_run = self.study.ResultSolid.Shape.Volume
        panel = panels.open_study_panel(self.study)
        settle()
        try:
            higher = int(round(100 * min(0.9, run + 0.25)))
            panel.threshold.setValue(higher)
            panel.reextract()
            settle()
            self.assertAlmostEqual(self.study.Threshold, higher / 100.0)
            self.assertIn("%.2f: keeps" % (higher / 100.0), panel.threshold_label.text())
            self.study.Result.ViewObject.Visibility = True
            self.study.ResultSolid.ViewObject.Visibility = False
            screenshot("slider_moved.png")
            self._select()
            FreeCADGui.runCommand("TopOpt_ResultAsSolid")
            settle()
            solid = self.study.ResultSolid
            shown = self.study.Result.Mesh.Volume
            self.assertLess(abs(solid.Shape.Volume - shown) / shown, 0.005)
            self.assertLess(solid.Shape.Volume, 0.97 * at_run)
            FreeCAD.Console.PrintMessage("TopOpt test: solid at the run's threshold %.2f: %.1f mm³, at the slider's "
                                         "%.2f: %.1f mm³ (shown mesh %.1f mm³)\n"
                                         % (run, at_run, higher / 100.0, solid.Shape.Volume, shown))
            screenshot("solid_follows_slider.png")
        finally:
            if panel.is_open():
                panel.reject()
            settle()

    def _select(self):
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(self.study)

    def test_verification_von_mises_in_fem_post_processing(self):
        from topopt.app import asbuilt
        pipe, res = self.study.VerificationFields, self.study.VerificationResult
        self.assertIsNotNone(pipe)
        report = json.loads(self.study.VerificationReport)
        self.assertAlmostEqual(max(res.vonMises), report["max_von_mises"], delta=1e-6 * report["max_von_mises"])
        for obj in self.doc.Objects:
            if obj.ViewObject is not None:
                obj.ViewObject.Visibility = False
        vo = pipe.ViewObject
        vo.Visibility = True
        self.assertIn(asbuilt.VON_MISES, vo.getEnumerationsOfProperty("Field"))
        self.assertEqual(vo.DisplayMode, "Surface")
        vo.Field = asbuilt.VON_MISES  # as a user picks it in the property editor (a cell field crashed 0.20)
        settle()
        import ObjectsFem
        clip = ObjectsFem.makePostVtkFilterClipScalar(self.doc, pipe)  # FEM's own clip works on it
        self.doc.recompute()
        clip.Scalars = asbuilt.VON_MISES
        clip.Value = report["max_von_mises"] / 4
        self.doc.recompute()
        clip.ViewObject.Visibility = False
        screenshot("verification_von_mises.png")
        self.doc.removeObject(clip.Name)
        vo.Visibility = False

    def test_every_field_of_the_pipelines_can_be_chosen(self):
        # choosing a cell field crashed FreeCAD 0.20 (SIGSEGV in the pipeline's view): the
        # run's pipelines hold point fields only, and each can be chosen as a user would
        for pipe in (self.study.Fields, self.study.VerificationFields):
            vo = pipe.ViewObject
            vo.DisplayMode = "Surface"
            settle(5)
            fields = vo.getEnumerationsOfProperty("Field")
            self.assertGreaterEqual(len(fields), 3, pipe.Label)
            for f in fields:
                vo.Field = f
                settle(5)
                self.assertEqual(vo.Field, f)
            vo.Visibility = False

    def test_export_step_command_writes_the_file(self):
        from topopt.gui import commands
        path = os.path.join(tempfile.mkdtemp(prefix="topopt-gui-step-"), "result.step")
        original = QtGui.QFileDialog.getSaveFileName
        QtGui.QFileDialog.getSaveFileName = staticmethod(lambda *a, **k: (path, "STEP (*.step *.stp)"))
        try:
            FreeCADGui.Selection.clearSelection()
            FreeCADGui.Selection.addSelection(self.study)
            commands.ExportStep().Activated()
        finally:
            QtGui.QFileDialog.getSaveFileName = original
        self.assertTrue(os.path.getsize(path) > 1000)
        with open(path) as f:
            self.assertIn("ISO-10303-21", f.readline())


if __name__ == "__main__":
    unittest.main()
