"""Planes, axes and directions from picked elements (topopt.app.picking), as the study panel's
design controls and limits take them: a planar face or a datum plane gives a plane, a
cylindrical face or a circular edge its axis, a straight edge its direction; anything else is
refused with a message naming what was picked."""
import unittest

import FreeCAD
import Part

from topopt.app import picking
from topopt.app.errors import TopOptError


class Picking(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.doc = FreeCAD.newDocument("Picking")
        cls.box = cls.doc.addObject("Part::Feature", "Box")
        cls.box.Shape = Part.makeBox(60, 10, 20)
        cls.tube = cls.doc.addObject("Part::Feature", "Tube")
        cls.tube.Shape = Part.makeCylinder(5, 30, FreeCAD.Vector(100, 0, 0), FreeCAD.Vector(1, 0, 0))
        cls.datum = cls.doc.addObject("Part::Feature", "Datum")
        cls.datum.Shape = Part.makePlane(40, 40, FreeCAD.Vector(0, 0, 7), FreeCAD.Vector(0, 0, 1))
        cls.doc.recompute()

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def close(self, got, expected):
        self.assertEqual(len(got), 3)
        for g, e in zip(got, expected):
            self.assertAlmostEqual(g, e, places=9)

    def test_plane_of_a_planar_face_and_of_a_datum_plane(self):
        point, normal = picking.plane_of(self.box, "Face4")  # y = 10
        self.close(point, [30, 10, 10])
        self.close(normal, [0, 1, 0])
        point, normal = picking.plane_of(self.datum)  # picked in the tree: the object itself
        self.assertAlmostEqual(point[2], 7)
        self.close([abs(x) for x in normal], [0, 0, 1])

    def test_axis_of_a_cylinder_a_circle_and_a_line(self):
        point, axis = picking.axis_of(self.tube, "Face1")
        self.assertAlmostEqual(point[1], 0)
        self.assertAlmostEqual(point[2], 0)
        self.close([abs(x) for x in axis], [1, 0, 0])
        circles = [e for e in self.tube.Shape.Edges if type(e.Curve).__name__ == "Circle"]
        name = "Edge%d" % next(i + 1 for i, e in enumerate(self.tube.Shape.Edges) if e.isSame(circles[0]))
        point, axis = picking.axis_of(self.tube, name)
        self.close([abs(x) for x in axis], [1, 0, 0])
        point, axis = picking.axis_of(self.box, "Edge1")  # the edge x = y = 0 along z (either way)
        self.close(point[:2] + [0], [0, 0, 0])
        self.close([abs(x) for x in axis], [0, 0, 1])

    def test_direction_of_a_face_and_an_edge(self):
        self.close(picking.direction_of(self.box, "Face6"), [0, 0, 1])
        self.close([abs(x) for x in picking.direction_of(self.box, "Edge1")], [0, 0, 1])  # a unit vector

    def test_wrong_picks_are_named(self):
        cases = [(picking.plane_of, self.tube, "Face1", "Face1 of Tube is not planar"),
                 (picking.plane_of, self.box, "Edge1", "Edge1 of Box is not planar"),
                 (picking.axis_of, self.box, "Face1", "Face1 of Box has no axis"),
                 (picking.direction_of, self.tube, "Face1", "gives no direction"),
                 (picking.plane_of, self.box, "Face99", "Box has no Face99"),
                 (picking.plane_of, self.box, "", "Box is not a datum plane or line")]
        for f, obj, sub, words in cases:
            with self.subTest(sub=sub):
                with self.assertRaises(TopOptError) as ctx:
                    f(obj, sub)
                self.assertIn(words, str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
