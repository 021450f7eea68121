"""A run's results as FreeCAD objects: the last SIMP iterate as a FEM result on the analysis
mesh, the fields pipeline and density view, the domain meshes; all linked from the study and
refreshed in place by a re-run; a run and a threshold change are undo steps; headless runs
print one line per stage and the summary, without FreeCAD's progress lines; documents
reopen without the mesh-defect complaint."""
import contextlib
import math
import os
import re
import tempfile
import unittest

import FreeCAD
import numpy as np
from helpers import box_study

from topopt.app import api, progress, quiet, results, runner
from topopt.app.study import RESULT_LINKS, owned_objects


@contextlib.contextmanager
def captured_output(sink):
    """Collects what this process writes to standard output and error (file descriptors 1 and
    2, where FreeCAD's console and its progress lines go) into sink[0]."""
    import sys
    sys.stdout.flush()
    sys.stderr.flush()
    quiet._flush_all()
    saved = os.dup(1), os.dup(2)
    with tempfile.TemporaryFile() as f:
        os.dup2(f.fileno(), 1)
        os.dup2(f.fileno(), 2)
        try:
            yield
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            quiet._flush_all()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            f.seek(0)
            sink.append(f.read().decode("utf-8", "replace"))


class RunResults(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.doc, cls.study = box_study("Results", iterations=12, mesh_size=3.0)
        cls.doc.UndoMode = 1
        out = []
        with captured_output(out):
            api.run(cls.study)
        cls.output = out[0]
        cls.first_history = list(cls.study.ComplianceHistory)

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def test_headless_output_is_one_line_per_stage_and_the_summary(self):
        lines = [line for line in self.output.splitlines() if line.strip()]
        for stage in ("reading the shapes", "meshing", "optimising (at most 12 iterations)",
                      "extracting the result shape", "analysing the last iterate"):
            self.assertEqual(sum(1 for line in lines if line == "TopOpt: " + stage), 1, stage)
        self.assertFalse(re.search(r"\(\s*\d+ %\)", self.output), "FreeCAD's progress lines leaked")
        self.assertIn("TopOptStudy finished in", self.output)
        self.assertIn("iterations: 12", self.output)
        self.assertIn("mesher: native (auto)", self.output)
        self.assertRegex(self.output, r"results: TopOptStudy result \(the shape, [0-9.e+]+ mm³\)")

    def test_fem_result_of_the_last_iterate(self):
        res, mesh = self.study.FemResult, self.study.AnalysisMesh
        self.assertEqual(res.Mesh, mesh)
        nodes = len(self.study.MeshNodes)
        self.assertEqual(mesh.FemMesh.NodeCount, nodes)
        self.assertEqual(mesh.FemMesh.VolumeCount, len(self.study.MeshTets) // 4)
        self.assertEqual(len(res.DisplacementVectors), nodes)
        self.assertEqual(list(res.NodeNumbers), list(range(1, nodes + 1)))
        # the beam bends down under its -z load: the loaded end (x = 60) moves down most
        xyz = np.array([[v.x, v.y, v.z] for v in self.study.MeshNodes])
        u = np.array([[v.x, v.y, v.z] for v in res.DisplacementVectors])
        self.assertLess(u[xyz[:, 0] > 59.9, 2].mean(), 0)
        self.assertAlmostEqual(np.abs(u[xyz[:, 0] < 0.1]).max(), 0.0)  # the fixed end
        # the work of the load (100 N spread over Face2) is the compliance of the last iterate
        work = -100.0 * u[xyz[:, 0] > 59.9, 2].mean()
        self.assertAlmostEqual(work / self.study.ComplianceHistory[-1], 1.0, delta=0.2)
        self.assertGreater(max(res.vonMises), 0)
        self.assertEqual(res.Stats[7], max(res.DisplacementLengths))  # FEM's own statistics filled
        self.assertEqual(res.Stats[9], max(res.vonMises))

    def test_fields_and_density_view(self):
        pipe, clip = self.study.Fields, self.study.DensityView
        self.assertEqual(pipe.TypeId, "Fem::FemPostPipeline")
        self.assertIn(clip, pipe.Filter)
        self.assertEqual(clip.Scalars, results.DENSITY)
        self.assertAlmostEqual(clip.Value, self.study.Threshold)
        self.assertTrue(0 < self.study.Threshold < 1)

    def test_everything_sits_under_the_study(self):
        children = owned_objects(self.study)
        for name, _ in RESULT_LINKS:
            if name != "DensityView":  # under the fields pipeline
                self.assertIn(getattr(self.study, name), children)
        self.assertEqual(len(self.study.Result.FaceColors), self.study.Result.Mesh.CountFacets)

    def test_zz_rerun_refreshes_in_place_and_undo_takes_runs_back(self):
        names = sorted(o.Name for o in self.doc.Objects)
        self.study.VolumeFraction = 0.3
        api.run(self.study, verbose=False)
        self.assertEqual(sorted(o.Name for o in self.doc.Objects), names)  # the same objects, updated
        second = list(self.study.ComplianceHistory)
        self.assertNotEqual(second, self.first_history)
        runner.reextract(self.study, 0.2)
        self.assertEqual(self.doc.UndoNames[:3], ["TopOpt threshold 0.20", "TopOpt run", "TopOpt run"])
        self.assertAlmostEqual(self.study.DensityView.Value, 0.2)
        self.doc.undo()
        self.assertNotAlmostEqual(self.study.Threshold, 0.2)
        self.doc.undo()
        self.assertEqual(list(self.study.ComplianceHistory), self.first_history)
        self.doc.undo()
        self.assertIsNone(self.study.Result)
        self.assertFalse([o for o in self.doc.Objects if o.Name.startswith("TopOptStudy_")])


class DomainMeshesAndReopen(unittest.TestCase):
    def test_domains_then_run_then_reopen(self):
        doc, study = box_study("Domains", iterations=4, mesh_size=4.0)
        try:
            mesh = runner.mesh_only(study)
            self.assertEqual(len(study.DomainMeshes), 1)  # a box without non-design solids
            self.assertEqual(study.DomainMeshes[0].FemMesh.VolumeCount, len(mesh["tets"]))
            api.run(study, verbose=False)
            self.assertEqual(study.DomainMeshes[0].FemMesh.VolumeCount, len(study.MeshTets) // 4)
            path = os.path.join(tempfile.mkdtemp(), "domains.FCStd")
            api.save(doc, path)
        finally:
            FreeCAD.closeDocument(doc.Name)
        out = []
        with captured_output(out):
            doc = quiet.open_document(path)
        try:
            self.assertNotIn("defects", out[0])
            study = doc.getObject("TopOptStudy")
            self.assertEqual(study.FemResult.Mesh, study.AnalysisMesh)
            self.assertGreater(study.AnalysisMesh.FemMesh.VolumeCount, 0)
            self.assertEqual(len(study.Result.FaceColors), study.Result.Mesh.CountFacets)
        finally:
            FreeCAD.closeDocument(doc.Name)


class Progress(unittest.TestCase):
    def test_fraction_goes_forward_and_stages_are_counted_once(self):
        t = progress.Tracker("optimize", max_iterations=50, clock=iter(range(1000)).__next__)
        records = [{"stage": "read", "fraction": 0.0},
                   {"stage": "mesh", "fraction": -1, "message": "checking the part"},
                   {"stage": "brep", "fraction": 0.5}, {"stage": "mesh", "fraction": 0.3, "message": "volumes"}]
        records += [{"iteration": i, "compliance": 100.0 / i, "volume": 0.3} for i in range(1, 6)]
        records += [{"stage": "surface", "fraction": -1}]
        fractions, new = [], []
        for r in records:
            new.append(t.update(r))
            fractions.append(t.fraction)
        self.assertEqual(fractions, sorted(fractions))
        self.assertEqual(sum(new), 5)  # read, brep, mesh, simp, surface
        self.assertEqual([s for s, _ in t.stages], ["read", "brep", "mesh", "simp", "surface"])
        self.assertIn("iteration 5 of at most 50", self._label_after(records[8]))

    @staticmethod
    def _label_after(record):
        t = progress.Tracker("optimize", 50)
        t.update(record)
        return t.label

    def test_simp_share_follows_convergence_not_only_the_cap(self):
        self.assertAlmostEqual(progress.simp_fraction(10, 100, [10.0, 9.0]), math.log(1 / 9.0) / math.log(progress.TOL_OBJECTIVE))
        self.assertEqual(progress.simp_fraction(10, 100, [10.0, 10.0]), 1.0)  # converged
        self.assertAlmostEqual(progress.simp_fraction(50, 100, [10.0, 5.0]), 0.5)  # the cap's share

    def test_mesher_used(self):
        self.assertEqual(progress.mesher_used("native", []), "native")
        self.assertTrue(progress.mesher_used(
            "auto", ["the native mesher could not mesh this part (x); meshing with Gmsh's OCC fragments instead"])
            .startswith("gmsh"))


def _kuhn_box(nx, ny, nz):
    """Nodes and tets of the box [0, nx] × [0, ny] × [0, nz], each unit cube in six tets."""
    idx = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k
    nodes = np.array([(i, j, k) for i in range(nx + 1) for j in range(ny + 1) for k in range(nz + 1)], dtype=float)
    paths = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    tets = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                for path in paths:
                    corner = [i, j, k]
                    tet = [idx(*corner)]
                    for axis in path:
                        corner[axis] += 1
                        tet.append(idx(*corner))
                    tets.append(tet)
    return nodes, np.array(tets, dtype=np.int64)


def _boundary_split_in_four(nodes, tets):
    """The box's boundary triangles each split in four at its edges' midpoints (new points, as
    the surface stage's splits make): points, triangles."""
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 2, 3]], tets[:, [0, 1, 3]], tets[:, [0, 1, 2]]])
    _, first, count = np.unique(np.sort(faces, axis=1), axis=0, return_index=True, return_counts=True)
    points, triangles = [], []
    for a, b, c in nodes[faces[first[count == 1]]]:
        base = len(points)
        points += [a, b, c, (a + b) / 2, (b + c) / 2, (c + a) / 2]
        triangles += [(base, base + 3, base + 5), (base + 3, base + 1, base + 4), (base + 5, base + 4, base + 2),
                      (base + 3, base + 4, base + 5)]
    return np.array(points), np.array(triangles, dtype=np.int64)


