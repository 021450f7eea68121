"""Every binding checks its arguments before the core sees them: an index out of range or
negative, a NaN, a wrong shape or length is a TopOptError ("InvalidParameter") naming the
argument, never a crash of FreeCAD or garbage coordinates. The cases of issue 18:
extract_surface, solve and volume_mesh with an index past the nodes and a negative one."""
import itertools
import json
import unittest

import numpy as np

import topopt

native = topopt.native()


def cube():
    """The unit cube as 8 nodes, 6 positive tets (Kuhn), 12 outward boundary triangles and their
    faces numbered 1..6 (x=0, x=1, y=0, y=1, z=0, z=1)."""
    nodes = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=float)
    tets = []
    for a, b, c in itertools.permutations((1, 2, 4)):
        t = [0, a, a | b, 7]
        m = nodes[t[1:]] - nodes[t[0]]
        if np.linalg.det(m) < 0:
            t[1], t[2] = t[2], t[1]
        tets.append(t)
    count = {}
    for t in tets:
        for f in ((t[1], t[2], t[3]), (t[0], t[3], t[2]), (t[0], t[1], t[3]), (t[0], t[2], t[1])):
            count.setdefault(tuple(sorted(f)), []).append(f)
    tris = [fs[0] for fs in count.values() if len(fs) == 1]  # a tet's faces point outwards
    faces = []
    for t in tris:
        c = nodes[list(t)].mean(axis=0)
        axis = int(np.argmax(np.abs(c - 0.5)))
        faces.append(1 + 2 * axis + int(c[axis] > 0.5))
    return nodes, np.array(tets), np.array(tris), np.array(faces)


JOB = json.dumps({"material": {"E": 1000.0, "nu": 0.3},
                  "supports": [{"type": "fixed", "faces": ["Face1"]}],
                  "load_cases": [{"name": "pull", "loads": [{"type": "force", "faces": ["Face2"],
                                                             "vector": [1.0, 0, 0]}]}]})


