"""The result back in CAD and its verification, as FreeCAD objects:

- the run's result.step (one solid, written by the core when the study's WriteStep is on) and
  verification.json / verification.vtu (when Verify is on) are kept in the study
  (ResultStep, VerificationVtu: files included in the .FCStd; VerificationReport: the JSON);
- ResultSolid: a Part::Feature holding the solid read from result.step ("Result as solid");
- VerificationMesh / VerificationResult: the result solid's own tet mesh as a FEM mesh and
  the verification's displacement and von Mises stress as a FEM mechanical result;
- VerificationFields: a FEM post-processing pipeline of the same fields, both per node
  (colour bar, clip; FreeCAD 0.20 crashes when a pipeline is coloured by a cell field).

A re-run refreshes these objects in place and removes those its files no longer support, so
nothing stale is left. Works headless (no view settings then) and with the GUI.
"""
import json
import os
import shutil
import tempfile

import FreeCAD
import numpy as np

from . import quiet, units, vtu
from .results import nodal_maximum
from .errors import TopOptError

STEP = "result.step"
REPORT = "verification.json"
VTU = "verification.vtu"

#: field names in the verification's pipeline (units in the names: FEM's colour bar shows only numbers)
DISPLACEMENT = "Displacement (mm)"
VON_MISES = "von Mises stress (MPa)"


def _keep_file(study, prop, name, data, folder):
    """Stores `data` (bytes, or None for none) in the study's included-file property `prop`.
    FreeCAD 0.20 cannot empty such a property: for none, a held file is replaced by an empty
    one (the document does not keep a stale copy) and ResultFiles no longer lists it."""
    if data is None and not getattr(study, prop):
        return
    path = os.path.join(folder, name)
    with open(path, "wb") as f:
        f.write(data or b"")
    setattr(study, prop, path)  # FreeCAD copies the file into the document


