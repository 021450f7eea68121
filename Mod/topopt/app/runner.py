"""Running a study: prepare (document → strings, GUI thread), execute (the worker process,
any thread, touches no document), apply (results → document, GUI thread). Headless scripts
call run(). Meshing, runs and re-extraction run in the worker process (topopt.app.worker):
whatever fails there, the document is only touched after success, and apply() happens in one
undo transaction ("TopOpt run"), so Edit > Undo takes a whole run back.
"""
import contextlib

import FreeCAD
import numpy as np

from . import asbuilt
from . import checks
from . import job as jobmod
from . import progress
from . import quiet
from . import results
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

    @property
    def max_iterations(self):
        return int(self.job["optimization"]["max_iterations"])


def _shape_breps(study):
    """(part, non-design) of the study as the worker takes them: BREP strings, "" for no
    non-design solids."""
    nd = jobmod.nondesign_compound(study)
    return study.Part.Shape.exportBrepToString(), nd.exportBrepToString() if nd else ""


def prepare(study):
    job = jobmod.study_to_job(study)
    return PreparedRun(job, *_shape_breps(study))


@contextlib.contextmanager
def transaction(doc, name):
    """One undo step named `name` for what happens inside (Edit > Undo takes it back whole);
    if anything inside raises, the step is aborted, which restores the document where undo is
    on (it always is with the GUI)."""
    doc.openTransaction(name)
    try:
        yield
    except BaseException:
        doc.abortTransaction()
        raise
    doc.commitTransaction()


def execute(prepared, on_progress=None, cancel=None, on_result=None):
    """Runs mesh → SIMP → surface → the last iterate's analysis in the worker process.
    on_progress(record) gets a dict per stage ({"stage", "fraction", "message"}) and iteration
    ({"iteration", "compliance", "volume", "change", "seconds"}) in the calling thread; it
    returns True to cancel, False or None to go on. cancel(), if given, is polled several
    times a second and cancels on True (this is how a Cancel button stops a worker that has
    gone silent). Returns the result dict: nodes, tets, domain, boundary_triangles,
    boundary_faces, boundary_nondesign_faces, densities, displacement (#V x 3, mm) and
    von_mises (#T, MPa) of the last iterate, history, threshold, surface_points,
    surface_triangles, surface_tags, status, seconds, warnings, files. on_result(result):
    result first, verification after: when the job verifies its result (the study's Verify),
    called in the calling thread with the result dict as soon as the shape (and result.step)
    is written, before the verification; the dict returned at the end then adds the
    verification's files (apply_verification), and a cancel after on_result stops the
    verification only. Without verification on_result is never called. Raises TopOptError
    (see worker.run)."""
    first = on_result is not None and bool(prepared.job.get("output", {}).get("verification"))
    return worker.run("optimize", job=prepared.job, part=prepared.part_brep, nondesign=prepared.nondesign_brep,
                      on_progress=on_progress, cancel=cancel, params={"result_first": 1} if first else None,
                      on_result=on_result if first else None)


def store_mesh(study, nodes, tets, domain, answer=None):
    """Keeps the analysis mesh in the study (for re-extraction and the domain view), and from the
    worker's `answer` its boundary numbered by the part's faces (boundary_triangles,
    boundary_faces, boundary_nondesign_faces), so that a re-extraction places the supports and
    loads as the run did."""
    study.MeshNodes = [FreeCAD.Vector(*map(float, p)) for p in nodes]
    study.MeshTets = [int(i) for i in np.asarray(tets).reshape(-1)]
    study.MeshDomains = [int(i) for i in domain]
    answer = answer or {}
    triangles = np.asarray(answer.get("boundary_triangles", []), dtype=np.int64).reshape(-1)
    faces = np.asarray(answer.get("boundary_faces", []), dtype=np.int64).reshape(-1)
    nondesign = np.asarray(answer.get("boundary_nondesign_faces", []), dtype=np.int64).reshape(-1)
    if len(nondesign) != len(faces):  # a mesh without non-design faces
        nondesign = np.zeros(len(faces), dtype=np.int64)
    if hasattr(study, "MeshBoundary"):  # a study made before it kept them gets them on restore
        study.MeshBoundary = [int(i) for i in triangles]
        study.MeshBoundaryFaces = [int(i) for i in faces]
        study.MeshBoundaryNonDesignFaces = [int(i) for i in nondesign]


