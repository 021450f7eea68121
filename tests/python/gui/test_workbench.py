"""The workbench in a real FreeCAD window (under Xvfb): it activates, its commands exist, a
study is made on the bundled example, its panel opens; screenshots are written for a person
to look at (TOPOPT_SCREENSHOTS, default /tmp/topopt-screenshots)."""
import os
import unittest

import FreeCAD
import FreeCADGui
import Part
from PySide import QtGui

from topopt.app import api
from gui_helpers import colours_in, grab_window, viewer_rect
from topopt.app.study import is_study

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(HERE, "..", "..", "..", "examples")
SHOTS = os.environ.get("TOPOPT_SCREENSHOTS", "/tmp/topopt-screenshots")


def settle(n=20):
    for _ in range(n):
        QtGui.QApplication.processEvents()


def screenshot(name):
    """The main window with its 3D view painted in (grab_window) and, beside it, the 3D view
    alone rendered offscreen. Returns the path of the 3D view image."""
    os.makedirs(SHOTS, exist_ok=True)
    mw = FreeCADGui.getMainWindow()
    mw.resize(1280, 960)
    settle()
    grab_window(os.path.join(SHOTS, name))
    view_path = os.path.join(SHOTS, name.replace(".png", "_3d.png"))
    FreeCADGui.ActiveDocument.ActiveView.saveImage(view_path, 1000, 750, "White")
    return view_path


def lever_document(name):
    """A document with the bundled lever and its three non-design solids."""
    doc = FreeCAD.newDocument(name)
    part = doc.addObject("Part::Feature", "Lever")
    part.Shape = Part.read(os.path.join(EXAMPLES, "lever.step"))
    keeps = []
    for i, s in enumerate(Part.read(os.path.join(EXAMPLES, "lever_nondesign.step")).Solids):
        o = doc.addObject("Part::Feature", "Keep%d" % (i + 1))
        o.Shape = s
        keeps.append(o)
    doc.recompute()
    return doc, part, keeps


