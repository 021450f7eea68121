"""Running a study: prepare (document → strings, GUI thread), execute (native, any thread,
touches no document), apply (results → document, GUI thread). Headless scripts call run().
"""
import json

import FreeCAD

from .. import native
from . import job as jobmod
from .errors import TopOptError


class PreparedRun:
    """Everything execute() needs, detached from the document."""

    def __init__(self, job, part_brep, nondesign_brep):
        self.job = job
        self.part_brep = part_brep
        self.nondesign_brep = nondesign_brep


def prepare(study):
    job = jobmod.study_to_job(study)
    part = study.Part.Shape
    nd = jobmod.nondesign_compound(study)
    return PreparedRun(job, part.exportBrepToString(), nd.exportBrepToString() if nd else "")


def _native_error(e):
    return TopOptError(str(e), getattr(e, "code", "Internal"))


def execute(prepared, on_progress=None):
    """Runs mesh → SIMP → surface natively. on_progress(record) gets a dict per iteration
    ({"iteration", "compliance", "volume", "change"}) or stage ({"stage", "fraction",
    "message"}); returning True cancels. Returns the result dict of the native run_job."""
    core = native()
    if not hasattr(core, "run_job"):
        raise TopOptError("this build of TopOpt cannot run optimisations yet (the native run_job is "
                          "missing): rebuild with scripts/build", "Internal")
    try:
        return core.run_job(json.dumps(prepared.job), prepared.part_brep, prepared.nondesign_brep,
                            on_progress)
    except core.TopOptError as e:
        raise _native_error(e) from None


def mesh_only(study):
    """Meshes the study's shapes (no optimisation) and stores the tagged mesh in the study.
    Returns the native result dict (nodes, tets, domain, boundary triangles, quality)."""
    prepared = prepare(study)
    core = native()
    try:
        result = core.mesh_shapes(json.dumps(prepared.job), prepared.part_brep, prepared.nondesign_brep)
    except core.TopOptError as e:
        raise _native_error(e) from None
    study.MeshNodes = [FreeCAD.Vector(*map(float, p)) for p in result["nodes"]]
    study.MeshTets = [int(i) for i in result["tets"].reshape(-1)]
    study.MeshDomains = [int(i) for i in result["domain"]]
    study.Densities = []
    _report_warnings(result)
    return result


def result_mesh(points, triangles):
    """A Mesh.Mesh from #P×3 points and #Q×3 triangles (points as FreeCAD.Vector: FreeCAD 0.20
    crashes on Mesh.Mesh((points, facets)) with plain tuples)."""
    import Mesh
    vectors = [FreeCAD.Vector(float(p[0]), float(p[1]), float(p[2])) for p in points]
    facets = [[vectors[int(t[0])], vectors[int(t[1])], vectors[int(t[2])]] for t in triangles]
    return Mesh.Mesh(facets)


def _report_warnings(result):
    """The core's warnings (e.g. the native mesher fell back to Gmsh) to FreeCAD's report view."""
    for w in result.get("warnings", []):
        FreeCAD.Console.PrintWarning("TopOpt: %s\n" % w)


def apply(study, result):
    """Stores the run's mesh, densities and history in the study and shows the result shape as
    a Mesh feature (created once, updated on later runs). Returns that feature."""
    doc = study.Document
    study.MeshNodes = [FreeCAD.Vector(*map(float, p)) for p in result["nodes"]]
    study.MeshTets = [int(i) for i in result["tets"].reshape(-1)]
    study.MeshDomains = [int(i) for i in result["domain"]]
    study.Densities = [float(x) for x in result["densities"]]
    study.ComplianceHistory = [float(h["compliance"]) for h in result["history"]]
    study.VolumeHistory = [float(h["volume"]) for h in result["history"]]
    study.Status = result.get("status", "done")
    _report_warnings(result)
    feature = study.Result
    if feature is None:
        feature = doc.addObject("Mesh::Feature", study.Name + "_Result")
        study.Result = feature
    feature.Mesh = result_mesh(result["surface_points"], result["surface_triangles"])
    doc.recompute()
    return feature


def run(study, on_progress=None):
    """prepare → execute → apply in the calling thread; returns the result Mesh feature."""
    return apply(study, execute(prepare(study), on_progress))


def reextract(study, threshold):
    """Re-extracts the result shape from the stored densities at another threshold (no
    re-run). Returns the result Mesh feature."""
    core = native()
    if not study.Densities:
        raise TopOptError("the study has no densities yet: run it first", "InvalidParameter")
    import numpy as np
    nodes = np.array([[v.x, v.y, v.z] for v in study.MeshNodes])
    tets = np.array(study.MeshTets, dtype=np.int32).reshape(-1, 4)
    domain = np.array(study.MeshDomains, dtype=np.int32)
    dens = np.array(study.Densities)
    try:
        points, triangles = core.extract_surface(nodes, tets, domain, dens, float(threshold))
    except core.TopOptError as e:
        raise _native_error(e) from None
    study.Threshold = float(threshold)
    feature = study.Result or study.Document.addObject("Mesh::Feature", study.Name + "_Result")
    study.Result = feature
    feature.Mesh = result_mesh(points, triangles)
    study.Document.recompute()
    return feature
