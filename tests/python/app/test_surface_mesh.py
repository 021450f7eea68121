"""The native surface mesher from FreeCADCmd: closed per solid, faces tagged with FreeCAD's
numbers (tagged areas equal FreeCAD's face areas), and the result as a Mesh feature whose
volume equals the solid's."""
import unittest

import FreeCAD
import Part

from topopt.app import api
from topopt.app.errors import TopOptError
from helpers import example


class SurfaceMesh(unittest.TestCase):
    def test_rocker_faces_and_volume(self):
        part = Part.read(example("rocker.step"))
        doc = FreeCAD.newDocument("surface")
        try:
            r, feature = api.surface_mesh(part, 2.0, doc=doc)
            self.assertEqual(r["failed_faces"], [])
            self.assertEqual(list(r["open_edges_per_solid"]), [0])
            self.assertEqual(r["self_intersecting_pairs"], 0)
            self.assertGreater(r["min_angle"], 20)
            # tagged areas against FreeCAD's own face areas (numbering agrees)
            areas = [0.0] * len(part.Faces)
            for (a, b, c), f in zip(r["triangles"], r["faces"]):
                pa, pb, pc = (FreeCAD.Vector(*map(float, r["nodes"][i])) for i in (a, b, c))
                areas[int(f) - 1] += 0.5 * (pb - pa).cross(pc - pa).Length
            for k, face in enumerate(part.Faces):
                self.assertAlmostEqual(areas[k], face.Area, delta=0.02 * face.Area, msg="Face%d" % (k + 1))
            self.assertTrue(feature.Mesh.isSolid())
            self.assertAlmostEqual(feature.Mesh.Volume, part.Volume, delta=0.01 * part.Volume)
        finally:
            FreeCAD.closeDocument(doc.Name)

    def test_bad_size_is_an_error(self):
        with self.assertRaises(TopOptError):
            api.surface_mesh(Part.makeBox(1, 1, 1), -1.0)


if __name__ == "__main__":
    unittest.main()