class ResultColours(unittest.TestCase):
    """The result shape's faces on a non-design solid are found by place: the surface stage splits
    and moves triangles there, so their corners need not be mesh nodes (the lever's eyes showed a
    grey ring on their orange tops before)."""

    def setUp(self):
        self.nodes, self.tets = _kuhn_box(4, 2, 2)
        centre_x = self.nodes[self.tets].mean(axis=1)[:, 0]
        self.domain = np.where(centre_x < 1, 1, 0)  # solid 1: the slab x < 1

    def coloured_area(self, points, triangles, tags=None):
        domain = results.facet_domains(points, triangles, self.nodes, self.tets, self.domain, tags)
        p = points[triangles]
        area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
        return area[domain == 1].sum(), area[domain == 0].sum()

    def test_split_triangles_on_a_solid_are_coloured_and_no_others(self):
        points, triangles = _boundary_split_in_four(self.nodes, self.tets)
        on_solid, off = self.coloured_area(points, triangles)
        # the slab's share of the box's boundary: its end 2 × 2, top and bottom 1 × 2, sides 1 × 2
        self.assertAlmostEqual(on_solid, 4 + 2 * 2 + 2 * 2, places=9)
        self.assertAlmostEqual(on_solid + off, 2 * (4 * 2 + 4 * 2 + 2 * 2), places=9)

    def test_points_projected_off_the_face_still_count(self):
        points, triangles = _boundary_split_in_four(self.nodes, self.tets)
        moved = points.copy()
        end = np.abs(points[:, 0]) < 1e-12
        moved[end, 0] -= 0.03 * np.sin(points[end, 1] * 2.1) ** 2  # a curved face's sagitta, 3 % of an edge
        flat = results.facet_domains(points, triangles, self.nodes, self.tets, self.domain)
        curved = results.facet_domains(moved, triangles, self.nodes, self.tets, self.domain)
        self.assertGreater((flat == 1).sum(), 0)
        self.assertTrue((curved == flat).all())

    def test_tags_decide_inside_the_part(self):
        points, triangles = _boundary_split_in_four(self.nodes, self.tets)
        tags = np.ones(len(triangles), dtype=np.int64)
        tags[:4] = -2  # the core's mark of a face of solid 2 inside the part
        tags[4:8] = 0  # the iso-surface: in the design, whatever its place
        domain = results.facet_domains(points, triangles, self.nodes, self.tets, self.domain, tags)
        self.assertTrue((domain[:4] == 2).all())
        self.assertTrue((domain[4:8] == 0).all())


if __name__ == "__main__":
    unittest.main()