def mesh_only(study, on_progress=None, cancel=None):
    """Meshes the study's shapes (no optimisation) in the worker process, stores the tagged
    mesh in the study and shows it (DomainMeshes: one FEM mesh per domain). The densities of
    an earlier run no longer match the mesh and are dropped (its result objects stay).
    Returns the result dict (nodes, tets, domain, boundary triangles and faces,
    min_radius_ratio, mean_radius_ratio, warnings)."""
    prepared = prepare(study)
    result = worker.run("mesh", job=prepared.job, part=prepared.part_brep, nondesign=prepared.nondesign_brep,
                        on_progress=on_progress, cancel=cancel)
    with transaction(study.Document, "TopOpt mesh"):
        store_mesh(study, result["nodes"], result["tets"], result["domain"], result)
        study.Densities = []
        results.show_domains(study, result["nodes"], result["tets"], result["domain"])
        quiet.recompute(study.Document)
    _report_warnings(result)
    return result


def result_mesh(points, triangles):
    """A Mesh.Mesh from #P×3 points and #Q×3 triangles (points as FreeCAD.Vector: FreeCAD 0.20
    crashes on Mesh.Mesh((points, facets)) with plain tuples)."""
    import Mesh
    vectors = [FreeCAD.Vector(float(p[0]), float(p[1]), float(p[2])) for p in points]
    facets = [[vectors[int(t[0])], vectors[int(t[1])], vectors[int(t[2])]] for t in triangles]
    with quiet.no_progress_lines():
        return Mesh.Mesh(facets)


def _report_warnings(result):
    """The core's warnings (e.g. the native mesher fell back to Gmsh) to FreeCAD's report view."""
    for w in result.get("warnings", []):
        FreeCAD.Console.PrintWarning("TopOpt: %s\n" % w)


def _result_feature(study, shape, points, triangles, tags, nodes, tets, domain):
    """The study's result shape (created once, updated later), its faces on non-design solids
    coloured apart (tags: the core's surface_tags)."""
    feature = study.Result
    if feature is None:
        feature = study.Document.addObject("Mesh::Feature", study.Name + "_Result")
        study.Result = feature
    feature.Label = "%s result" % study.Label
    feature.Mesh = shape
    results.colour_result(feature, results.facet_domains(points, triangles, nodes, tets, domain, tags))
    return feature


def apply(study, result):
    """Stores the run in the study and makes or refreshes its objects: the result shape, the
    FEM result of the last iterate with its mesh, the fields and density view, and the domain
    meshes if the study shows them. Everything is converted before the first property is set,
    so that a bad result leaves the study as it was. Returns the result shape's feature.
    Callers wrap it in an undo transaction (run() does)."""
    doc = study.Document
    shape = result_mesh(result["surface_points"], result["surface_triangles"])
    nodes = np.asarray(result["nodes"], dtype=np.float64)
    tets = np.asarray(result["tets"], dtype=np.int64)
    domain = np.asarray(result["domain"], dtype=np.int64)
    store_mesh(study, nodes, tets, domain, result)
    study.Densities = [float(x) for x in result["densities"]]
    study.ComplianceHistory = [float(h["compliance"]) for h in result["history"]]
    study.VolumeHistory = [float(h["volume"]) for h in result["history"]]
    study.Threshold = float(result.get("threshold", 0.5))
    study.RunThreshold = study.Threshold  # result.step's: the slider moves Threshold only
    study.Status = result.get("status", "done")
    feature = _result_feature(study, shape, result["surface_points"], result["surface_triangles"],
                              result.get("surface_tags"), nodes, tets, domain)
    results.update_fem_objects(study, result, study.Threshold)
    asbuilt.store_files(study, result.get("files", {}))
    asbuilt.update_verification(study)
    asbuilt.refresh_solid(study)
    if study.DomainMeshes:
        results.show_domains(study, nodes, tets, domain)
    quiet.recompute(doc)
    results.style_result(feature)
    return feature