class Workbench(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        FreeCAD.ConfigSet("TopOptNoDialogs", "1")  # errors go to the report view only
        FreeCADGui.getMainWindow().show()
        settle()

    def test_activates_with_commands(self):
        self.assertIn("TopOptWorkbench", FreeCADGui.listWorkbenches())
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        settle()
        self.assertEqual(FreeCADGui.activeWorkbench().name(), "TopOptWorkbench")
        commands = FreeCADGui.listCommands()
        for name in ("TopOpt_NewStudy", "TopOpt_Fixed", "TopOpt_Force", "TopOpt_Run", "TopOpt_ExportStl"):
            self.assertIn(name, commands)
        toolbars = [t.windowTitle() for t in FreeCADGui.getMainWindow().findChildren(QtGui.QToolBar)
                    if t.isVisible()]
        self.assertIn("Topology Optimization", toolbars)

    def test_new_study_from_selection_and_panel(self):
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        doc, part, keeps = lever_document("GuiLever")
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(part)
        for o in keeps:
            FreeCADGui.Selection.addSelection(o)
        FreeCADGui.runCommand("TopOpt_NewStudy")
        settle()
        studies = [o for o in doc.Objects if is_study(o)]
        self.assertEqual(len(studies), 1)
        study = studies[0]
        self.assertEqual(study.Part, part)
        self.assertEqual(len(study.NonDesign), 3)
        # Supports and loads through the scripting API, as a user's macro would.
        api.add_fixed(study, "Face9")
        api.add_force(study, "Face10", (0, -2000, 0))
        doc.recompute()
        children = study.ViewObject.Proxy.claimChildren()
        force = study.Constraints[1]
        self.assertEqual(children, [study.Constraints[0], force, force.Direction[0]])  # the force's line after it
        self.assertIsNotNone(FreeCADGui.Control.activeDialog())
        FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
        FreeCADGui.SendMsgToActiveView("ViewFit")
        path = screenshot("workbench_study.png")
        self.assertGreater(os.path.getsize(path), 10000)
        # the window's screenshot shows the 3D view (a bare widget grab leaves it one flat colour)
        rect = viewer_rect()
        self.assertIsNotNone(rect)
        self.assertGreater(colours_in(QtGui.QImage(os.path.join(SHOTS, "workbench_study.png")), rect), 20)
        FreeCADGui.Control.closeDialog()

    def test_mesh_run_and_result_in_the_panel(self):
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        doc, part, keeps = lever_document("GuiRun")
        study = api.new_study(doc, part, keeps, volume_fraction=0.35, mesh_size=4.0)
        study.MaxIterations = 15
        api.add_fixed(study, "Face9")
        api.add_force(study, "Face10", (0, -2000, 0))
        doc.recompute()
        # Mesh: one feature per domain, coloured
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(study)
        FreeCADGui.runCommand("TopOpt_Mesh")
        settle()
        domains = study.DomainMeshes
        self.assertEqual(len(domains), 4)  # design + 3 non-design solids
        self.assertEqual(sum(o.FemMesh.VolumeCount for o in domains), len(study.MeshTets) // 4)
        part.Visibility = False
        for o in keeps:
            o.Visibility = False
        FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
        FreeCADGui.SendMsgToActiveView("ViewFit")
        screenshot("workbench_mesh.png")
        for o in domains:
            o.Visibility = False
        # Run from the panel, on its worker thread, and wait for it
        from topopt.gui.panels import open_study_panel
        panel = open_study_panel(study)
        widgets = {b.prop: b.widget for b in panel.bindings}
        self.assertEqual(widgets["Mesher"].currentText(), "auto")
        self.assertEqual(widgets["WallLayers"].value(), 0)  # layers across thin walls: off by default
        widgets["Mesher"].setCurrentText("native")  # the panel edits the study itself
        self.assertEqual(study.Mesher, "native")
        study.VolumeFraction = 0.4  # the property editor's change shows in the panel
        settle()
        self.assertAlmostEqual(widgets["VolumeFraction"].value(), 0.4)
        panel.start_run()
        self.assertAlmostEqual(study.VolumeFraction, 0.4)  # Run does not write the panel over it
        self.assertFalse(panel.run_button.isEnabled())
        panel.wait(600)
        self.assertIsNotNone(study.Result, panel.status.text())
        self.assertTrue(study.Result.Mesh.isSolid())
        self.assertGreater(len(panel.plot.compliance), 1)  # the live plot got the iterations
        self.assertIsNotNone(study.DensityView)
        FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
        FreeCADGui.SendMsgToActiveView("ViewFit")
        path = screenshot("workbench_result.png")
        self.assertGreater(os.path.getsize(path), 10000)
        # The threshold slider re-extracts without a run
        before = study.Result.Mesh.Volume
        panel.threshold.setValue(25)
        panel.reextract()
        settle()
        self.assertGreater(study.Result.Mesh.Volume, before)
        density = study.DensityView
        study.Result.Visibility = False
        density.Visibility = True
        screenshot("workbench_density.png")
        panel.accept()

    def test_a_document_made_without_the_gui_opens_grouped_and_coloured(self):
        import subprocess
        import tempfile
        path = os.path.join(tempfile.mkdtemp(), "headless.FCStd")
        script = os.path.join(os.path.dirname(path), "make.py")
        with open(script, "w") as f:
            f.write("""import os, sys
sys.path.insert(0, %r)
import helpers
from topopt.app import api
doc, study = helpers.box_study("Headless", iterations=4, mesh_size=4.0)
api.run(study, verbose=False)
api.save(doc, %r)
os._exit(0)
""" % (os.path.join(HERE, "..", "app"), path))
        subprocess.run(["freecadcmd", "-c", "exec(open(%r).read())" % script], check=True, timeout=600,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        doc = FreeCAD.openDocument(path)
        settle(40)
        study = doc.getObject("TopOptStudy")
        from topopt.gui.view_providers import ViewProviderStudy
        self.assertIsInstance(study.ViewObject.Proxy, ViewProviderStudy)  # icon, tree, panel
        self.assertIn(study.Result, study.ViewObject.Proxy.claimChildren())
        self.assertTrue(study.Result.ViewObject.Coloring)
        self.assertEqual(study.DensityView.ViewObject.Field, "Density")  # computed now, with the GUI
        FreeCAD.closeDocument(doc.Name)

    def test_cancel_takes_the_panels_edits_back(self):
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        doc, part, keeps = lever_document("GuiCancel")
        doc.UndoMode = 1
        study = api.new_study(doc, part, keeps, volume_fraction=0.35, mesh_size=4.0)
        from topopt.gui.panels import open_study_panel
        panel = open_study_panel(study)
        widgets = {b.prop: b.widget for b in panel.bindings}
        widgets["VolumeFraction"].setValue(0.6)
        widgets["MeshSize"].setValue(7.0)
        self.assertAlmostEqual(study.VolumeFraction, 0.6)
        panel.reject()
        self.assertAlmostEqual(study.VolumeFraction, 0.35)
        self.assertAlmostEqual(float(study.MeshSize), 4.0)
        panel = open_study_panel(study)
        {b.prop: b.widget for b in panel.bindings}["VolumeFraction"].setValue(0.5)
        panel.accept()
        self.assertAlmostEqual(study.VolumeFraction, 0.5)
        self.assertIn("Edit TopOpt study", doc.UndoNames)
        doc.undo()
        self.assertAlmostEqual(study.VolumeFraction, 0.35)

    def test_icons_one_per_command_and_the_plot_legends_apart(self):
        from topopt.gui import commands
        icons = [cls().GetResources()["Pixmap"] for _, cls in commands.COMMANDS]
        self.assertEqual(len(set(icons)), len(icons))
        for path in icons:
            self.assertTrue(os.path.isfile(path), path)
        self.assertIn("Separator", commands.TOOLBARS[0][1])
        from topopt.gui.plot import HistoryPlot
        plot = HistoryPlot()
        plot.resize(240, 180)
        plot.set_history([120.0, 80.0, 61.5], [0.3, 0.3, 0.3])
        metrics = QtGui.QFontMetrics(plot.font())
        rect = plot.plot_rect(metrics, ["150"])
        self.assertGreaterEqual(rect.top(), 2 * metrics.height())  # two legend lines above the axes
        image = QtGui.QImage(240, 180, QtGui.QImage.Format_ARGB32)
        plot.render(image)
        os.makedirs(SHOTS, exist_ok=True)
        image.save(os.path.join(SHOTS, "plot_240px.png"))

    def test_bad_selection_reports_and_does_not_crash(self):
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        doc = FreeCAD.newDocument("GuiBad")
        face = doc.addObject("Part::Feature", "JustAFace")
        face.Shape = Part.makePlane(10, 10)
        doc.recompute()
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(face)
        FreeCADGui.runCommand("TopOpt_NewStudy")
        settle()
        self.assertFalse([o for o in doc.Objects if is_study(o)])
        self.assertIn(face, doc.Objects)  # the document survives


if __name__ == "__main__":
    unittest.main()
