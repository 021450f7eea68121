"""Objectives and limits through the Python API: api.set_responses writes the study's
Responses, the job carries them as the optimization keys the core reads, every value is
checked by the core's own job parser (the same messages as a job file) before the study
changes, and displacement limits take picked faces of the part or of a non-design solid."""
import json
import unittest

import FreeCAD
import Part
from helpers import box_study

from topopt.app import api
from topopt.app.errors import TopOptError


class Responses(unittest.TestCase):
    def setUp(self):
        self.doc, self.study = box_study("Responses")
        pad = self.doc.addObject("Part::Feature", "Pad")
        pad.Shape = Part.makeBox(5, 10, 10, FreeCAD.Vector(55, 0, 0))
        self.doc.recompute()
        self.study.NonDesign = [pad]
        self.pad = pad

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_mass_with_limits_reaches_the_job(self):
        r = api.set_responses(self.study, objective="mass", compliance_limit=50.0, stress_limit=200,
                              displacement_limits=[("Face2", (0, 0, -1), 0.5),
                                                   ([(self.pad, ("Face2",))], (0, 0, -2), 0.8)])
        opt = api.job_of(self.study)["optimization"]
        self.assertEqual(opt["objective"], "mass")
        self.assertEqual(opt["compliance_limit"], 50.0)
        self.assertEqual(opt["stress_limit"], 200.0)
        self.assertEqual(opt["update"], "mma")
        self.assertEqual(self.study.Update, "mma")  # OC cannot: the study says so itself
        self.assertEqual(opt["displacement_limits"][0], {"faces": ["Face2"], "direction": [0, 0, -1], "limit": 0.5})
        self.assertEqual(opt["displacement_limits"][1]["faces"], ["NonDesign:Face2"])
        self.assertEqual(json.loads(self.study.Responses), r)

    def test_default_clears(self):
        api.set_responses(self.study, objective="frequency")
        self.assertEqual(api.job_of(self.study)["optimization"]["objective"], "frequency")
        api.set_responses(self.study)
        self.assertEqual(self.study.Responses, "")
        self.assertNotIn("objective", api.job_of(self.study)["optimization"])

    def test_bad_values_are_named_as_in_a_job_file_and_change_nothing(self):
        cases = [
            (dict(objective="mass"), "needs a limit"),
            (dict(objective="lightest"), "objective"),
            (dict(compliance_limit=10.0), "compliance_limit"),  # with "mass" only
            (dict(objective="mass", stress_limit=-5), "stress_limit"),
            (dict(objective="mass", compliance_limit=float("nan")), "compliance_limit"),
            (dict(displacement_limits=[("Face2", (0, 0, 0), 0.5)]), "direction"),
            (dict(displacement_limits=[("Face2", (0, 0, 1), 0)]), "limit"),
            (dict(displacement_limits=[("Face9", (0, 0, 1), 1)]), "Face9"),
            (dict(displacement_limits=[([(self.study.Part, ("Vertex3",))], (0, 0, 1), 1)]), "pick a face"),
        ]
        for kwargs, words in cases:
            with self.subTest(kwargs=kwargs):
                with self.assertRaises(TopOptError) as ctx:
                    api.set_responses(self.study, **kwargs)
                self.assertIn(words, str(ctx.exception))
                self.assertEqual(self.study.Responses, "")
                self.assertEqual(self.study.Update, "oc")

    def test_controls_go_through_the_job_parser_with_the_responses(self):
        api.set_controls(self.study, extrusion=(0, 1, 0))
        self.study.Responses = '{"objective": "mass"}'  # hand-written, without the limit "mass" needs
        with self.assertRaises(TopOptError) as ctx:
            api.set_controls(self.study, extrusion=(0, 0, 1))
        self.assertIn("needs a limit", str(ctx.exception))
        self.assertEqual(json.loads(self.study.GeometryControls), {"extrusion": [0.0, 1.0, 0.0]})


if __name__ == "__main__":
    unittest.main()
