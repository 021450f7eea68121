"""Faults of the core end the worker process, never FreeCAD. For each fault kind the worker can
be told to simulate (TOPOPT_FAULT, test-only: abort, access violation, hang + Cancel) at a
meshing stage and at an optimisation stage, FreeCAD carries on, the error names the stage and
what to try, no worker process is left, and the document is exactly as before (same objects,
same property values, the study's earlier result untouched), and it saves and reloads."""
import os
import tempfile
import time
import unittest

import FreeCAD

from topopt.app import api, runner
from topopt.app.errors import TopOptError
from helpers import box_study, snapshot, worker_children


class WorkerFaults(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.environ.pop("TOPOPT_FAULT", None)
        cls.doc, cls.study = box_study("Faults")
        api.run(cls.study)  # a first result, which every failed call must leave as it was
        cls.result_volume = cls.study.Result.Mesh.Volume
        cls.before = snapshot(cls.doc)

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def tearDown(self):
        os.environ.pop("TOPOPT_FAULT", None)

    def fail_with(self, fault, call=None, hang_seconds=None):
        """Runs the study (or `call`) with TOPOPT_FAULT=fault; returns the TopOptError. With
        hang_seconds, cancels that long after the fault's stage was reported (like a user
        pressing Cancel on a run that has gone silent) and checks that the cancel was prompt."""
        os.environ["TOPOPT_FAULT"] = fault
        stage = fault.split(":")[0].split("/")[0]
        seen = {}

        def on_progress(record):
            if record.get("stage") == stage or ("iteration" in record and stage == "simp"):
                seen.setdefault("at", time.monotonic())

        def cancel():
            return hang_seconds is not None and "at" in seen and time.monotonic() > seen["at"] + hang_seconds

        with self.assertRaises(TopOptError) as ctx:
            (call or (lambda: api.run(self.study, on_progress, cancel)))()
        if hang_seconds is not None:
            self.assertLess(time.monotonic() - seen["at"], hang_seconds + 2.0, "Cancel must end the worker at once")
        return ctx.exception

    def assertSurvivedIntact(self, error):
        self.assertEqual(worker_children(), [], "no worker process may be left behind")
        self.assertEqual(snapshot(self.doc), self.before, "the document must be exactly as before")
        self.assertAlmostEqual(self.study.Result.Mesh.Volume, self.result_volume, places=9)
        self.doc.recompute()  # FreeCAD still works
        if error.code == "WorkerCrashed":
            self.assertIn("your document is unchanged", str(error))

    def test_abort_while_meshing(self):
        e = self.fail_with("mesh/faces:abort")
        self.assertEqual(e.code, "WorkerCrashed")
        self.assertEqual(e.stage, "mesh")
        self.assertIn("the mesher crashed (aborted, SIGABRT) while meshing (faces): try another mesher "
                      "(the study's Mesher 'gmsh' or 'native') or another mesh size; your document is unchanged", str(e))
        self.assertSurvivedIntact(e)

    def test_access_violation_while_meshing(self):
        e = self.fail_with("mesh/faces:segv")
        self.assertEqual(e.code, "WorkerCrashed")
        self.assertIn("the mesher crashed (access violation, SIGSEGV) while meshing (faces)", str(e))
        self.assertSurvivedIntact(e)

    def test_abort_while_optimising(self):
        e = self.fail_with("simp:abort")
        self.assertEqual(e.code, "WorkerCrashed")
        self.assertEqual(e.stage, "simp")
        self.assertIn("the optimiser crashed (aborted, SIGABRT) while optimising (iteration 1): try a coarser mesh "
                      "size or fewer iterations; your document is unchanged", str(e))
        self.assertSurvivedIntact(e)

    def test_access_violation_while_optimising(self):
        e = self.fail_with("simp:segv")
        self.assertEqual(e.code, "WorkerCrashed")
        self.assertIn("the optimiser crashed (access violation, SIGSEGV) while optimising (iteration 1)", str(e))
        self.assertSurvivedIntact(e)

    def test_hang_while_meshing_then_cancel(self):
        e = self.fail_with("mesh/faces:hang", hang_seconds=1.0)
        self.assertEqual(e.code, "Cancelled")
        self.assertEqual(str(e), "cancelled while meshing (faces)")
        self.assertSurvivedIntact(e)

    def test_hang_while_optimising_then_cancel(self):
        e = self.fail_with("simp:hang", hang_seconds=1.0)
        self.assertEqual(e.code, "Cancelled")
        self.assertEqual(str(e), "cancelled while optimising (iteration 1)")
        self.assertSurvivedIntact(e)

    def test_crash_while_re_extracting(self):
        e = self.fail_with("surface:segv", lambda: runner.reextract(self.study, 0.25))
        self.assertEqual(e.code, "WorkerCrashed")
        self.assertIn("the result-shape extraction crashed (access violation, SIGSEGV) while extracting the result "
                      "shape: try another threshold; your document is unchanged", str(e))
        self.assertSurvivedIntact(e)

    def test_hang_while_re_extracting_times_out(self):
        saved, runner.REEXTRACT_TIMEOUT = runner.REEXTRACT_TIMEOUT, 4.0
        try:
            e = self.fail_with("surface:hang", lambda: runner.reextract(self.study, 0.25))
        finally:
            runner.REEXTRACT_TIMEOUT = saved
        self.assertEqual(e.code, "Timeout")
        self.assertIn("did not finish within 4 s while extracting the result shape", str(e))
        self.assertSurvivedIntact(e)

    def test_abort_while_checking_shapes(self):
        e = self.fail_with("brep:abort", lambda: api.info(self.study.Part.Shape))
        self.assertEqual(e.code, "WorkerCrashed")
        self.assertIn("the geometry kernel (OCCT) crashed (aborted, SIGABRT) while checking the shapes", str(e))
        self.assertSurvivedIntact(e)

    def test_zz_document_saves_and_reloads(self):
        # after every fault above (alphabetical order puts this test last)
        self.fail_with("mesh/faces:segv")
        path = os.path.join(tempfile.mkdtemp(), "faults.FCStd")
        name = self.study.Name
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        doc = type(self).doc = FreeCAD.openDocument(path)
        self.assertEqual(snapshot(doc), self.before)  # the same objects with the same values
        again = doc.getObject(name)
        self.assertAlmostEqual(again.Result.Mesh.Volume, self.result_volume, places=6)
        self.assertTrue(runner.reextract(again, 0.3).Mesh.isSolid())  # and the worker still serves it


class ProgressCallback(unittest.TestCase):
    """What on_progress may do: return True to cancel, raise (its exception comes back as it is),
    and nothing else (a clear error)."""

    @classmethod
    def setUpClass(cls):
        os.environ.pop("TOPOPT_FAULT", None)
        cls.doc, cls.study = box_study("Callback")
        cls.before = snapshot(cls.doc)

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def test_true_cancels(self):
        with self.assertRaises(TopOptError) as ctx:
            api.run(self.study, lambda r: "iteration" in r)
        self.assertEqual(ctx.exception.code, "Cancelled")
        self.assertEqual(str(ctx.exception), "cancelled while optimising (iteration 1)")
        self.assertEqual(snapshot(self.doc), self.before)

    def test_an_exception_comes_back_as_itself(self):
        def broken(record):
            raise KeyError("the plot went away")
        with self.assertRaises(KeyError) as ctx:
            api.run(self.study, broken)
        self.assertIn("the plot went away", str(ctx.exception))
        self.assertEqual(worker_children(), [])
        self.assertEqual(snapshot(self.doc), self.before)

    def test_a_string_is_a_clear_error(self):
        with self.assertRaises(TopOptError) as ctx:
            api.run(self.study, lambda r: "stop")
        self.assertEqual(ctx.exception.code, "InvalidParameter")
        self.assertEqual(str(ctx.exception), "the progress callback returned 'stop' (str): it must return True "
                                             "(cancel), False or None")
        self.assertEqual(worker_children(), [])
        self.assertEqual(snapshot(self.doc), self.before)


if __name__ == "__main__":
    unittest.main()
