"""The result back in CAD and verified, in FreeCADCmd: a run keeps result.step and the
verification's files in the study; api.result_solid makes a Part solid from the STEP (one undo
step), api.export_step writes it, both at the threshold the slider shows, both refuse cleanly (naming the setting) when the run wrote
no STEP; at a threshold the slider moved to, the part's bore comes back as cylinders; the verification becomes a FEM mesh, a FEM result and a fields pipeline whose largest
von Mises stress is verification.json's; a re-run without the files removes what they made."""
import json
import os
import tempfile
import unittest

import FreeCAD
import Part
from helpers import box_study, top_loaded_box_study

from topopt.app import api, asbuilt, results, units, vtu
from topopt.app.errors import TopOptError
from topopt.app.study import STEP_MAX_TRIANGLES


class ResultAsBuilt(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.doc, cls.study = top_loaded_box_study("AsBuilt")
        cls.doc.UndoMode = 1
        cls.study.WriteStep = True
        cls.study.Verify = True
        api.run(cls.study, verbose=False)
        cls.folder = tempfile.mkdtemp(prefix="topopt-asbuilt-test-")

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def test_the_job_asks_for_the_files(self):
        self.assertEqual(api.job_of(self.study)["output"],
                         {"step": True, "verification": True, "step_max_triangles": STEP_MAX_TRIANGLES})

    def test_result_solid_is_one_valid_closed_solid_of_the_result_mesh_volume(self):
        feature = api.result_solid(self.study)
        self.assertEqual(feature.TypeId, "Part::Feature")
        self.assertIs(self.study.ResultSolid, feature)
        shape = feature.Shape
        self.assertEqual(len(shape.Solids), 1)
        self.assertTrue(shape.isValid())
        self.assertTrue(all(s.isClosed() for s in shape.Solids[0].Shells))
        mesh_volume = self.study.Result.Mesh.Volume
        self.assertGreater(mesh_volume, 0)
        self.assertLess(abs(shape.Volume - mesh_volume) / mesh_volume, 0.005)
        from topopt.app.study import owned_objects
        self.assertIn(feature, owned_objects(self.study))

    def test_result_solid_is_one_undo_step(self):
        before = len(self.doc.Objects)
        had = self.study.ResultSolid is not None
        api.result_solid(self.study)
        self.assertEqual(self.doc.UndoNames[0], "TopOpt result as solid")
        if not had:
            self.assertEqual(len(self.doc.Objects), before + 1)
            self.doc.undo()
            self.assertIsNone(self.study.ResultSolid)
            self.assertEqual(len(self.doc.Objects), before)
            self.doc.redo()
            self.assertIsNotNone(self.study.ResultSolid)

    def test_export_step_writes_the_solid(self):
        path = api.export_step(self.study, os.path.join(self.folder, "beam.step"))
        shape = Part.read(path)
        self.assertEqual(len(shape.Solids), 1)
        self.assertLess(abs(shape.Volume - self.study.Result.Mesh.Volume) / shape.Volume, 0.005)

    def test_export_step_refuses_a_missing_folder(self):
        with self.assertRaises(TopOptError) as e:
            api.export_step(self.study, os.path.join(self.folder, "no", "such", "beam.step"))
        self.assertIn("does not exist", str(e.exception))

    def test_re_extraction_at_the_run_threshold_is_the_run_shape(self):
        # issue 19: the study keeps the run's boundary numbered by the part's faces, so the slider
        # cleans the result by the run's supports and loads: the same surface, without a warning
        from topopt.app import runner
        self.assertEqual(len(self.study.MeshBoundary), 3 * len(self.study.MeshBoundaryFaces))
        self.assertGreater(max(self.study.MeshBoundaryFaces), 0)
        answer = runner.extract_at(self.study, self.study.RunThreshold)
        self.assertEqual([w for w in answer["warnings"] if "may differ from the run's" in w], [])
        run = self.study.Result.Mesh
        self.assertEqual(len(answer["surface_triangles"]), run.CountFacets)
        shown = runner.result_mesh(answer["surface_points"], answer["surface_triangles"])
        self.assertAlmostEqual(shown.Volume, run.Volume, delta=1e-9 * run.Volume)

    def test_step_and_solid_follow_the_threshold_slider(self):
        from topopt.app import runner
        run_threshold = self.study.Threshold
        self.assertAlmostEqual(asbuilt.run_threshold(self.study), run_threshold)
        run_volume = Part.read(asbuilt.step_path(self.study)).Volume
        try:
            runner.reextract(self.study, 0.7 if run_threshold < 0.6 else 0.3)
            mesh_volume = self.study.Result.Mesh.Volume
            shape = Part.read(api.export_step(self.study, os.path.join(self.folder, "moved.step")))
            self.assertEqual(len(shape.Solids), 1)
            self.assertTrue(shape.isValid())
            # the shape the slider shows, not the run's
            self.assertLess(abs(shape.Volume - mesh_volume) / mesh_volume, 0.005)
            self.assertGreater(abs(shape.Volume - run_volume) / run_volume, 0.02)
            solid = api.result_solid(self.study).Shape
            self.assertLess(abs(solid.Volume - mesh_volume) / mesh_volume, 0.005)
        finally:
            runner.reextract(self.study, run_threshold)

    def test_verification_of_the_run_is_in_fem(self):
        report = json.loads(self.study.VerificationReport)
        self.assertEqual(report["failed"], {})
        check_verification_objects(self, self.study, report)
        self.assertGreater(units.prop(self.study, "ComplianceAsBuilt", "N*mm"), 0)

    def test_vtu_reader_reads_what_the_writer_wrote(self):
        nodes = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]
        tets = [[0, 1, 2, 3], [1, 2, 3, 4]]
        path = vtu.write_tets(os.path.join(self.folder, "t.vtu"), nodes, tets,
                              [("u", [[i, 2 * i, 3 * i] for i in range(5)])], [("s", [1.5, 2.5])])
        n, t, points, cells = vtu.read_tets(path)
        self.assertEqual(t.tolist(), tets)
        self.assertEqual(n.tolist(), nodes)
        self.assertEqual(points["u"][4].tolist(), [4, 8, 12])
        self.assertEqual(cells["s"].tolist(), [1.5, 2.5])
        self.assertEqual(results.nodal_maximum(t, cells["s"], 5).tolist(), [1.5, 2.5, 2.5, 2.5, 2.5])

    def test_z_the_solid_and_the_step_follow_the_threshold(self):
        # the slider's threshold (study.Threshold after a re-extraction), not the run's, makes
        # Result as solid and Export STEP; back at the run's, they are result.step's again
        from topopt.app import runner
        run = self.study.RunThreshold
        self.assertAlmostEqual(run, self.study.Threshold)
        at_run = api.result_solid(self.study).Shape.Volume
        higher = round(min(0.9, run + 0.25), 2)
        runner.reextract(self.study, higher)
        self.assertAlmostEqual(self.study.Threshold, higher)
        self.assertAlmostEqual(self.study.RunThreshold, run)  # the run's is kept
        shown = self.study.Result.Mesh.Volume
        solid = api.result_solid(self.study).Shape
        self.assertEqual(len(solid.Solids), 1)
        self.assertTrue(solid.isValid())
        self.assertLess(abs(solid.Volume - shown) / shown, 0.005)
        self.assertLess(solid.Volume, 0.97 * at_run)
        path = api.export_step(self.study, os.path.join(self.folder, "higher.step"))
        read = Part.read(path)
        self.assertEqual(len(read.Solids), 1)
        self.assertLess(abs(read.Volume - shown) / shown, 0.005)
        # an explicit threshold other than the shown one: extracted anew, the document's result unchanged
        lower = round(max(0.1, run - 0.2), 2)
        below = api.result_solid(self.study, threshold=lower).Shape.Volume
        self.assertGreater(below, at_run * 1.01)
        self.assertAlmostEqual(self.study.Threshold, higher)
        back = api.result_solid(self.study, threshold=run).Shape.Volume
        self.assertAlmostEqual(back, at_run, delta=1e-6 * at_run)
        with self.assertRaises(TopOptError) as e:
            api.result_solid(self.study, threshold=1.5)
        self.assertIn("strictly between 0 and 1", str(e.exception))

    def test_the_step_at_another_threshold_keeps_the_studys_triangle_budget(self):
        # the worker's re-extraction honours StepMaxTriangles as a run does: a budget no
        # coarsening within 0.5 % of the volume can meet is refused naming the job's key, the
        # default writes the solid
        run = self.study.RunThreshold
        lower = round(max(0.1, run - 0.15), 2)
        self.study.StepMaxTriangles = 10
        try:
            with self.assertRaises(TopOptError) as e:
                api.result_solid(self.study, threshold=lower)
            self.assertIn("step_max_triangles", str(e.exception))
            self.assertIn("StepMaxTriangles", str(e.exception))
        finally:
            self.study.StepMaxTriangles = STEP_MAX_TRIANGLES
        self.assertEqual(len(api.result_solid(self.study, threshold=lower).Shape.Solids), 1)

    def test_zz_rerun_without_the_files_removes_what_they_made_and_refuses(self):
        api.result_solid(self.study)
        self.study.WriteStep = False
        self.study.Verify = False
        api.run(self.study, verbose=False)
        for name in ("ResultSolid", "VerificationMesh", "VerificationResult", "VerificationFields"):
            self.assertIsNone(getattr(self.study, name), name)
        self.assertEqual(units.prop(self.study, "ComplianceAsBuilt", "N*mm"), 0.0)
        for call in (lambda: api.result_solid(self.study),
                     lambda: api.export_step(self.study, os.path.join(self.folder, "x.step"))):
            with self.assertRaises(TopOptError) as e:
                call()
            self.assertIn("WriteStep", str(e.exception))
        self.assertFalse(os.path.exists(os.path.join(self.folder, "x.step")))