def apply_verification(study, result):
    """After a result-first run (execute's on_result, then apply): keeps the run's final files
    (result["files"]: result.step, verification.json with the verification's figures,
    verification.vtu) in the study and makes its verification objects (FEM mesh, result,
    fields). Callers wrap it in an undo transaction. Returns the verification's FEM result
    object, or None when the verification failed (verification.json says why)."""
    asbuilt.store_files(study, result.get("files", {}))
    res = asbuilt.update_verification(study)
    quiet.recompute(study.Document)
    return res


def where_results_are(study):
    """A line naming the run's objects and their main figures."""
    parts = []
    if study.Result is not None:
        parts.append("%s (the shape, %.4g mm³)" % (study.Result.Label, study.Result.Mesh.Volume))
    res = study.FemResult
    if res is not None and res.DisplacementLengths:
        parts.append("%s (FEM result: largest displacement %.4g mm, largest von Mises stress %.4g MPa)"
                     % (res.Label, max(res.DisplacementLengths), max(res.vonMises or [0.0])))
    if study.DensityView is not None:
        parts.append("%s (density view)" % study.DensityView.Label)
    if study.VerificationResult is not None:
        parts.append("%s (FEM result of the result solid)" % study.VerificationResult.Label)
    return "  results: " + ("; ".join(parts) if parts else "none")


def report_run(study, result, tracker, seconds):
    """Prints the run summary to the report view (FreeCAD's console without the GUI)."""
    lines = progress.run_summary(study, result, tracker, seconds) + asbuilt.summary_lines(study)
    lines.append(where_results_are(study))
    FreeCAD.Console.PrintMessage("\n".join(lines) + "\n")
    _report_warnings(result)


def run(study, on_progress=None, cancel=None, verbose=True):
    """prepare → execute → apply in the calling thread, apply as one undo step; returns the
    result Mesh feature. With `verbose`, prints one line per stage as it starts and the run
    summary with where the results are (the report view; standard output without the GUI)."""
    prepared = prepare(study)
    tracker = progress.Tracker("optimize", prepared.max_iterations)

    def follow(record):
        if tracker.update(record) and verbose:
            FreeCAD.Console.PrintMessage(progress.stage_line(tracker.stage, prepared.max_iterations) + "\n")
        return on_progress(record) if on_progress is not None else None

    result = execute(prepared, follow, cancel)
    tracker.finish()
    with tracker.timed("document"):
        with transaction(study.Document, "TopOpt run"):
            feature = apply(study, result)
    seconds = tracker.clock() - tracker.started
    if verbose:
        report_run(study, result, tracker, seconds)
    return feature


