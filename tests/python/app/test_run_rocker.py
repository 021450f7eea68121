"""A study on the rocker built from script in FreeCADCmd, run end to end (mesh → SIMP →
result surface), its result checked, saved, reloaded and found intact."""
import os
import tempfile
import unittest

import FreeCAD
import Part

from topopt.app import api
from topopt.app.errors import TopOptError
from topopt.app.study import is_study
from helpers import example


def rocker_document():
    doc = FreeCAD.newDocument("Rocker")
    part = doc.addObject("Part::Feature", "Rocker")
    part.Shape = Part.read(example("rocker.step"))
    keep = []
    for i, solid in enumerate(Part.read(example("rocker_nondesign.step")).Solids):
        o = doc.addObject("Part::Feature", "Ring%d" % (i + 1))
        o.Shape = solid
        keep.append(o)
    doc.recompute()
    return doc, part, keep


def make_study(doc, part, keep, iterations=12):
    study = api.new_study(doc, part, keep, volume_fraction=0.3, mesh_size=3.0)
    study.MaxIterations = iterations
    api.add_fixed(study, "Face10")                  # bore at (0, 0)
    api.add_force(study, ["Face9"], (0, -1000, 0))  # bore at (80, 10)
    api.add_force(study, ["Face11"], (600, 0, 0))   # bore at (40, 55)
    doc.recompute()
    return study


class RunRocker(unittest.TestCase):
    def setUp(self):
        self.doc, self.part, self.keep = rocker_document()

    def tearDown(self):
        for name in list(FreeCAD.listDocuments()):
            FreeCAD.closeDocument(name)

    def test_run_save_reload(self):
        study = make_study(self.doc, self.part, self.keep)
        records = []
        result = api.run(study, lambda r: records.append(r))
        self.assertTrue(any("iteration" in r for r in records))
        self.assertTrue(any(r.get("stage") == "mesh" for r in records))
        mesh = result.Mesh
        self.assertTrue(mesh.isSolid(), "the result shape must be closed")
        self.assertFalse(mesh.hasNonManifolds())
        nd_volume = sum(o.Shape.Volume for o in self.keep)
        target = 0.3 * (self.part.Shape.Volume - nd_volume) + nd_volume
        # the mesh's volume is the exact target before smoothing; smoothing moves it a little,
        # and the tet mesh's faceted bores differ from the B-Rep's by a fraction of a percent
        self.assertAlmostEqual(mesh.Volume / target, 1.0, delta=0.03)
        # the rings are kept: every ring's bore surface is inside the result's bounding box
        for o in self.keep:
            self.assertTrue(mesh.BoundBox.isInside(o.Shape.BoundBox.Center))
        n_dens, n_hist = len(study.Densities), len(study.ComplianceHistory)
        self.assertEqual(n_dens, len(study.MeshTets) // 4)
        self.assertGreater(n_hist, 1)
        self.assertLess(study.ComplianceHistory[-1], study.ComplianceHistory[0])
        name, volume = study.Name, mesh.Volume
        path = os.path.join(tempfile.mkdtemp(), "rocker_study.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        doc = FreeCAD.openDocument(path)
        again = doc.getObject(name)
        self.assertTrue(is_study(again))
        self.assertEqual(len(again.Densities), n_dens)
        self.assertEqual(len(again.ComplianceHistory), n_hist)
        self.assertIsNotNone(again.Result)
        self.assertAlmostEqual(again.Result.Mesh.Volume, volume, places=3)
        self.assertEqual(again.Part.Name, "Rocker")
        # the threshold slider's path: re-extract from the stored densities without a run
        from topopt.app import runner
        thicker = runner.reextract(again, 0.2)
        self.assertTrue(thicker.Mesh.isSolid())
        self.assertGreater(thicker.Mesh.Volume, volume)

    def test_cancel_keeps_the_document(self):
        study = make_study(self.doc, self.part, self.keep, iterations=50)
        with self.assertRaises(TopOptError) as ctx:
            api.run(study, lambda r: r.get("iteration", 0) >= 2)
        self.assertEqual(ctx.exception.code, "Cancelled")
        self.assertIsNone(study.Result)
        self.assertIn(study.Name, [o.Name for o in self.doc.Objects])

    def test_no_support_is_named(self):
        study = api.new_study(self.doc, self.part, self.keep, volume_fraction=0.3, mesh_size=4.0)
        api.add_force(study, ["Face9"], (0, -1000, 0))
        self.doc.recompute()
        with self.assertRaises(TopOptError) as ctx:
            api.run(study)
        self.assertEqual(ctx.exception.code, "NoSupport")


if __name__ == "__main__":
    unittest.main()
