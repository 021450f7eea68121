"""Studies in FreeCADCmd: built from script, turned into jobs, saved and reloaded intact."""
import os
import tempfile
import unittest

import FreeCAD
import Part

import topopt
from topopt.app import api, units
from topopt.app.study import STEP_MAX_TRIANGLES, is_study
from helpers import bundled


def lever_document():
    doc = FreeCAD.newDocument("LeverStudy")
    part = doc.addObject("Part::Feature", "Lever")
    part.Shape = Part.read(bundled("lever.step"))
    nd = Part.read(bundled("lever_nondesign.step"))
    objs = []
    for i, solid in enumerate(nd.Solids):
        o = doc.addObject("Part::Feature", "Keep%d" % (i + 1))
        o.Shape = solid
        objs.append(o)
    doc.recompute()
    return doc, part, objs


class StudyFromScript(unittest.TestCase):
    def setUp(self):
        self.doc, self.part, self.nd = lever_document()

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def make(self):
        study = api.new_study(self.doc, self.part, self.nd, volume_fraction=0.35, mesh_size=3.0)
        api.add_fixed(study, "Face9")
        api.add_force(study, ["Face10"], (0, -2000, 0))
        api.add_pressure(study, "Face4", -0.5, obj=self.nd[2])  # the pad face at y = 15
        api.add_symmetry(study, "Face5")
        api.add_fixed_components(study, "Face7", z=True)
        self.doc.recompute()
        return study

    def test_job_matches_what_was_set(self):
        job = api.job_of(self.make())
        self.assertEqual(job["supports"][0], {"type": "fixed", "faces": ["Face9"]})
        self.assertIn({"type": "symmetry", "faces": ["Face5"]}, job["supports"])
        self.assertIn({"type": "components", "faces": ["Face7"], "fix": ["z"]}, job["supports"])
        loads = job["load_cases"][0]["loads"]
        force = loads[0]
        self.assertEqual(force["faces"], ["Face10"])
        for a, b in zip(force["vector"], (0, -2000, 0)):
            self.assertAlmostEqual(a, b, places=9)
        # Face4 of the third non-design solid: faces of solids 1 and 2 come first (4 + 4).
        n_before = len(self.nd[0].Shape.Faces) + len(self.nd[1].Shape.Faces)
        self.assertEqual(loads[1], {"type": "pressure", "faces": ["NonDesign:Face%d" % (n_before + 4)],
                                    "value": -0.5})
        self.assertAlmostEqual(job["optimization"]["volume_fraction"], 0.35)
        self.assertEqual(job["mesh"]["size"], 3.0)
        self.assertEqual(job["mesh"]["mesher"], "auto")
        self.assertNotIn("wall_layers", job["mesh"])  # off unless asked for

    def test_joining_non_design_solids_is_on_unless_the_study_turns_it_off(self):
        study = self.make()
        self.assertIs(api.job_of(study)["result"]["join_non_design"], True)
        study.JoinNonDesign = False
        self.assertIs(api.job_of(study)["result"]["join_non_design"], False)

    def test_wall_layers_reach_the_job_and_are_checked(self):
        study = self.make()
        study.WallLayers = 2
        self.assertEqual(api.job_of(study)["mesh"]["wall_layers"], 2)
        study.WallLayers = 7
        with self.assertRaises(api.TopOptError) as ctx:
            api.job_of(study)
        self.assertIn("WallLayers is 7, outside [0, 4]", str(ctx.exception))

    def test_step_budget_reaches_the_job_and_is_checked(self):
        # a new study's budget is the core's own default (StepExportParams::max_triangles), not a
        # copy that may drift from it
        self.assertEqual(STEP_MAX_TRIANGLES, topopt.native().STEP_MAX_TRIANGLES)
        study = self.make()
        self.assertEqual(api.job_of(study)["output"]["step_max_triangles"], STEP_MAX_TRIANGLES)
        study.StepMaxTriangles = 0  # no budget
        self.assertEqual(api.job_of(study)["output"]["step_max_triangles"], 0)
        study.StepMaxTriangles = -5
        with self.assertRaises(api.TopOptError) as ctx:
            api.job_of(study)
        self.assertIn("StepMaxTriangles", str(ctx.exception))

    def test_native_mesh_is_tagged_with_the_brep_volumes(self):
        # the 14-step mesher through the study: every domain's tet volume is its solid's
        # (FreeCAD's own figure) within 0.5 %, and the pad faces on the part's boundary are tagged
        from topopt.app import runner
        import numpy as np
        study = self.make()
        study.Mesher = "native"
        result = runner.mesh_only(study)
        self.assertEqual(list(result["warnings"]), [])  # meshed natively, no fallback to Gmsh
        X, T, dom = result["nodes"], result["tets"], result["domain"]
        a, b, c = (X[T[:, k]] - X[T[:, 0]] for k in (1, 2, 3))
        vol = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
        self.assertGreater(vol.min(), 0.0)
        expected = [self.part.Shape.Volume - sum(o.Shape.Volume for o in self.nd)] + [o.Shape.Volume for o in self.nd]
        self.assertEqual(sorted(set(dom.tolist())), list(range(len(expected))))
        for d, v in enumerate(expected):
            self.assertAlmostEqual(vol[dom == d].sum() / v, 1.0, delta=0.005, msg="domain %d" % d)
        nd_faces = result["boundary_nondesign_faces"]
        self.assertEqual(len(nd_faces), len(result["boundary_triangles"]))
        self.assertGreater((nd_faces > 0).sum(), 0)
        self.assertLessEqual(nd_faces.max(), sum(len(o.Shape.Faces) for o in self.nd))

    def test_save_and_reload(self):
        study = self.make()
        study.ComplianceHistory = [10.0, 8.0, 7.5]
        study.Densities = [0.5, 1.0]
        units.set_prop(study, "ComplianceCrisp", 3.25, "N*mm")
        path = os.path.join(tempfile.mkdtemp(), "lever_study.FCStd")
        self.doc.saveAs(path)
        name = self.doc.Name
        FreeCAD.closeDocument(name)
        self.doc = FreeCAD.openDocument(path)
        studies = [o for o in self.doc.Objects if is_study(o)]
        self.assertEqual(len(studies), 1)
        s = studies[0]
        self.assertEqual(s.Part.Name, "Lever")
        self.assertEqual([o.Name for o in s.NonDesign], ["Keep1", "Keep2", "Keep3"])
        self.assertEqual(len(s.Constraints), 5)
        self.assertEqual(list(s.ComplianceHistory), [10.0, 8.0, 7.5])
        self.assertAlmostEqual(s.VolumeFraction, 0.35)
        # a work again after reopening (FreeCAD 0.20 saves a quantity property's value only)
        self.assertEqual(s.ComplianceCrisp.Unit, FreeCAD.Units.Quantity("1 mJ").Unit)
        self.assertAlmostEqual(units.prop(s, "ComplianceCrisp", "N*mm"), 3.25)
        self.assertEqual(s.ComplianceCrisp.UserString, "3.25 mJ")
        self.assertEqual(api.job_of(s)["supports"][0]["faces"], ["Face9"])