def extract_at(study, threshold, cancel=None, stored=None, step=False):
    """The result shape of the study's stored densities at `threshold` (in (0, 1)), extracted in
    the worker process; the document is not touched. stored: checks.stored_mesh(study) when
    the caller has it; step: also write it as a STEP solid (the answer's files["result.step"]),
    within the study's StepMaxTriangles, with the study's part and non-design shapes so that
    their cylinders, cones, spheres and tori come back as analytic faces, as in the run's
    result.step. The request carries the study's job and the stored mesh's boundary numbered by
    the part's faces, so that the shape is made as the run made it: its surface settings (with an
    overhang control, its too-flat facets lifted), its hygiene (fill_voids, the bridges' size) and
    its pieces (those joined to the supports and loads kept). A study whose job cannot be made
    any more, or a document that kept no boundary: the worker keeps the largest piece and warns.
    Returns the worker's answer (surface_points #P×3, surface_triangles #Q×3, surface_tags #Q,
    files). cancel(): polled, True cancels. Raises TopOptError if the study has no result, if
    what it stored is damaged, or if the worker fails or runs past REEXTRACT_TIMEOUT seconds."""
    if not study.Densities:
        raise TopOptError("the study has no densities yet: run it first", "InvalidParameter")
    threshold = checks.in_range(threshold, "threshold", 0.0, 1.0, open_low=True, open_high=True)
    nodes, tets, domain, densities = stored if stored is not None else checks.stored_mesh(study)
    shapes = _source_shapes(study) if step else {}
    params = {"threshold": threshold, "join_non_design": 1 if getattr(study, "JoinNonDesign", True) else 0}
    if step:  # the study's STEP budget, as its job's output.step_max_triangles gives it to a run
        params.update(_step_budget(study), step=1)
    try:
        arrays = dict({"nodes": nodes, "tets": tets, "domain": domain, "densities": densities},
                      **checks.stored_boundary(study, len(nodes)))
        return worker.run("extract_surface", job=_extraction_job(study), arrays=arrays, params=params, cancel=cancel,
                          timeout=REEXTRACT_TIMEOUT, **shapes)
    except TopOptError as e:
        if e.code == "TooLarge" and "step_max_triangles" in str(e):  # the core names the job's key
            raise TopOptError("%s (in the workbench: the study's StepMaxTriangles, under Output)" % e,
                              e.code) from e
        raise


def _extraction_job(study):
    """The study's job for a re-extraction: the whole job (its supports and loads place the
    anchors the run cleaned the result by), or, when the study no longer makes one (a support
    or load removed since the run), its optimization section alone, with a warning: the result
    is then cleaned keeping its largest piece."""
    try:
        return jobmod.study_to_job(study)
    except TopOptError as e:
        FreeCAD.Console.PrintWarning("TopOpt: %s: the re-extracted shape keeps the largest piece, not the pieces "
                                     "joined to the supports and loads, and may differ from the run's\n" % e)
        return {"optimization": jobmod.study_optimization(study)}


def _step_budget(study):
    """{"step_max_triangles": N} from the study's StepMaxTriangles (checked, as job_of checks it),
    {} for a study saved before it had one (the core's default)."""
    numbers = jobmod.study_numbers(study)
    return {"step_max_triangles": numbers["StepMaxTriangles"]} if "StepMaxTriangles" in numbers else {}


def _source_shapes(study):
    """{"part", "nondesign"}: the study's shapes as BREP strings for the worker (as prepare
    sends them), or {} when the part is gone or empty: the STEP is then written with facets only."""
    part = getattr(study, "Part", None)
    if part is None or part.Shape.isNull():
        return {}
    part_brep, nondesign_brep = _shape_breps(study)
    return {"part": part_brep, "nondesign": nondesign_brep}


def reextract(study, threshold, cancel=None):
    """Re-extracts the result shape from the stored densities at another threshold (no
    re-run), in the worker process, and moves the density view's cut there; one undo step
    ("TopOpt threshold"). threshold: in (0, 1); cancel(): polled, True cancels. Stopped after
    REEXTRACT_TIMEOUT seconds. Returns the result Mesh feature. Raises TopOptError if the
    study has no result, if what it stored is damaged, or if the worker fails (the document
    is then unchanged). The study's Threshold is the shown shape's: runs never read it."""
    if not study.Densities:
        raise TopOptError("the study has no densities yet: run it first", "InvalidParameter")
    stored = checks.stored_mesh(study)
    nodes, tets, domain, _ = stored
    result = extract_at(study, threshold, cancel, stored)
    shape = result_mesh(result["surface_points"], result["surface_triangles"])
    with transaction(study.Document, "TopOpt threshold %.2f" % threshold):
        study.Threshold = threshold
        feature = _result_feature(study, shape, result["surface_points"], result["surface_triangles"],
                                  result.get("surface_tags"), nodes, tets, domain)
        results.set_density_cut(study, threshold)
        quiet.recompute(study.Document)
    results.style_result(feature)
    return feature
