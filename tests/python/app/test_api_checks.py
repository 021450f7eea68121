"""The Python API checks what it is given before anything runs, and says what to fix: study
properties out of range or not finite (named), empty or wrong face lists (and no orphan
constraint left behind), a missing export folder, and the in-process calls of the core
(topopt.app.core) with indices out of range, lengths that do not match or NaN."""
import math
import os
import tempfile
import unittest

import FreeCAD
import numpy as np

from topopt.app import api, core, runner
from topopt.app.errors import TopOptError
from helpers import box_study, snapshot

# a unit cube: 8 nodes, 6 positive tets (Kuhn's split), and its 12 outward boundary triangles
CUBE_NODES = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
CUBE_TETS = np.array([[0, 1, 3, 7], [0, 1, 7, 5], [0, 5, 7, 4], [0, 3, 2, 7], [0, 2, 6, 7], [0, 6, 4, 7]])
CUBE_TRIS = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                      [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]])


class Fails:
    def error_of(self, f):
        with self.assertRaises(TopOptError) as ctx:
            f()
        return ctx.exception


class StudyProperties(Fails, unittest.TestCase):
    def setUp(self):
        self.doc, self.study = box_study("Props")

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_volume_fraction_zero_is_not_clamped(self):
        self.study.VolumeFraction = 0.0
        self.assertEqual(self.study.VolumeFraction, 0.0)  # kept as typed, not clamped to 0.01
        e = self.error_of(lambda: api.run(self.study))
        self.assertEqual(e.code, "InvalidParameter")
        self.assertEqual(str(e), "VolumeFraction is 0, outside (0, 1): give a value in that range")
        self.assertIsNone(self.study.Result)

    def test_volume_fraction_one_and_above(self):
        for vf in (1.0, 1.5):
            self.study.VolumeFraction = vf
            e = self.error_of(lambda: api.job_of(self.study))
            self.assertEqual(str(e), "VolumeFraction is %g, outside (0, 1): give a value in that range" % vf)

    def test_nan_and_infinity_are_named(self):
        for prop, value in (("YoungsModulus", float("nan")), ("Penalty", float("inf")),
                            ("MeshSize", float("nan")), ("VolumeFraction", float("nan"))):
            saved = getattr(self.study, prop)
            setattr(self.study, prop, value)
            e = self.error_of(lambda: api.job_of(self.study))
            self.assertEqual(str(e), "%s is %r: give a finite number" % (prop, float(value)))
            setattr(self.study, prop, saved)
        api.job_of(self.study)  # all restored: fine again

    def test_nan_in_a_force(self):
        # an older document's scripted force: its direction only in TopOptDirection
        force = [c for c in self.study.Constraints if c.TypeId == "Fem::ConstraintForce"][0]
        line = force.Direction[0]
        force.Direction = None
        self.doc.removeObject(line.Name)
        force.addProperty("App::PropertyVector", "TopOptDirection", "TopOpt", "")
        force.TopOptDirection = FreeCAD.Vector(float("nan"), 0, 1)
        e = self.error_of(lambda: api.job_of(self.study))
        self.assertEqual(str(e), "'%s': TopOptDirection must be a vector of three finite numbers (x, y, z), not "
                                 "Vector (nan, 0.0, 1.0)" % force.Label)

    def test_other_ranges(self):
        for prop, value, text in (("PoissonRatio", 0.5, "PoissonRatio is 0.5, outside (-1, 0.5)"),
                                  ("YoungsModulus", 0.0, "YoungsModulus is 0, outside (0, inf]"),
                                  ("MaxIterations", 0, "MaxIterations is 0, outside [1, 10000]")):
            saved = getattr(self.study, prop)
            setattr(self.study, prop, value)
            self.assertIn(text, str(self.error_of(lambda: api.job_of(self.study))))
            setattr(self.study, prop, saved)

    def test_new_study_checks_before_adding(self):
        part = self.study.Part
        names = [o.Name for o in self.doc.Objects]
        for vf in (0.0, 1.0, float("nan")):
            e = self.error_of(lambda: api.new_study(self.doc, part, (), volume_fraction=vf))
            self.assertIn("volume_fraction is", str(e))
        e = self.error_of(lambda: api.new_study(self.doc, part, (), mesh_size=-2))
        self.assertEqual(str(e), "mesh_size (mm, 0 for automatic) is -2, outside [0, inf]: give a value in that range")
        self.assertEqual([o.Name for o in self.doc.Objects], names)


