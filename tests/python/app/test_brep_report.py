"""The native module inside FreeCADCmd: numbering agrees with FreeCAD's, bad input raises."""
import unittest

import FreeCAD
import Part

import topopt
from topopt.app import api
from helpers import example


class NumberingAgreesWithFreeCAD(unittest.TestCase):
    def check_faces(self, shape, faces_detail):
        self.assertEqual(len(shape.Faces), len(faces_detail))
        for k, face in enumerate(shape.Faces):
            d = faces_detail[k]
            self.assertEqual(d["name"], "Face%d" % (k + 1))
            self.assertAlmostEqual(d["area"], face.Area, delta=1e-7 * max(1.0, face.Area))
            c = face.CenterOfMass
            for a, b in zip(d["centre"], (c.x, c.y, c.z)):
                self.assertAlmostEqual(a, b, delta=1e-6)

    def test_examples_part_faces(self):
        for name in ("rocker", "cantilever", "bracket"):
            part = Part.read(example(name + ".step"))
            nd = Part.read(example(name + "_nondesign.step"))
            report = api.info(part, nd)
            self.check_faces(part, report["part"]["faces_detail"])
            self.assertAlmostEqual(report["part"]["volume"], part.Volume, delta=1e-6 * part.Volume)
            self.assertEqual(len(report["nondesign"]["solids"]), len(nd.Solids))
            for s, solid in zip(report["nondesign"]["solids"], nd.Solids):
                self.assertAlmostEqual(s["volume"], solid.Volume, delta=1e-6 * solid.Volume)

    def test_nondesign_faces_point_at_the_right_part_faces(self):
        part = Part.read(example("rocker.step"))
        nd = Part.read(example("rocker_nondesign.step"))
        report = api.info(part, nd)
        for s in report["nondesign"]["solids"]:
            for f in s["faces"]:
                if f["on"] != "face":
                    continue
                # Every tessellation point of the non-design face lies on the named part face.
                target = part.getElement(f["on_entity"])
                points = nd.Faces[int(f["name"][4:]) - 1].tessellate(0.2)[0]
                self.assertGreater(len(points), 2)
                for p in points[:: max(1, len(points) // 12)]:
                    self.assertLess(target.distToShape(Part.Vertex(p))[0], 1e-6, f["name"])

    def test_list_of_solids_is_the_same_as_a_compound(self):
        part = Part.read(example("bracket.step"))
        nd = Part.read(example("bracket_nondesign.step"))
        a = api.info(part, nd)
        b = api.info(part, list(nd.Solids))
        self.assertEqual(a["contacts"], b["contacts"])
        self.assertEqual(len(a["contacts"]), 1)


class BadInput(unittest.TestCase):
    def assertFails(self, code, words, part, nd=None):
        with self.assertRaises(api.TopOptError) as ctx:
            api.info(part, nd)
        self.assertEqual(ctx.exception.code, code)
        self.assertIn(words, str(ctx.exception))

    def test_not_a_solid(self):
        face = Part.makePlane(10, 10)
        self.assertFails("InvalidShape", "not a solid", face)

    def test_open_shell(self):
        box = Part.makeBox(10, 10, 10)
        shell = Part.Shell(box.Faces[:5])
        self.assertFails("InvalidShape", "open shell", Part.makeBox(20, 20, 20, FreeCAD.Vector(-5, -5, -5)), shell)

    def test_sticking_out(self):
        self.assertFails("NonDesignOutside", "non-design solid 1 is not inside the part",
                         Part.makeBox(10, 10, 10), Part.makeBox(5, 5, 5, FreeCAD.Vector(8, 2, 2)))

    def test_overlap(self):
        self.assertFails("NonDesignOverlap", "non-design solids 1 and 2 overlap",
                         Part.makeBox(10, 10, 10),
                         [Part.makeBox(4, 4, 4, FreeCAD.Vector(1, 1, 1)), Part.makeBox(4, 4, 4, FreeCAD.Vector(3, 3, 3))])

    def test_not_a_shape(self):
        with self.assertRaises(api.TopOptError):
            api.info("not a shape")

    def test_native_error_type_is_a_runtime_error(self):
        native = topopt.native()
        with self.assertRaises(RuntimeError) as ctx:
            native.info("garbage", "")
        self.assertEqual(ctx.exception.code, "Io")


if __name__ == "__main__":
    unittest.main()