def check_verification_objects(test, study, report):
    """The study's verification FEM objects match verification.json's figures."""
    res, mesh, pipe = study.VerificationResult, study.VerificationMesh, study.VerificationFields
    test.assertEqual(res.TypeId, "Fem::FemResultObjectPython")
    test.assertEqual(mesh.TypeId, "Fem::FemMeshObjectPython")
    test.assertEqual(pipe.TypeId, "Fem::FemPostPipeline")
    test.assertIs(res.Mesh, mesh)
    test.assertEqual(mesh.FemMesh.VolumeCount, report["tets"])
    test.assertEqual(len(res.vonMises), mesh.FemMesh.NodeCount)
    test.assertAlmostEqual(max(res.vonMises), report["max_von_mises"], delta=1e-6 * report["max_von_mises"])
    test.assertAlmostEqual(max(res.DisplacementLengths), report["max_displacement"],
                           delta=1e-6 * report["max_displacement"])
    for name, value in (("ComplianceAsBuilt", report["compliance_as_built"]),
                        ("ComplianceCrisp", report["crisp"]["compliance"])):
        test.assertEqual(getattr(study, name).Unit, FreeCAD.Units.Quantity("1 mJ").Unit, name)  # a work, not a number
        test.assertAlmostEqual(units.prop(study, name, "N*mm"), value, delta=1e-9 * value)
    from topopt.app.study import owned_objects
    for obj in (res, mesh, pipe):
        test.assertIn(obj, owned_objects(study))