class Constraints(Fails, unittest.TestCase):
    def setUp(self):
        self.doc, self.study = box_study("Cons")
        self.before = snapshot(self.doc)

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def assertNoOrphan(self):
        self.assertEqual(snapshot(self.doc), self.before)

    def test_empty_face_list(self):
        e = self.error_of(lambda: api.add_fixed(self.study, []))
        self.assertEqual(e.code, "FaceNotFound")
        self.assertEqual(str(e), "no faces given: name at least one face of Beam, like 'Face3'")
        self.assertNoOrphan()
        api.job_of(self.study)  # and later runs are not broken

    def test_bad_face_leaves_no_constraint(self):
        adders = [lambda: api.add_fixed(self.study, "Face99"),
                  lambda: api.add_fixed_components(self.study, ["Face1", "Face99"], z=True),
                  lambda: api.add_symmetry(self.study, "Face99"),
                  lambda: api.add_force(self.study, "Face99", (0, 0, 1)),
                  lambda: api.add_pressure(self.study, "Face99", 1.0),
                  lambda: api.add_pressure(self.study, "Edge3", 1.0)]
        for add in adders:
            e = self.error_of(add)
            self.assertEqual(e.code, "FaceNotFound")
            self.assertIn("Beam has no face '", str(e))
            self.assertIn("': it has Face1 to Face6", str(e))
            self.assertNoOrphan()

    def test_bad_values_leave_no_constraint(self):
        for add, text in ((lambda: api.add_force(self.study, "Face2", (0, float("nan"), 1)),
                           "the force's y component is nan: give a finite number"),
                          (lambda: api.add_force(self.study, "Face2", (0, 1)),
                           "the force must be a vector of three numbers (x, y, z in N), not (0, 1)"),
                          (lambda: api.add_force(self.study, "Face2", (0, 0, 0)),
                           "the force is zero: give a non-zero vector"),
                          (lambda: api.add_pressure(self.study, "Face2", float("inf")),
                           "the pressure is inf: give a finite number"),
                          (lambda: api.add_fixed_components(self.study, "Face2"),
                           "fix at least one component: pass x=True, y=True or z=True")):
            self.assertEqual(str(self.error_of(add)), text)
            self.assertNoOrphan()

    def test_faces_of_the_wrong_kind(self):
        e = self.error_of(lambda: api.add_fixed(self.study, 3))
        self.assertEqual(str(e), "faces must be a face name like 'Face3' or a list of them, not 3")
        e = self.error_of(lambda: api.add_fixed("not a study", "Face1"))
        self.assertEqual(e.code, "InvalidParameter")
        self.assertIn("is not a TopOpt study", str(e))
        self.assertNoOrphan()