class Arguments(unittest.TestCase):
    def setUp(self):
        self.nodes, self.tets, self.tris, self.faces = cube()
        self.domain = np.zeros(len(self.tets), dtype=np.int32)
        self.dens = np.ones(len(self.tets))

    def refused(self, message, function, *args, **kwargs):
        with self.assertRaises(native.TopOptError) as ctx:
            function(*args, **kwargs)
        self.assertEqual(ctx.exception.code, "InvalidParameter")
        self.assertEqual(str(ctx.exception), message)

    def with_tet_index(self, value):
        tets = self.tets.copy()
        tets[3, 2] = value
        return tets

    def with_tri_index(self, value):
        tris = self.tris.copy()
        tris[5, 0] = value
        return tris

    # --- the cases of the issue: past the nodes, and negative -----------------------------
    def test_extract_surface_indices(self):
        points, triangles = native.extract_surface(self.nodes, self.tets, self.domain, self.dens, 0.5)
        self.assertGreater(len(triangles), 0)
        for value in (9999, -1):
            self.refused("tets[3, 2] = %d but there are 8 nodes (indices 0 to 7)" % value, native.extract_surface,
                         self.nodes, self.with_tet_index(value), self.domain, self.dens, 0.5)

    def test_design_report(self):
        # the whole cube solid: one piece, no void, nothing to warn about; bad arguments refused
        report = native.design_report(self.nodes, self.tets, self.domain, self.dens, 0.5)
        self.assertEqual(report["pieces"], 1)
        self.assertEqual(report["voids_filled"], 0)
        self.assertEqual(report["warnings"], [])
        for value in (9999, -1):
            self.refused("tets[3, 2] = %d but there are 8 nodes (indices 0 to 7)" % value, native.design_report,
                         self.nodes, self.with_tet_index(value), self.domain, self.dens, 0.5)
        self.refused("the threshold must lie strictly between 0 and 1", native.design_report, self.nodes, self.tets,
                     self.domain, self.dens, 1.0)
        self.refused("fill_voids must be True or False", native.design_report, self.nodes, self.tets, self.domain,
                     self.dens, 0.5, fill_voids="yes")

    def test_measure_members(self):
        # the Kuhn tets of the unit cube with x <= 1/2 (three of them, the cube cut by the plane
        # through its diagonal) against void: a member of the cube's size; bad arguments refused
        solid = np.array([1.0 if self.nodes[t].mean(axis=0)[0] < 0.5 else 0.0 for t in self.tets])
        m = native.measure_members(self.nodes, self.tets, self.domain, solid, 0.5)
        self.assertEqual(m["solid_design"], int(solid.sum()))
        self.assertGreater(m["smallest_member"], 0)
        self.assertLessEqual(m["smallest_member"], np.sqrt(3))
        self.assertEqual(len(m["thickness"]), len(self.tets))
        self.assertTrue(all(m["thickness"][solid == 0] == 0))
        self.refused("solid[0] = 2 is outside [0, 1]", native.measure_members, self.nodes, self.tets, self.domain,
                     2 * np.ones(len(self.tets)))
        self.refused("reach = -1 but it must be at least 0", native.measure_members, self.nodes, self.tets,
                     self.domain, solid, -1.0)
        self.refused("gaps must be True or False", native.measure_members, self.nodes, self.tets, self.domain, solid,
                     0.5, gaps=1)

    def test_solve_indices(self):
        r = native.solve(self.nodes, self.tets, self.tris, self.faces, self.domain, JOB)
        self.assertGreater(r["compliance"][0], 0)
        for value in (8, -3):
            self.refused("tets[3, 2] = %d but there are 8 nodes (indices 0 to 7)" % value, native.solve,
                         self.nodes, self.with_tet_index(value), self.tris, self.faces, self.domain, JOB)
            self.refused("tris[5, 0] = %d but there are 8 nodes (indices 0 to 7)" % value, native.solve,
                         self.nodes, self.tets, self.with_tri_index(value), self.faces, self.domain, JOB)

    def test_volume_mesh_indices(self):
        r = native.volume_mesh(self.nodes, self.tris)
        self.assertGreater(len(r["tets"]), 0)
        for value in (12, -1):
            self.refused("triangles[5, 0] = %d but there are 8 nodes (indices 0 to 7)" % value, native.volume_mesh,
                         self.nodes, self.with_tri_index(value))

    # --- shapes, lengths, finite numbers, empty arrays, types -----------------------------
    def test_shapes_and_lengths(self):
        self.refused("nodes must be an array of #V by 3 coordinates, not of shape (8, 2)", native.volume_mesh,
                     self.nodes[:, :2], self.tris)
        self.refused("densities has 5 entries but there are 6 tets: give one per tet", native.extract_surface,
                     self.nodes, self.tets, self.domain, self.dens[:5], 0.5)
        self.refused("domain has 2 entries but there are 6 tets: give one per tet", native.solve,
                     self.nodes, self.tets, self.tris, self.faces, self.domain[:2], JOB)
        self.refused("tri_face has 11 entries but there are 12 triangles: give one per triangle", native.solve,
                     self.nodes, self.tets, self.tris, self.faces[:11], self.domain, JOB)
        self.refused("tets is empty: give at least one row", native.extract_surface,
                     self.nodes, np.zeros((0, 4), dtype=int), self.domain[:0], self.dens[:0], 0.5)

    def test_values(self):
        nodes = self.nodes.copy()
        nodes[2, 1] = np.nan
        self.refused("nodes[2, 1] is nan: every coordinate must be a finite number", native.volume_mesh,
                     nodes, self.tris)
        dens = self.dens.copy()
        dens[0] = np.inf
        self.refused("densities[0] is inf: every value must be a finite number", native.extract_surface,
                     self.nodes, self.tets, self.domain, dens, 0.5)
        self.refused("tets[0, 0] = 0.5 is not a whole number", native.extract_surface,
                     self.nodes, self.tets + 0.5, self.domain, self.dens, 0.5)
        faces = self.faces.copy()
        faces[3] = -2
        self.refused("tri_face[3] = -2 but tags start at 0", native.solve,
                     self.nodes, self.tets, self.tris, faces, self.domain, JOB)
        self.refused("threshold is nan: give a finite number", native.extract_surface,
                     self.nodes, self.tets, self.domain, self.dens, float("nan"))
        self.refused("size (mm, 0: from the boundary) = -1 but it must be at least 0", native.volume_mesh,
                     self.nodes, self.tris, -1.0)
        self.refused("smoothing_iterations = 2.5 is not a whole number", native.extract_surface,
                     self.nodes, self.tets, self.domain, self.dens, 0.5, -1.0, 2.5)

    def test_types(self):
        self.refused("part must be a str, not a NoneType", native.info, None)
        self.refused("tolerance must be a number, not a str", native.info, "x", "", "tight")
        self.refused("nodes must be an array of #V by 3 coordinates, not a str", native.volume_mesh, "abc", self.tris)
        self.refused("tets must be an array of #n by 4 indices into the nodes, not an array of bool",
                     native.extract_surface, self.nodes, self.tets > 3, self.domain, self.dens, 0.5)
        self.refused("callback must be a function taking a dict, or None", native.run_job, JOB, "", "", 5)
        self.refused("optimization must be a str, not a dict", native.extract_surface,
                     self.nodes, self.tets, self.domain, self.dens, 0.5, -1.0, -1, {})

    def test_job_json_of_the_wrong_kind_is_named(self):
        job = json.loads(JOB)
        job["material"]["E"] = "stiff"
        with self.assertRaises(native.TopOptError) as ctx:
            native.solve(self.nodes, self.tets, self.tris, self.faces, self.domain, json.dumps(job))
        self.assertNotIn("json.exception", str(ctx.exception))
        self.assertIn("E", str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