def core_verification_files(folder):
    """verification.vtu and verification.json as the core writes them (src/io/vtu.cpp,
    src/pipeline/result_files.cpp) for two tets under one load case named "tip": the VTU
    with Int32 cell domain, displacement_tip per point, von_mises_tip per tet. Returns
    ({name: bytes}, report dict)."""
    nodes = [[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10], [10, 10, 10]]
    tets = [[0, 1, 2, 3], [1, 2, 3, 4]]
    u = [[0, 0, 0], [0, 0, -0.25], [0, 0, -0.1], [0, 0, 0], [0.02, 0, -0.5]]
    vm = [40.5, 120.25]
    text = ['<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
            '  <UnstructuredGrid>\n    <Piece NumberOfPoints="5" NumberOfCells="2">\n      <Points>\n'
            '        <DataArray type="Float64" NumberOfComponents="3" format="ascii">\n']
    text += [" %g %g %g\n" % tuple(p) for p in nodes]
    text.append('        </DataArray>\n      </Points>\n      <Cells>\n'
                '        <DataArray type="Int64" Name="connectivity" format="ascii">\n')
    text += [" %d %d %d %d\n" % tuple(t) for t in tets]
    text.append('        </DataArray>\n        <DataArray type="Int64" Name="offsets" format="ascii">\n 4 8\n'
                '        </DataArray>\n        <DataArray type="UInt8" Name="types" format="ascii">\n 10 10\n'
                '        </DataArray>\n      </Cells>\n      <PointData>\n'
                '        <DataArray type="Float64" Name="displacement_tip" NumberOfComponents="3" format="ascii">\n')
    text += [" %g %g %g\n" % tuple(d) for d in u]
    text.append('        </DataArray>\n      </PointData>\n      <CellData>\n'
                '        <DataArray type="Int32" Name="domain" format="ascii">\n 0 0\n        </DataArray>\n'
                '        <DataArray type="Float64" Name="von_mises_tip" NumberOfComponents="1" format="ascii">\n'
                ' 40.5\n 120.25\n        </DataArray>\n      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n'
                '</VTKFile>\n')
    max_u = max(sum(c * c for c in d) ** 0.5 for d in u)
    report = {"compliance_as_built": 12.5, "max_displacement": max_u, "max_von_mises": max(vm), "tets": 2,
              "crisp": {"compliance": 11.75}, "ratio": 12.5 / 11.75, "failed": {}}
    return {asbuilt.VTU: "".join(text).encode(), asbuilt.REPORT: json.dumps(report).encode()}, report