class Results(Fails, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.doc, cls.study = box_study("Results", iterations=3)
        api.run(cls.study)

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def test_export_into_a_missing_folder(self):
        folder = os.path.join(tempfile.mkdtemp(), "not", "there")
        e = self.error_of(lambda: api.export_stl(self.study, os.path.join(folder, "beam.stl")))
        self.assertEqual(e.code, "Io")
        self.assertEqual(str(e), "the folder %s does not exist: create it or pick another folder for beam.stl" % folder)

    def test_export_writes(self):
        path = os.path.join(tempfile.mkdtemp(), "beam.stl")
        self.assertEqual(api.export_stl(self.study, path), path)
        self.assertGreater(os.path.getsize(path), 84)

    def test_damaged_stored_mesh_is_named(self):
        # what a corrupted or hand-edited .FCStd can hold: a tet naming a node that does not exist
        tets = list(self.study.MeshTets)
        try:
            bad = list(tets)
            bad[5] = len(self.study.MeshNodes) + 7
            self.study.MeshTets = bad
            result_before = snapshot(self.doc)
            e = self.error_of(lambda: runner.reextract(self.study, 0.4))
            self.assertEqual(e.code, "InvalidParameter")
            self.assertEqual(str(e), "the result stored in %s is damaged (MeshTets: row 1 holds %d, but there are %d "
                                     "nodes (indices 0 to %d)): run the study again"
                             % (self.study.Label, bad[5], len(self.study.MeshNodes), len(self.study.MeshNodes) - 1))
            self.assertEqual(snapshot(self.doc), result_before)
            bad[5] = -1
            self.study.MeshTets = bad
            self.assertIn("MeshTets: row 1 holds -1", str(self.error_of(lambda: runner.reextract(self.study, 0.4))))
            self.study.MeshTets = tets[:-1]
            self.assertIn("MeshTets holds %d numbers, not four per tet" % (len(tets) - 1),
                          str(self.error_of(lambda: runner.reextract(self.study, 0.4))))
        finally:
            self.study.MeshTets = tets
        for t in (0.0, 1.0, float("nan")):
            self.assertIn("threshold is", str(self.error_of(lambda: runner.reextract(self.study, t))))
        self.assertTrue(runner.reextract(self.study, 0.4).Mesh.isSolid())


class InProcessCalls(Fails, unittest.TestCase):
    """topopt.app.core: what stays in FreeCAD's process checks every argument first."""

    def test_extract_surface_of_a_cube(self):
        points, triangles = core.extract_surface(CUBE_NODES, CUBE_TETS, [], np.ones(6), threshold=0.5)
        self.assertEqual(len(points), 8)
        self.assertEqual(len(triangles), 12)

    def test_extract_surface_takes_the_jobs_optimization(self):
        # the run's surface settings: the section is read as the job parser reads it
        points, triangles = core.extract_surface(CUBE_NODES, CUBE_TETS, [], np.ones(6), threshold=0.5,
                                                 optimization={"smoothing_iterations": 0})
        self.assertEqual((len(points), len(triangles)), (8, 12))
        e = self.error_of(lambda: core.extract_surface(CUBE_NODES, CUBE_TETS, [], np.ones(6), threshold=0.5,
                                                       optimization={"smoothing_iterationz": 0}))
        self.assertIn("smoothing_iterationz", str(e))
        base = {"controls": {"overhang": {"direction": [0, 0, 1], "base_face": "Face5"}}}
        e = self.error_of(lambda: core.extract_surface(CUBE_NODES, CUBE_TETS, [], np.ones(6), threshold=0.5,
                                                       optimization=base))
        self.assertIn("without the overhang lift", str(e))

    def test_extract_surface_bad_arguments(self):
        dens = np.ones(6)
        past_the_end = CUBE_TETS.copy()
        past_the_end[2, 1] = 8
        cases = [((CUBE_NODES, past_the_end, [], dens), "tets: row 2 holds 8, but there are 8 nodes (indices 0 to 7)"),
                 ((CUBE_NODES, CUBE_TETS - 1, [], dens), "tets: row 0 holds -1, but there are 8 nodes"),
                 ((CUBE_NODES, CUBE_TETS, [0, 0], dens), "domain has 2 entries for 6 tets: give one per tet"),
                 ((CUBE_NODES, CUBE_TETS, [], np.ones(5)), "densities has 5 entries for 6 tets: give one per tet"),
                 ((CUBE_NODES * np.nan, CUBE_TETS, [], dens), "nodes: entry 0 is nan: every value must be a finite"),
                 ((CUBE_NODES[:, :2], CUBE_TETS, [], dens), "nodes must have 3 columns"),
                 ((CUBE_NODES, CUBE_TETS[:, :3], [], dens), "tets must have 4 columns"),
                 ((CUBE_NODES, CUBE_TETS * 0.5, [], dens), "tets must hold whole numbers (indices)")]
        for args, text in cases:
            e = self.error_of(lambda: core.extract_surface(*args, threshold=0.5))
            self.assertEqual(e.code, "InvalidParameter")
            self.assertIn(text, str(e))
        self.assertIn("give a threshold in (0, 1)",
                      str(self.error_of(lambda: core.extract_surface(CUBE_NODES, CUBE_TETS, [], dens))))
        self.assertIn("threshold is nan", str(self.error_of(
            lambda: core.extract_surface(CUBE_NODES, CUBE_TETS, [], dens, threshold=math.nan))))

    def test_volume_mesh(self):
        r = core.volume_mesh(CUBE_NODES, CUBE_TRIS)
        X, T = r["nodes"], r["tets"]
        a, b, c = (X[T[:, k]] - X[T[:, 0]] for k in (1, 2, 3))
        self.assertAlmostEqual(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0, 1.0, places=9)
        self.assertIn("triangles: row 0 holds 99", str(self.error_of(
            lambda: core.volume_mesh(CUBE_NODES, np.vstack([[0, 99, 3], CUBE_TRIS[1:]])))))
        self.assertIn("size is -1", str(self.error_of(lambda: core.volume_mesh(CUBE_NODES, CUBE_TRIS, -1))))

    def test_solve(self):
        job = {"material": {"E": 1000.0, "nu": 0.3},
               "supports": [{"type": "fixed", "faces": ["Face1"]}],
               "load_cases": [{"name": "pull", "loads": [{"type": "force", "faces": ["Face2"],
                                                          "vector": [10.0, 0.0, 0.0]}]}]}
        faces = np.array([3, 3, 4, 4, 5, 5, 6, 6, 1, 1, 2, 2])  # CUBE_TRIS' pairs; Face1: x = 0, Face2: x = 1
        r = core.solve(CUBE_NODES, CUBE_TETS, CUBE_TRIS, faces, [], job)
        self.assertGreater(r["compliance"][0], 0)
        self.assertIn("tri_face has 11 entries for 12 triangles", str(self.error_of(
            lambda: core.solve(CUBE_NODES, CUBE_TETS, CUBE_TRIS, faces[:-1], [], job))))
        self.assertIn("tris: row 0 holds 8", str(self.error_of(
            lambda: core.solve(CUBE_NODES, CUBE_TETS, CUBE_TRIS + 8, faces, [], job))))
        bad = dict(job, material={"E": float("nan"), "nu": 0.3})
        self.assertEqual(str(self.error_of(lambda: core.solve(CUBE_NODES, CUBE_TETS, CUBE_TRIS, faces, [], bad))),
                         "job.material.E is not a finite number (NaN or infinite): give a number")


if __name__ == "__main__":
    unittest.main()