def store_files(study, files):
    """Keeps a run's result files in the study. files: {name: bytes} as the worker returns
    them (result.step, verification.json, verification.vtu; any may be missing). Sets
    ResultFiles, ResultStep, VerificationVtu, VerificationReport, ComplianceAsBuilt and
    ComplianceCrisp."""
    study.ResultFiles = sorted(name for name in (STEP, VTU, REPORT) if files.get(name))
    folder = tempfile.mkdtemp(prefix="topopt-files-")
    try:
        _keep_file(study, "ResultStep", STEP, files.get(STEP), folder)
        _keep_file(study, "VerificationVtu", VTU, files.get(VTU), folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    report = files.get(REPORT)
    study.VerificationReport = report.decode("utf-8") if report else ""
    figures = verification_report(study)
    units.set_prop(study, "ComplianceAsBuilt", float(figures.get("compliance_as_built", 0.0) or 0.0), "N*mm")
    units.set_prop(study, "ComplianceCrisp", float(figures.get("crisp", {}).get("compliance", 0.0) or 0.0), "N*mm")


def verification_report(study):
    """The study's verification.json as a dict ({} when the last run wrote none)."""
    text = str(getattr(study, "VerificationReport", "") or "")
    if not text.strip():
        return {}
    try:
        value = json.loads(text)
    except ValueError:
        return {}
    return value if isinstance(value, dict) else {}


def _file(study, prop):
    """The path of the study's included file `prop` when the last run wrote it, else None."""
    path = str(getattr(study, prop, "") or "")
    name = {"ResultStep": STEP, "VerificationVtu": VTU}[prop]
    return path if name in getattr(study, "ResultFiles", []) and os.path.isfile(path) else None


def _why_no_step(study):
    """The sentence that says why the study holds no result.step and what to change."""
    if study.Result is None:
        return "the study has no result yet: run it first"
    failed = verification_report(study).get("failed", {}).get("step")
    if failed and failed.get("code") == "TooLarge":  # past the budget: the core names the job's key
        return ("the last run could not write the result as a STEP solid (%s): raise the study's "
                "StepMaxTriangles (Output) and run again" % failed.get("message", "unknown reason"))
    if failed:
        return ("the last run could not write the result as a STEP solid (%s): try another mesh size or "
                "threshold and run again" % failed.get("message", "unknown reason"))
    if not getattr(study, "WriteStep", True):
        return ("the last run wrote no STEP file because the study's WriteStep (Output) is off: turn it on "
                "and run the study again")
    return "the last run wrote no STEP file: run the study again (its WriteStep, under Output, must be on)"


def step_path(study):
    """The path of the result.step the study's last run wrote. Raises TopOptError saying which
    setting to change when there is none."""
    path = _file(study, "ResultStep")
    if path is None:
        raise TopOptError(_why_no_step(study), "InvalidParameter")
    return path


def run_threshold(study):
    """The threshold of the shape in the study's result.step (verification.json's step
    section), or None when the run wrote no STEP or recorded no threshold."""
    value = verification_report(study).get("step", {}).get("threshold")
    return float(value) if isinstance(value, (int, float)) else None


def step_at_threshold(study, folder, threshold=None):
    """The path of a STEP file holding the study's result at `threshold` (None: the study's
    current Threshold, what the threshold slider shows; threshold_solid.chosen): the run's
    result.step at the run's threshold (threshold_solid.is_the_runs), else one the worker
    writes into `folder` from the stored densities (runner.extract_at with step, the shape the
    slider shows). Raises TopOptError when the study has no result, the threshold is outside
    (0, 1), or the shape cannot become a valid solid (saying what to change)."""
    from . import runner, threshold_solid
    run_step = step_path(study)  # a run that wrote no STEP (WriteStep off) gets none at any threshold
    threshold = threshold_solid.chosen(study, threshold)
    if threshold_solid.is_the_runs(study, threshold):
        return run_step
    result = runner.extract_at(study, threshold, step=True)
    data = result.get("files", {}).get(STEP)
    if not data:
        raise TopOptError("the result at threshold %.3f could not be written as a STEP solid: move the threshold "
                          "slider and try again" % threshold, "InvalidShape")
    path = os.path.join(folder, STEP)
    with open(path, "wb") as f:
        f.write(data)
    return path


def read_step(path):
    """The shape in the STEP file at `path` (Part.read: FreeCAD 0.20 and 1.x alike), checked
    to hold one valid solid. Raises TopOptError otherwise."""
    import Part
    try:
        with quiet.no_progress_lines():
            shape = Part.read(path)
    except Exception as e:  # OCCT's reader failed: FreeCAD raises its own exception types
        raise TopOptError("cannot read the result's STEP file (%s): run the study again" % e, "Io") from None
    if len(shape.Solids) != 1 or not shape.isValid():
        raise TopOptError("the result's STEP file holds %d solid(s)%s, not one valid solid: run the study again "
                          "with another mesh size" % (len(shape.Solids), "" if shape.isValid() else " (invalid)"),
                          "InvalidShape")
    return shape.Solids[0]


def make_solid_feature(study, shape):
    """The study's ResultSolid (a Part::Feature, created once) holding `shape`."""
    doc = study.Document
    feature = study.ResultSolid
    if feature is None or feature.TypeId != "Part::Feature":
        feature = doc.addObject("Part::Feature", study.Name + "_ResultSolid")
        study.ResultSolid = feature
    feature.Label = "%s result solid" % study.Label
    feature.Shape = shape
    vo = feature.ViewObject
    if vo is not None:
        from .results import RESULT_COLOUR
        vo.ShapeColor = RESULT_COLOUR
        vo.DisplayMode = "Shaded"  # a solid of thousands of planar faces: their edges drawn looked like a mesh
    return feature


def refresh_solid(study):
    """After a run: the study's ResultSolid, if the user made one, re-read from the new
    result.step, or removed when the run wrote none (a stale solid would mislead)."""
    feature = study.ResultSolid
    if feature is None:
        return
    path = _file(study, "ResultStep")
    try:
        if path is not None:
            make_solid_feature(study, read_step(path))
            return
    except TopOptError as e:  # the run itself succeeded: say so, and drop the stale solid
        FreeCAD.Console.PrintWarning("TopOpt: %s\n" % e)
    study.ResultSolid = None
    study.Document.removeObject(feature.Name)


# --- the verification in FEM ---------------------------------------------------------------

def _first(fields, prefix, what):
    """The first field of `fields` ({name: array}) whose name starts with `prefix` (the
    verification writes one per load case: displacement_<case>, von_mises_<case>)."""
    for name in sorted(fields):
        if name.startswith(prefix):
            return fields[name]
    raise TopOptError("the verification's VTU holds no %s field: run the study again" % what, "Io")


def _remove_verification(study):
    doc = study.Document
    for name in ("VerificationFields", "VerificationResult", "VerificationMesh"):
        obj = getattr(study, name)
        if obj is not None:
            setattr(study, name, None)
            doc.removeObject(obj.Name)


def _link(study, link, kind, make, label):
    """The object the study links as `link`, made with make() when missing or of another kind."""
    obj = getattr(study, link)
    if obj is None or obj.TypeId != kind:
        obj = make()
        setattr(study, link, obj)
    obj.Label = label
    return obj


def _verification_objects(study, u, vm_nodes, path):
    import Fem
    import ObjectsFem
    doc, name = study.Document, study.Name
    mesh = Fem.FemMesh()
    mesh.read(path)
    mesh_obj = _link(study, "VerificationMesh", "Fem::FemMeshObjectPython",
                     lambda: ObjectsFem.makeMeshResult(doc, name + "_VerificationMesh"),
                     "%s verification mesh" % study.Label)
    mesh_obj.FemMesh = mesh
    res = _link(study, "VerificationResult", "Fem::FemResultObjectPython",
                lambda: ObjectsFem.makeResultMechanical(doc, name + "_VerificationResult"),
                "%s verification (as built)" % study.Label)
    from .results import fill_mechanical_result
    fill_mechanical_result(res, mesh_obj, u, vm_nodes)
    pipe = _link(study, "VerificationFields", "Fem::FemPostPipeline", lambda: _make_pipeline(doc, name),
                 "%s verification fields" % study.Label)
    pipe.read(path)
    pipe.recomputeChildren()
    return res


def _make_pipeline(doc, name):
    """A FEM post pipeline shown as a surface: set before it holds data, as FEM's own solvers
    do (FreeCAD 0.20's pipeline view crashes when its display mode changes on some data)."""
    pipe = doc.addObject("Fem::FemPostPipeline", name + "_VerificationFields")
    if pipe.ViewObject is not None:
        pipe.ViewObject.DisplayMode = "Surface"
    return pipe


def update_verification(study):
    """After a run: the verification's FEM mesh, FEM result and fields pipeline made or
    refreshed from the study's VerificationVtu, or removed when the run wrote none. Nodal von
    Mises is the largest of the tets around each node (its maximum is the JSON's). Returns the
    FEM result object or None."""
    path = _file(study, "VerificationVtu")
    if path is None:
        _remove_verification(study)
        return None
    nodes, tets, points, cells = vtu.read_tets(path)
    u = np.asarray(_first(points, "displacement", "displacement"), dtype=np.float64).reshape(-1, 3)
    vm = np.asarray(_first(cells, "von_mises", "von Mises stress"), dtype=np.float64).reshape(-1)
    vm_nodes = nodal_maximum(tets, vm, len(nodes))  # its maximum is the JSON's max_von_mises
    folder = tempfile.mkdtemp(prefix="topopt-verification-")
    try:
        # point data only: FreeCAD 0.20's pipeline view crashes when a cell field is chosen
        fields = vtu.write_tets(os.path.join(folder, "verification.vtu"), nodes, tets,
                                [(DISPLACEMENT, u), (VON_MISES, vm_nodes)])
        res = _verification_objects(study, u, vm_nodes, fields)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    _style_verification(study)
    return res


def _style_verification(study):
    """With the GUI: the verification's mesh, result and fields hidden (the user turns the
    fields on to see them as a coloured surface with FEM's colour bar)."""
    for name in ("VerificationMesh", "VerificationResult", "VerificationFields"):
        obj = getattr(study, name)
        if obj is not None and obj.ViewObject is not None:
            obj.ViewObject.Visibility = False
    pipe = study.VerificationFields
    if pipe is not None and pipe.ViewObject is not None:
        quiet.recompute(study.Document)
        pipe.ViewObject.updateColorBars()


def summary_lines(study):
    """Report-view lines on the result files: the STEP solid and the as-built against the crisp
    design's compliance (or why there is none)."""
    report = verification_report(study)
    lines = []
    step = report.get("step")
    if step:
        lines.append("  result.step: %d solid(s), %d faces (%d planar), %s, %.4g mm³" % (
            step.get("solids", 0), step.get("faces", 0), step.get("planar_faces", 0),
            "valid" if step.get("valid") else "NOT valid", step.get("volume", 0.0)))
    if "compliance_as_built" in report:
        crisp = report.get("crisp", {})
        if not report.get("crisp_carries_load", True):
            lines.append("  verification: the crisp design on the FE mesh does not carry the load (members "
                         "thinner than one tet: the design has not converged)")
        lines.append("  verification: as-built compliance %.6g N·mm vs crisp %.6g N·mm (ratio %.3g); "
                     "max von Mises %.4g MPa, max displacement %.4g mm on %d tets" % (
                         report["compliance_as_built"], crisp.get("compliance", 0.0), report.get("ratio", 0.0),
                         report.get("max_von_mises", 0.0), report.get("max_displacement", 0.0),
                         report.get("tets", 0)))
    for key, failure in sorted(report.get("failed", {}).items()):
        lines.append("  %s failed: %s" % (key, failure.get("message", "")))
    return lines