class VerificationInFem(unittest.TestCase):
    def test_the_cores_verification_files_become_fem_objects_and_go_again(self):
        doc, study = box_study("AsBuiltFem")
        try:
            files, report = core_verification_files(tempfile.mkdtemp(prefix="topopt-asbuilt-"))
            asbuilt.store_files(study, files)
            asbuilt.update_verification(study)
            check_verification_objects(self, study, report)
            self.assertEqual(max(study.VerificationResult.vonMises), 120.25)
            self.assertTrue(any("as-built compliance 12.5 N·mm vs crisp 11.75" in line
                                for line in asbuilt.summary_lines(study)))
            asbuilt.store_files(study, {})  # a run without verification: nothing stale stays
            asbuilt.update_verification(study)
            self.assertIsNone(study.VerificationResult)
            self.assertFalse([o for o in doc.Objects if o.Name.startswith(study.Name + "_Verification")])
        finally:
            FreeCAD.closeDocument(doc.Name)


class SliderSolidKeepsTheBore(unittest.TestCase):
    """Result as solid at a threshold the slider moved to (the worker's extract_surface, not
    the run's result.step) gives the part's bore back as cylinders of its radius (issue 19/23)."""

    RADIUS = 2.5

    @classmethod
    def setUpClass(cls):
        cls.doc = FreeCAD.newDocument("SliderBore")
        part = cls.doc.addObject("Part::Feature", "BoredBeam")
        bore = Part.makeCylinder(cls.RADIUS, 12, FreeCAD.Vector(45, 5, -1))
        part.Shape = Part.makeBox(60, 10, 10).cut(bore)
        cls.doc.recompute()
        ends = {}
        for i, face in enumerate(part.Shape.Faces, 1):  # the end faces x = 0 and x = 60, by place
            if face.Surface.__class__.__name__ == "Plane" and abs(face.Surface.Axis.x) > 0.99:
                ends[round(face.CenterOfMass.x)] = "Face%d" % i
        cls.study = api.new_study(cls.doc, part, (), volume_fraction=0.4, mesh_size=3.0)
        cls.study.MaxIterations = 6
        cls.study.WriteStep = True
        api.add_fixed(cls.study, ends[0])
        api.add_force(cls.study, ends[60], (0, 0, -100))
        cls.doc.recompute()
        api.run(cls.study, verbose=False)

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def test_the_solid_at_a_low_threshold_has_the_bore_as_cylinders(self):
        # at 0.02 every tet is kept: the beam with its bore, no longer the run's shape
        solid = api.result_solid(self.study, threshold=0.02).Shape
        self.assertEqual(len(solid.Solids), 1)
        self.assertTrue(solid.isValid())
        radii = [f.Surface.Radius for f in solid.Faces if f.Surface.__class__.__name__ == "Cylinder"]
        self.assertGreater(len(radii), 0, "the bore came back as %d facets" % len(solid.Faces))
        for radius in radii:
            self.assertAlmostEqual(radius, self.RADIUS, places=6)


class NoResult(unittest.TestCase):
    def test_a_study_without_a_run_is_refused(self):
        doc, study = box_study("AsBuiltNoRun")
        try:
            for call in (lambda: api.result_solid(study),
                         lambda: api.export_step(study, os.path.join(tempfile.gettempdir(), "none.step"))):
                with self.assertRaises(TopOptError) as e:
                    call()
                self.assertIn("run it first", str(e.exception))
            self.assertIsNone(study.ResultSolid)
        finally:
            FreeCAD.closeDocument(doc.Name)


if __name__ == "__main__":
    unittest.main()