class StudyBadInput(unittest.TestCase):
    def setUp(self):
        self.doc, self.part, self.nd = lever_document()

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def code_of(self, f):
        with self.assertRaises(api.TopOptError) as ctx:
            f()
        return ctx.exception.code, str(ctx.exception)

    def test_no_support(self):
        study = api.new_study(self.doc, self.part, self.nd)
        api.add_force(study, "Face10", (0, -1, 0))
        code, msg = self.code_of(lambda: api.job_of(study))
        self.assertEqual(code, "NoSupport")
        self.assertIn("add a fixed support", msg)

    def test_face_that_does_not_exist(self):
        study = api.new_study(self.doc, self.part, self.nd)
        code, msg = self.code_of(lambda: api.add_fixed(study, "Face99"))
        self.assertEqual(code, "FaceNotFound")
        self.assertIn("Face1 to Face10", msg)

    def test_volume_fraction_out_of_range(self):
        for vf in (0.0, 1.0, 1.5, -0.2):
            code, _ = self.code_of(lambda: api.new_study(self.doc, self.part, self.nd, volume_fraction=vf))
            self.assertEqual(code, "InvalidParameter")

    def test_constraint_on_a_foreign_object(self):
        other = self.doc.addObject("Part::Box", "Other")
        self.doc.recompute()
        study = api.new_study(self.doc, self.part, self.nd)
        api.add_fixed(study, "Face1", obj=other)
        api.add_force(study, "Face10", (0, -1, 0))
        code, msg = self.code_of(lambda: api.job_of(study))
        self.assertEqual(code, "FaceNotFound")
        self.assertIn("neither the study's part", msg)


if __name__ == "__main__":
    unittest.main()
