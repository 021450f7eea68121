"""Result first, verification after, in a real FreeCAD window (under Xvfb): with the study's
Verify on, the panel shows the result as soon as the worker has written it and the worker
goes on to verify it; meanwhile the study is usable (settings, threshold) and Stop stops the
verification only. The verification's files and FEM objects arrive when it ends; a stopped or
crashed verification (TOPOPT_FAULT, test-only) leaves the result as it was. Screenshots go to
TOPOPT_SCREENSHOTS."""
import json
import os
import time
import unittest

import FreeCAD
import FreeCADGui
from PySide import QtGui

from gui_helpers import grab_window, open_workbench, scroll_to, settle
from app.helpers import top_loaded_box_study
from topopt.app import units
from topopt.gui import panels

SHOTS = os.environ.get("TOPOPT_SCREENSHOTS", "/tmp/topopt-screenshots")


def wait_for(panel, condition, seconds=600.0):
    """Processes events (the panel's queue included) until condition() or the time is up."""
    deadline = time.time() + seconds
    while not condition() and time.time() < deadline:
        QtGui.QApplication.processEvents()
        panel.poll()
        time.sleep(0.02)
    return condition()


class VerificationAfter(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        open_workbench()

    def setUp(self):
        os.environ.pop("TOPOPT_FAULT", None)
        self.doc, self.study = top_loaded_box_study("VerifyAfter")
        self.assertTrue(self.study.Verify)  # on by default
        self.panel = panels.open_study_panel(self.study)
        settle()

    def tearDown(self):
        os.environ.pop("TOPOPT_FAULT", None)
        if self.panel.is_open():
            self.panel.reject()
        FreeCAD.closeDocument(self.doc.Name)

    def start_until_result(self):
        """Starts a run whose verification hangs (TOPOPT_FAULT) and returns once the result is
        shown and the verification runs."""
        os.environ["TOPOPT_FAULT"] = "verification:hang"  # a verification that would never end
        self.panel.start_run()
        self.assertTrue(wait_for(self.panel, lambda: self.panel.verifying or self.panel.thread is None),
                        self.panel.status.text())
        self.check_result_shown()

    def check_result_shown(self):
        """The state right after the result is shown, the verification still to come."""
        self.assertTrue(self.panel.verifying, "no result-first stage: %s" % self.panel.status.text())
        study = self.study
        self.assertIsNotNone(study.Result)  # the result is there
        self.assertTrue(study.Result.Mesh.isSolid())
        self.assertIn("TopOpt run", self.doc.UndoNames)
        self.assertIsNone(study.VerificationResult)  # its verification is not yet
        self.assertEqual(units.prop(study, "ComplianceAsBuilt", "N*mm"), 0.0)
        self.assertIn("result.step", study.ResultFiles)
        self.assertNotIn("verification.vtu", study.ResultFiles)
        self.assertEqual(self.panel.progress.value(), 100)
        self.assertFalse(self.panel.run_button.isEnabled())
        self.assertTrue(self.panel.cancel_button.isEnabled())
        self.assertEqual(self.panel.cancel_button.text(), "Stop verification")
        self.assertTrue(self.panel.threshold.isEnabled())  # the study stays usable
        self.assertTrue(all(b.widget.isEnabled() for b in self.panel.bindings))

    def test_the_verification_arrives_after_the_result(self):
        shown = self.panel._show_result_first
        seen = []

        def at_result(result, ready):  # the verification may end before the next poll: look right here
            shown(result, ready)
            self.check_result_shown()
            volume = [b for b in self.panel.bindings if b.prop == "VolumeFraction"][0]
            volume.widget.setValue(0.35)  # edited while the verification runs
            self.assertAlmostEqual(self.study.VolumeFraction, 0.35)
            os.makedirs(SHOTS, exist_ok=True)
            self.panel.timer.stop()  # no poll while the screenshot is taken: the verification's end waits
            scroll_to(self.panel, self.panel.verify_status)
            grab_window(os.path.join(SHOTS, "verification_running.png"))
            self.assertTrue(self.panel.verifying)
            self.panel.timer.start()
            seen.append(True)
        self.panel._show_result_first = at_result
        self.panel.start_run()
        self.panel.wait(600)
        self.assertEqual(seen, [True])
        study = self.study
        self.assertIsNone(self.panel.thread)
        self.assertFalse(self.panel.verifying)
        self.assertIsNotNone(study.VerificationResult, self.panel.verify_status.text())
        self.assertGreater(units.prop(study, "ComplianceAsBuilt", "N*mm"), 0.0)
        self.assertEqual(sorted(study.ResultFiles), ["result.step", "verification.json", "verification.vtu"])
        report = json.loads(study.VerificationReport)
        self.assertIn("compliance_as_built", report)
        self.assertIn("threshold", report["step"])  # the STEP's report kept through both parts
        self.assertEqual(report["failed"], {})
        self.assertTrue(self.panel.verify_status.text().startswith("verified in"), self.panel.verify_status.text())
        self.assertIn("TopOpt verification", self.doc.UndoNames)
        self.assertTrue(self.panel.run_button.isEnabled())
        self.assertEqual(self.panel.cancel_button.text(), "Stop")
        self.assertAlmostEqual(study.VolumeFraction, 0.35)  # the edit made meanwhile stays
        scroll_to(self.panel, self.panel.verify_status)
        grab_window(os.path.join(SHOTS, "verification_done.png"))

    def test_stop_during_the_verification_keeps_the_result(self):
        self.start_until_result()
        shape = (self.study.Result.Mesh.CountFacets, self.study.Result.Mesh.Volume)
        self.panel.cancel_button.click()
        self.panel.wait(60)
        self.assertIsNone(self.panel.thread)
        self.assertEqual(self.panel.verify_status.text(), "verification stopped; the result stays")
        self.assertIsNotNone(self.study.Result)
        self.assertEqual((self.study.Result.Mesh.CountFacets, self.study.Result.Mesh.Volume), shape)
        self.assertIsNone(self.study.VerificationResult)
        self.assertEqual(self.study.ResultFiles, ["result.step", "verification.json"])
        self.assertTrue(self.panel.run_button.isEnabled())
        self.assertNotIn("TopOpt verification", self.doc.UndoNames)

    def test_a_crashed_verification_is_said_and_the_result_stays(self):
        os.environ["TOPOPT_FAULT"] = "verification:abort"  # may end before the panel looks: not awaited
        self.panel.start_run()
        self.panel.wait(600)
        self.assertIsNone(self.panel.thread)
        self.assertTrue(self.panel.verify_status.text().startswith("verification failed:"),
                        self.panel.verify_status.text())
        self.assertIn("result stays", self.panel.verify_status.text())
        self.assertIsNotNone(self.study.Result)
        self.assertTrue(self.study.Result.Mesh.isSolid())
        self.assertIn("TopOpt run", self.doc.UndoNames)
        self.assertIsNone(self.study.VerificationResult)
        self.assertTrue(self.panel.run_button.isEnabled())


if __name__ == "__main__":
    unittest.main()
