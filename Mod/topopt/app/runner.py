"""Running a study: prepare (document → strings, GUI thread), execute (the worker process,
any thread, touches no document), apply (results → document, GUI thread). Headless scripts
call run(). Meshing, runs and re-extraction run in the worker process (topopt.app.worker):
whatever fails there, the document is only touched after success.
"""
import FreeCAD

from . import checks
from . import job as jobmod
from . import worker
from .errors import TopOptError

#: seconds the threshold slider's re-extraction may take before it is stopped (it runs while
#: FreeCAD waits)
REEXTRACT_TIMEOUT = 300.0


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


def execute(prepared, on_progress=None, cancel=None):
    """Runs mesh → SIMP → surface in the worker process. on_progress(record) gets a dict per
    stage ({"stage", "fraction", "message"}) and iteration ({"iteration", "compliance",
    "volume", "change", "seconds"}) in the calling thread; it returns True to cancel, False or
    None to go on. cancel(), if given, is polled several times a second and cancels on True
    (this is how a Cancel button stops a worker that has gone silent). Returns the result
    dict: nodes, tets, domain, boundary_triangles, boundary_faces, boundary_nondesign_faces,
    densities, history, threshold, surface_points, surface_triangles, surface_tags, status,
    seconds, warnings. Raises TopOptError (see worker.run)."""
    return worker.run("optimize", job=prepared.job, part=prepared.part_brep, nondesign=prepared.nondesign_brep,
                      on_progress=on_progress, cancel=cancel)


def mesh_only(study, on_progress=None, cancel=None):
    """Meshes the study's shapes (no optimisation) in the worker process and stores the tagged
    mesh in the study. Returns the result dict (nodes, tets, domain, boundary triangles and
    faces, min_radius_ratio, mean_radius_ratio, warnings)."""
    prepared = prepare(study)
    result = worker.run("mesh", job=prepared.job, part=prepared.part_brep, nondesign=prepared.nondesign_brep,
                        on_progress=on_progress, cancel=cancel)
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
    a Mesh feature (created once, updated on later runs). Returns that feature. Everything is
    converted before the first property is set, so that a bad result leaves the study as it was."""
    doc = study.Document
    shape = result_mesh(result["surface_points"], result["surface_triangles"])
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
    feature.Mesh = shape
    doc.recompute()
    return feature


def run(study, on_progress=None, cancel=None):
    """prepare → execute → apply in the calling thread; returns the result Mesh feature."""
    return apply(study, execute(prepare(study), on_progress, cancel))


def reextract(study, threshold, cancel=None):
    """Re-extracts the result shape from the stored densities at another threshold (no
    re-run), in the worker process. threshold: in (0, 1); cancel(): polled, True cancels.
    Stopped after REEXTRACT_TIMEOUT seconds. Returns the result Mesh feature.
    Raises TopOptError if the study has no result, if what it stored is damaged, or if the
    worker fails (the document is then unchanged)."""
    if not study.Densities:
        raise TopOptError("the study has no densities yet: run it first", "InvalidParameter")
    threshold = checks.in_range(threshold, "threshold", 0.0, 1.0, open_low=True, open_high=True)
    nodes, tets, domain, densities = checks.stored_mesh(study)
    result = worker.run("extract_surface", arrays={"nodes": nodes, "tets": tets, "domain": domain,
                                                   "densities": densities},
                        params={"threshold": threshold}, cancel=cancel, timeout=REEXTRACT_TIMEOUT)
    shape = result_mesh(result["surface_points"], result["surface_triangles"])
    study.Threshold = threshold
    feature = study.Result or study.Document.addObject("Mesh::Feature", study.Name + "_Result")
    study.Result = feature
    feature.Mesh = shape
    study.Document.recompute()
    return feature
