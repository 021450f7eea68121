"""Faults of the core through the study panel's Run, in a real FreeCAD window (under Xvfb):
the worker crashes (TOPOPT_FAULT, test-only) or hangs and the user presses Cancel; FreeCAD
stays up, the panel says what happened and what to try, the message box the user sees is
captured (TOPOPT_SCREENSHOTS, default /tmp/topopt-screenshots), and the document is exactly as
it was."""
import os
import sys
import time
import unittest

import FreeCAD
import FreeCADGui
import Part
from PySide import QtCore, QtGui

from gui_helpers import grab_window
from topopt.app import api

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "app"))
from helpers import snapshot, worker_children  # noqa: E402  (shared with the FreeCADCmd tests)

SHOTS = os.environ.get("TOPOPT_SCREENSHOTS", "/tmp/topopt-screenshots")


def settle(n=20):
    for _ in range(n):
        QtGui.QApplication.processEvents()


def beam_document(name):
    doc = FreeCAD.newDocument(name)
    part = doc.addObject("Part::Feature", "Beam")
    part.Shape = Part.makeBox(60, 10, 10)
    doc.recompute()
    study = api.new_study(doc, part, (), volume_fraction=0.4, mesh_size=4.0)
    study.MaxIterations = 30
    api.add_fixed(study, "Face1")
    api.add_force(study, "Face2", (0, 0, -100))
    doc.recompute()
    return doc, study


class MessageCatcher:
    """Waits for the modal message box the panel opens, saves a picture of the screen with it
    and of the box alone, keeps its text and closes it."""

    def __init__(self, name):
        self.name, self.text, self.paths = name, None, []
        QtCore.QTimer.singleShot(200, self.look)

    def look(self):
        box = QtGui.QApplication.activeModalWidget()
        if not isinstance(box, QtGui.QMessageBox):
            QtCore.QTimer.singleShot(200, self.look)
            return
        os.makedirs(SHOTS, exist_ok=True)
        settle(5)
        screen = os.path.join(SHOTS, self.name + "_screen.png")
        QtGui.QGuiApplication.primaryScreen().grabWindow(0).save(screen)
        alone = os.path.join(SHOTS, self.name + "_box.png")
        box.grab().save(alone)
        self.paths = [screen, alone]
        self.text = box.text()
        box.accept()


class PanelFaults(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        FreeCADGui.getMainWindow().resize(1280, 960)
        FreeCADGui.getMainWindow().show()
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        settle()

    def setUp(self):
        self.doc, self.study = beam_document("GuiFault")

    def tearDown(self):
        os.environ.pop("TOPOPT_FAULT", None)
        FreeCADGui.Control.closeDialog()
        FreeCAD.closeDocument(self.doc.Name)
        settle()

    def start(self, fault):
        from topopt.gui.panels import open_study_panel
        panel = open_study_panel(self.study)
        settle()
        self.before = snapshot(self.doc)
        os.environ["TOPOPT_FAULT"] = fault
        panel.start_run()
        return panel

    def assertIntact(self):
        self.assertEqual(worker_children(), [])
        self.assertEqual(snapshot(self.doc), self.before)
        self.assertIsNone(self.study.Result)
        self.assertIsNone(self.study.DensityView)
        self.assertIsNone(self.study.FemResult)

    def test_crash_while_meshing_shows_the_stage_and_what_to_try(self):
        FreeCAD.ConfigSet("TopOptNoDialogs", "")  # the message box a user gets
        try:
            catcher = MessageCatcher("fault_mesh_segv")
            panel = self.start("mesh/faces:segv")
            panel.wait(120)
            settle()
        finally:
            FreeCAD.ConfigSet("TopOptNoDialogs", "1")
        expected = ("the mesher crashed (access violation, SIGSEGV) while meshing (faces): try another mesher "
                    "(the study's Mesher 'gmsh' or 'native') or another mesh size; your document is unchanged")
        self.assertEqual(catcher.text, expected)
        self.assertEqual(panel.status.text(), "failed: " + expected)
        self.assertTrue(panel.run_button.isEnabled())
        for path in catcher.paths:
            self.assertGreater(os.path.getsize(path), 2000)
        self.assertIntact()

    def test_cancel_of_a_hung_run_ends_it_at_once(self):
        FreeCAD.ConfigSet("TopOptNoDialogs", "1")
        panel = self.start("simp:hang")
        deadline = time.monotonic() + 120
        while not panel.plot.compliance and time.monotonic() < deadline:  # the first iteration arrives
            QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
            panel.poll()
        self.assertEqual(len(panel.plot.compliance), 1)  # then the worker hangs
        time.sleep(1.0)
        settle()
        self.assertIsNotNone(panel.thread)  # still "running"
        pressed = time.monotonic()
        panel.cancel_button.click()
        panel.wait(30)
        self.assertLess(time.monotonic() - pressed, 3.0, "Cancel must end the worker at once")
        self.assertEqual(panel.status.text(),
                         "stopped (cancelled while optimising (iteration 1)); the document is as it was")
        os.makedirs(SHOTS, exist_ok=True)
        grab_window(os.path.join(SHOTS, "fault_simp_hang_cancelled.png"))
        self.assertIntact()


if __name__ == "__main__":
    unittest.main()
