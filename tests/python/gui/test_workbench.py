"""The workbench in a real FreeCAD window (under Xvfb): it activates, its commands exist, a
study is made on the bundled example, its panel opens; screenshots are written for a person
to look at (TOPOPT_SCREENSHOTS, default /tmp/topopt-screenshots)."""
import os
import unittest

import FreeCAD
import FreeCADGui
import Part
from PySide2 import QtWidgets

from topopt.app import api
from topopt.app.study import is_study

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(HERE, "..", "..", "..", "examples")
SHOTS = os.environ.get("TOPOPT_SCREENSHOTS", "/tmp/topopt-screenshots")


def settle(n=20):
    for _ in range(n):
        QtWidgets.QApplication.processEvents()


def screenshot(name):
    """The main window (widgets) and, beside it, the 3D view rendered offscreen (a widget grab
    does not capture OpenGL). Returns the path of the 3D view image."""
    os.makedirs(SHOTS, exist_ok=True)
    mw = FreeCADGui.getMainWindow()
    mw.resize(1280, 960)
    settle()
    mw.grab().save(os.path.join(SHOTS, name))
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
        toolbars = [t.windowTitle() for t in FreeCADGui.getMainWindow().findChildren(QtWidgets.QToolBar)
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
        self.assertEqual(len(study.ViewObject.Proxy.claimChildren()), 2)
        self.assertIsNotNone(FreeCADGui.Control.activeDialog())
        FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
        FreeCADGui.SendMsgToActiveView("ViewFit")
        path = screenshot("workbench_study.png")
        self.assertGreater(os.path.getsize(path), 10000)
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
        domains = [o for o in doc.Objects if o.Name.startswith(study.Name + "_MeshDomain")]
        self.assertEqual(len(domains), 4)  # design + 3 non-design solids
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
        self.assertEqual(panel.mesher.currentText(), "auto")
        self.assertEqual(panel.layers.value(), 0)  # layers across thin walls: off by default
        panel.mesher.setCurrentText("native")  # the run takes the panel's choice
        panel.start_run()
        self.assertEqual(study.Mesher, "native")
        self.assertFalse(panel.run_button.isEnabled())
        panel.wait(600)
        self.assertIsNotNone(study.Result, panel.status.text())
        self.assertTrue(study.Result.Mesh.isSolid())
        self.assertGreater(len(panel.plot.compliance), 1)  # the live plot got the iterations
        self.assertIsNotNone(doc.getObject(study.Name + "_Density"))
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
        density = doc.getObject(study.Name + "_Density")
        study.Result.Visibility = False
        density.Visibility = True
        screenshot("workbench_density.png")
        FreeCADGui.Control.closeDialog()

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
