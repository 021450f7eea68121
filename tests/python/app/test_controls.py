"""Geometry controls through the Python API: api.set_controls writes the study's
GeometryControls, the job carries them as the "controls" object the core reads, bad arguments
are refused naming the argument, and a run with a control (in the worker) uses it: a mirror
plane that is no symmetry of the part is refused by the core naming the plane, and so is a base
plate face that does not face against the build direction."""
import unittest

import FreeCAD
import numpy as np

from topopt.app import api, runner
from helpers import box_study

# a unit cube in 6 tets: a stored result the threshold slider re-extracts
CUBE_NODES = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
CUBE_TETS = np.array([[0, 1, 3, 7], [0, 1, 7, 5], [0, 5, 7, 4], [0, 3, 2, 7], [0, 2, 6, 7], [0, 6, 4, 7]])


class Controls(unittest.TestCase):
    def setUp(self):
        self.doc, self.study = box_study("Controls", iterations=6, mesh_size=4.0)

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_controls_reach_the_job(self):
        self.assertNotIn("controls", api.job_of(self.study)["optimization"])
        api.set_controls(self.study, symmetry_planes=[((0, 5, 5), (0, 1, 1))],
                         cyclic=[((0, 5, 5), (1, 0, 0), 4)], patterns=[((1, 0, 0), 20, 3)],
                         extrusion=(0, 0, 1), tolerance=2)
        c = api.job_of(self.study)["optimization"]["controls"]
        self.assertEqual(c["symmetry_planes"], [{"point": [0, 5, 5], "normal": [0, 1, 1]}])
        self.assertEqual(c["cyclic"], [{"point": [0, 5, 5], "axis": [1, 0, 0], "sectors": 4}])
        self.assertEqual(c["patterns"], [{"direction": [1, 0, 0], "pitch": 20, "count": 3}])
        self.assertEqual(c["extrusion"], [0, 0, 1])
        self.assertEqual(c["tolerance"], 2)
        api.set_controls(self.study, draw_direction=(0, 0, 1), parting_point=(0, 0, 5), draw_cell=1.5)
        c = api.job_of(self.study)["optimization"]["controls"]
        self.assertEqual(c["draw_direction"], {"direction": [0, 0, 1], "parting_point": [0, 0, 5], "cell": 1.5})
        api.set_controls(self.study, draw_direction=(0, 1, 0))  # one-sided: no parting plane
        c = api.job_of(self.study)["optimization"]["controls"]
        self.assertEqual(c["draw_direction"], {"direction": [0, 1, 0]})
        api.set_controls(self.study, build_direction=(0, 0, 1), base_face="Face5", overhang_cell=2)
        c = api.job_of(self.study)["optimization"]["controls"]
        self.assertEqual(c["overhang"], {"direction": [0, 0, 1], "angle": 45, "base_face": "Face5", "cell": 2})
        api.set_controls(self.study, build_direction=(1, 0, 0), overhang_angle=50, base_face=1)
        c = api.job_of(self.study)["optimization"]["controls"]
        self.assertEqual(c["overhang"], {"direction": [1, 0, 0], "angle": 50, "base_face": "Face1"})
        api.set_controls(self.study)  # cleared
        self.assertEqual(self.study.GeometryControls, "")
        self.assertNotIn("controls", api.job_of(self.study)["optimization"])

    def test_member_sizes_reach_the_job_and_the_core_checks_them(self):
        self.assertEqual(self.study.Update, "oc")
        api.set_controls(self.study, min_member_size=10, max_member_size=24)
        opt = api.job_of(self.study)["optimization"]
        self.assertEqual(opt["controls"]["min_member_size"], 10)
        self.assertEqual(opt["controls"]["max_member_size"], 24)
        self.assertEqual(self.study.Update, "mma")  # the local volume constraint needs MMA
        for kwargs, words in [(dict(min_member_size=-1), "min_member_size"),
                              (dict(min_member_size=10, max_member_size=8), "max_member_size")]:
            with self.assertRaises(api.TopOptError) as ctx:
                api.set_controls(self.study, **kwargs)
            self.assertIn(words, str(ctx.exception))
        # 5 mm on a 4 mm mesh: below two mesh sizes, refused by the core once the mesh is known
        api.set_controls(self.study, min_member_size=5)
        with self.assertRaises(api.TopOptError) as ctx:
            api.run(self.study, verbose=False)
        self.assertIn("controls.min_member_size is below two mesh sizes", str(ctx.exception))

    def test_bad_arguments_name_what_to_fix(self):
        for kwargs, words in [(dict(symmetry_planes=[((0, 5, 5), (0, 0, 0))]), "symmetry plane 1 normal"),
                              (dict(cyclic=[((0, 0, 0), (1, 0, 0), 2.5)]), "cyclic 1 sectors"),
                              (dict(patterns=[((1, 0, 0), -3, 2)]), "pattern 1 pitch"),
                              (dict(extrusion=(1, 2)), "extrusion"),
                              (dict(draw_direction=(0, 0, 0)), "draw_direction"),
                              (dict(parting_point=(0, 0, 1)), "parting_point"),
                              (dict(draw_direction=(0, 0, 1), draw_cell=-1), "draw_cell"),
                              (dict(build_direction=(0, 0, 0)), "build_direction"),
                              (dict(build_direction=(0, 0, 1), overhang_angle=85), "overhang_angle"),
                              (dict(build_direction=(0, 0, 1), base_face="Top"), "is not a face name"),
                              (dict(base_face="Face5"), "base_face needs build_direction"),
                              (dict(build_direction=(0, 0, 1), overhang_cell=-1), "overhang_cell")]:
            with self.assertRaises(api.TopOptError) as ctx:
                api.set_controls(self.study, **kwargs)
            self.assertIn(words, str(ctx.exception))
        self.study.GeometryControls = "[1, 2]"
        with self.assertRaises(api.TopOptError) as ctx:
            api.job_of(self.study)
        self.assertIn("GeometryControls", str(ctx.exception))

    def test_the_slider_request_carries_the_build(self):
        # issue 22: the threshold slider re-extracts in the worker with the run's surface settings,
        # the study's job's optimization section (its overhang control: the lift)
        api.set_controls(self.study, build_direction=(0, 0, 1), overhang_angle=50)
        self.study.Densities = [1.0] * 6
        stored = (CUBE_NODES, CUBE_TETS, np.zeros(6, dtype=np.int32), np.ones(6))
        sent = {}

        def record(operation, **kwargs):
            sent.update(kwargs, operation=operation)
            return {}

        real = runner.worker.run
        runner.worker.run = record
        try:
            runner.extract_at(self.study, 0.5, stored=stored)
        finally:
            runner.worker.run = real
        self.assertEqual(sent["operation"], "extract_surface")
        # the whole job (issue 19: its supports and loads place the anchors the run cleaned by)
        self.assertEqual(sent["job"], api.job_of(self.study))
        self.assertEqual(sent["job"]["optimization"]["controls"]["overhang"], {"direction": [0, 0, 1], "angle": 50})
        # through the worker: the core reads it; a base face the stored mesh cannot place is said
        api.set_controls(self.study, build_direction=(0, 0, 1), base_face="Face5")
        answer = runner.extract_at(self.study, 0.5, stored=stored)
        self.assertEqual(len(answer["surface_triangles"]), 12)
        self.assertEqual(len([w for w in answer["warnings"] if "without the overhang lift" in w]), 1)
        # a stored mesh without its boundary (as here, or a document saved before it kept one):
        # the supports and loads cannot be placed, the largest piece is kept, and that is said
        self.assertEqual(len([w for w in answer["warnings"] if "may differ from the run's" in w]), 1)

    def test_the_core_uses_the_controls(self):
        api.set_controls(self.study, symmetry_planes=[((0, 40, 5), (0, 1, 0))])  # y = 40: off the part
        with self.assertRaises(api.TopOptError) as ctx:
            api.run(self.study, verbose=False)
        self.assertIn("symmetry plane 1", str(ctx.exception))
        api.set_controls(self.study, symmetry_planes=[((0, 5, 5), (0, 1, 0))], extrusion=(0, 0, 1))
        result = api.run(self.study, verbose=False)
        self.assertGreater(result.Mesh.CountFacets, 0)
        api.set_controls(self.study, draw_direction=(0, 0, 1), parting_point=(0, 0, 5))
        result = api.run(self.study, verbose=False)
        self.assertGreater(result.Mesh.CountFacets, 0)
        api.set_controls(self.study, build_direction=(0, 0, 1), base_face="Face6")  # the top: faces up, refused
        with self.assertRaises(api.TopOptError) as ctx:
            api.run(self.study, verbose=False)
        self.assertIn("Face6 is not a flat face facing against the build direction", str(ctx.exception))
        api.set_controls(self.study, build_direction=(0, 0, 1), base_face="Face5")
        result = api.run(self.study, verbose=False)
        self.assertGreater(result.Mesh.CountFacets, 0)


if __name__ == "__main__":
    unittest.main()
