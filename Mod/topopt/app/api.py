"""Plain scripting API for FreeCADCmd and the Python console.

Shapes go to the native core as BREP text (Shape.exportBrepToString()), so the core links
only OCCT, the same OCCT FreeCAD loads. Every call that meshes, runs or checks shapes runs in
the worker process (topopt.app.worker): a failure of the core ends that process, never
FreeCAD, and comes back as a TopOptError. Arguments are checked here before anything starts.
"""
import json
import os
import shutil
import tempfile

import Part

from . import checks
from . import directions
from . import quiet
from . import units
from . import worker
from .errors import TopOptError  # noqa: F401  (part of the API)

#: seconds a shape check (info) may take before the worker is stopped
INFO_TIMEOUT = 600.0


def _brep(shape):
    if shape is None:
        return ""
    if isinstance(shape, (list, tuple)):
        shape = Part.makeCompound(list(shape)) if shape else None
        if shape is None:
            return ""
    if not isinstance(shape, Part.Shape):
        raise TopOptError("expected a Part shape, got %s" % type(shape).__name__, "InvalidShape")
    return shape.exportBrepToString()


def info(part, nondesign=None, tolerance=-1.0, cancel=None):
    """Check the part and the non-design solids and classify one against the other (in the
    worker process).

    part: a Part.Shape holding one solid (Ω). nondesign: a solid, a compound of solids or a
    list of solids (Ω̄, in order), or None. tolerance: coincidence tolerance in mm (< 0: from
    the part's size). cancel(): polled, True cancels. Returns a dict (see `topopt info --json`):
    counts, volumes, where each non-design face lies on the part, contacts. Raises TopOptError
    with a message saying what to fix.
    """
    tolerance = checks.number(tolerance, "tolerance")
    result = worker.run("info", part=_brep(part), nondesign=_brep(nondesign), params={"tolerance": tolerance},
                        cancel=cancel, timeout=INFO_TIMEOUT)
    return result["report"]


def surface_mesh(shape, size=0.0, doc=None, name="SurfaceMesh", wall_layers=0):
    """The native surface mesh of one shape (every solid closed and outward, each triangle
    tagged with its FreeCAD face number) and its checks, made in the worker process.

    size: target edge length in mm (0: the shape's diagonal / 50). wall_layers: 0 (off) to 4,
    element layers across walls thinner than two sizes. Returns a dict (nodes, triangles,
    faces, failed_faces, failure_reasons, open_edges_per_solid, self_intersecting_pairs,
    min_angle, share_below_20deg, warnings); with `doc`, also adds a Mesh feature `name` to it
    and returns (dict, feature).
    """
    size = checks.in_range(size, "size (mm, 0 for the default)", 0.0)
    wall_layers = int(checks.in_range(wall_layers, "wall_layers", 0, 4))
    result = worker.run("surface_mesh", part=_brep(shape), params={"size": size, "wall_layers": wall_layers})
    if doc is None:
        return result
    import FreeCAD
    import Mesh
    pts = [FreeCAD.Vector(*map(float, p)) for p in result["nodes"]]  # Vectors: FreeCAD 0.20 needs them
    tri = [tuple(int(i) for i in t) for t in result["triangles"]]
    feature = doc.addObject("Mesh::Feature", name)
    feature.Mesh = Mesh.Mesh([[pts[a], pts[b], pts[c]] for a, b, c in tri])
    quiet.recompute(doc)
    return result, feature


# --- Studies -------------------------------------------------------------------------------

def new_study(doc, part, nondesign=(), volume_fraction=0.3, mesh_size=0.0, name="TopOptStudy"):
    """Adds a study to `doc`: `part` is the document object of the whole part (one solid),
    `nondesign` the document objects of the solids to keep, volume_fraction in (0, 1),
    mesh_size in mm (0: automatic). Returns the study object. Everything is checked before
    the study is added."""
    from .study import make_study
    volume_fraction = checks.in_range(volume_fraction, "volume_fraction", 0.0, 1.0, True, True)
    mesh_size = checks.in_range(mesh_size, "mesh_size (mm, 0 for automatic)", 0.0)
    for obj in [part] + list(nondesign):
        if getattr(obj, "Shape", None) is None:
            raise TopOptError("%r is not a document object with a shape: pick a solid" % (obj,), "InvalidShape")
    study = make_study(doc, part, nondesign, name)
    study.VolumeFraction = volume_fraction
    study.MeshSize = mesh_size
    return study


def _faces(study, faces, obj):
    """The References entry [(obj, ("Face3", ...))] for faces of `obj` (default: the study's
    part), every name checked. Raises TopOptError naming the face or what is missing."""
    from .study import is_study
    if not is_study(study):
        raise TopOptError("%r is not a TopOpt study: pass the object api.new_study returned" % (study,),
                          "InvalidParameter")
    obj = obj or study.Part
    if obj is None or getattr(obj, "Shape", None) is None:
        raise TopOptError("the faces must belong to a document object with a shape (the study's part "
                          "or a non-design solid)", "FaceNotFound")
    if isinstance(faces, str):
        faces = [faces]
    try:
        faces = list(faces)
    except TypeError:
        raise TopOptError("faces must be a face name like 'Face3' or a list of them, not %r" % (faces,),
                          "FaceNotFound") from None
    if not faces:
        raise TopOptError("no faces given: name at least one face of %s, like 'Face3'" % obj.Label, "FaceNotFound")
    count = len(obj.Shape.Faces)
    for f in faces:
        if not isinstance(f, str) or not f.startswith("Face") or not f[4:].isdigit() or not 1 <= int(f[4:]) <= count:
            raise TopOptError("%s has no face %r: it has Face1 to Face%d" % (obj.Label, f, count), "FaceNotFound")
    return [(obj, tuple(faces))]


def _add_constraint(study, make, configure):
    """Makes a constraint with make(doc), sets it up with configure(c) and attaches it to the
    study; if anything fails on the way the constraint is removed again, so that no orphan is
    left in the document."""
    doc = study.Document
    c = make(doc)
    try:
        configure(c)
        study.Constraints = list(study.Constraints) + [c]
    except BaseException:
        line = directions.helper_line(c)
        doc.removeObject(c.Name)
        if line is not None:
            doc.removeObject(line.Name)
        raise
    return c


def _fem(maker, name):
    def make(doc):
        import ObjectsFem
        return getattr(ObjectsFem, maker)(doc, name)
    return make


def add_fixed(study, faces, obj=None):
    """Fixes the given faces ("Face3" or ["Face3", "Face4"]) of the part (or of `obj`)."""
    refs = _faces(study, faces, obj)
    return _add_constraint(study, _fem("makeConstraintFixed", "Fixed"), lambda c: setattr(c, "References", refs))


def add_fixed_components(study, faces, x=False, y=False, z=False, obj=None):
    """Fixes only some displacement components on the faces (a roller support)."""
    refs = _faces(study, faces, obj)
    if not (x or y or z):
        raise TopOptError("fix at least one component: pass x=True, y=True or z=True", "InvalidParameter")

    def configure(c):
        c.References = refs
        for axis, fixed in zip("xyz", (x, y, z)):
            setattr(c, axis + "Fix", bool(fixed))
            setattr(c, axis + "Free", not fixed)
    return _add_constraint(study, _fem("makeConstraintDisplacement", "Displacement"), configure)


def add_symmetry(study, faces, obj=None):
    """A symmetry plane on planar faces of the part: their normal displacement is fixed."""
    from .symmetry import make_symmetry_plane
    refs = _faces(study, faces, obj)
    return _add_constraint(study, make_symmetry_plane, lambda c: setattr(c, "References", refs))


def add_force(study, faces, vector, obj=None):
    """A total force (N, a 3-vector) spread over the faces by area. FEM's force constraint
    gets the magnitude and, as its direction reference, a hidden line along the vector
    (topopt.app.directions), so that FEM draws and applies exactly this vector."""
    import FreeCAD
    refs = _faces(study, faces, obj)
    try:
        components = list(vector)
    except TypeError:
        components = []
    if len(components) != 3:
        raise TopOptError("the force must be a vector of three numbers (x, y, z in N), not %r" % (vector,),
                          "InvalidParameter")
    components = [checks.number(x, "the force's %s component" % axis) for axis, x in zip("xyz", components)]
    v = FreeCAD.Vector(*components)
    if v.Length == 0:
        raise TopOptError("the force is zero: give a non-zero vector", "InvalidParameter")

    def configure(c):
        c.References = refs
        units.set_prop(c, "Force", v.Length, "N")
        directions.set_vector_direction(c, v)
    return _add_constraint(study, _fem("makeConstraintForce", "Force"), configure)


def add_pressure(study, faces, value, obj=None):
    """A pressure (MPa) on the faces; positive pushes into the part."""
    refs = _faces(study, faces, obj)
    value = checks.number(value, "the pressure")

    def configure(c):
        c.References = refs
        units.set_prop(c, "Pressure", abs(value), "MPa")
        c.Reversed = value < 0
    return _add_constraint(study, _fem("makeConstraintPressure", "Pressure"), configure)


def _vector(value, name):
    """[x, y, z] of finite numbers, not all zero."""
    try:
        v = [checks.number(c, name) for c in value]
    except TypeError:
        v = []
    if len(v) != 3:
        raise TopOptError("%s must be three numbers [x, y, z] (mm, model axes)" % name, "InvalidParameter")
    if name.endswith(("normal", "axis", "direction", "extrusion")) and not any(v):
        raise TopOptError("%s must not be [0, 0, 0]: give a direction" % name, "InvalidParameter")
    return v


def _whole(value, name, low, high):
    x = checks.in_range(value, name, low, high)
    if x != int(x):
        raise TopOptError("%s is %g: give a whole number" % (name, x), "InvalidParameter")
    return int(x)


def _overhang(direction, angle, base_face, cell):
    """The job's "overhang" dict of set_controls' arguments (checked there)."""
    o = {"direction": _vector(direction, "build_direction"),
         "angle": checks.in_range(angle, "overhang_angle", 10, 80)}
    if base_face is not None:
        name = "Face%d" % _whole(base_face, "base_face", 1, 1e9) if not isinstance(base_face, str) else base_face
        o["base_face"] = name
    if checks.in_range(cell, "overhang_cell", 0, None) > 0:
        o["cell"] = float(cell)
    return o


def set_controls(study, symmetry_planes=(), cyclic=(), patterns=(), extrusion=None, tolerance=0.0,
                 draw_direction=None, parting_point=None, draw_cell=0.0, build_direction=None,
                 overhang_angle=45.0, base_face=None, overhang_cell=0.0, min_member_size=0.0,
                 max_member_size=0.0):
    """Sets the study's geometry controls (docs/optimization.md, "controls"); called without
    arguments it clears them. symmetry_planes: [(point, normal), ...]; cyclic: [(point, axis,
    sectors), ...]; patterns: [(direction, pitch mm, count), ...]; extrusion: a direction or
    None; tolerance: mm, 0 = the mesh's mean edge length. draw_direction: the direction a
    casting die is drawn in, or None; parting_point: with it, a point of the parting plane
    (split casting: two dies drawn apart along ±draw_direction), None for one-sided casting;
    draw_cell: mm, the draw grid's cell side (0: the tolerance). build_direction: the direction
    an additive process builds the part in (from the base plate up), or None: with it the design
    prints without supports at overhang_angle (degrees from the plate, [10, 80], 45 usual) on the
    base plate base_face ("Face5" or 5, a flat face of the part facing against the direction;
    None: the plate touches the part's lowest point), overhang_cell: mm, the overhang lattice's
    spacing (0: the tolerance). min_member_size: mm, the thinnest member and gap (robust
    formulation; sets the filter radius; 0: none); max_member_size: mm, the widest solid ball (a
    local volume constraint; needs MMA, so the study's Update becomes "mma"; 0: none). Vectors
    are [x, y, z] in model axes. Returns the controls as the job's dict. Raises TopOptError
    naming the argument."""
    c = {}
    if symmetry_planes:
        c["symmetry_planes"] = [{"point": _vector(p, "symmetry plane %d point" % (i + 1)),
                                 "normal": _vector(n, "symmetry plane %d normal" % (i + 1))}
                                for i, (p, n) in enumerate(symmetry_planes)]
    if cyclic:
        c["cyclic"] = [{"point": _vector(p, "cyclic %d point" % (i + 1)), "axis": _vector(a, "cyclic %d axis" % (i + 1)),
                        "sectors": _whole(n, "cyclic %d sectors" % (i + 1), 2, 360)}
                       for i, (p, a, n) in enumerate(cyclic)]
    if patterns:
        c["patterns"] = [{"direction": _vector(d, "pattern %d direction" % (i + 1)),
                          "pitch": checks.in_range(p, "pattern %d pitch" % (i + 1), 0, None, open_low=True),
                          "count": _whole(n, "pattern %d count" % (i + 1), 2, 10000)}
                         for i, (d, p, n) in enumerate(patterns)]
    if extrusion is not None:
        c["extrusion"] = _vector(extrusion, "extrusion")
    if draw_direction is not None:
        draw = {"direction": _vector(draw_direction, "draw_direction")}
        if parting_point is not None:
            draw["parting_point"] = _vector(parting_point, "parting_point")
        if checks.in_range(draw_cell, "draw_cell", 0, None) > 0:
            draw["cell"] = float(draw_cell)
        c["draw_direction"] = draw
    elif parting_point is not None:
        raise TopOptError("parting_point needs draw_direction: give the direction the dies are drawn in",
                          "InvalidParameter")
    if build_direction is not None:
        c["overhang"] = _overhang(build_direction, overhang_angle, base_face, overhang_cell)
    elif base_face is not None:
        raise TopOptError("base_face needs build_direction: give the direction the part is built in",
                          "InvalidParameter")
    if checks.in_range(tolerance, "tolerance", 0, None) > 0:
        c["tolerance"] = float(tolerance)
    if checks.in_range(min_member_size, "min_member_size", 0, None) > 0:
        c["min_member_size"] = float(min_member_size)
    if checks.in_range(max_member_size, "max_member_size", 0, None) > 0:
        c["max_member_size"] = float(max_member_size)
    update = "mma" if "max_member_size" in c else None
    check_optimization(study, controls=c, update=update)
    study.GeometryControls = json.dumps(c) if c else ""
    if update and study.Update == "oc":
        study.Update = "mma"  # the local volume constraint needs MMA; visible in the property editor
    return c


def check_optimization(study, controls=None, responses=None, update=None):
    """Checks the study's optimisation settings with `controls` and/or `responses` (dicts as
    the job has them; None: the study's own) exactly as a job file is checked (the core's
    parser), without running anything. update: the update scheme to check with (None: the
    study's Update). Raises TopOptError naming the job key and the value to
    give, e.g. "optimization.stress_limit must be a positive von Mises stress in MPa"."""
    from . import core
    from . import job as jobmod
    opt = {"volume_fraction": checks.in_range(study.VolumeFraction, "VolumeFraction", 0, 1, True, True)}
    if (update or study.Update) == "mma":
        opt["update"] = "mma"
    opt.update(jobmod.study_responses(study) if responses is None else responses)
    controls = jobmod.study_controls(study) if controls is None else controls
    if controls:
        opt["controls"] = controls
    probe = {"supports": [{"type": "fixed", "faces": ["Face1"]}],
             "load_cases": [{"name": "check", "loads": [{"type": "force", "faces": ["Face1"], "vector": [0, 0, 1]}]}],
             "optimization": opt}
    core.check_job(probe)


def _limit_faces(study, faces, i):
    """The job's face names of displacement limit i from the job's own names ("Face7",
    "NonDesign:Face2") or picked references [(obj, ("Face7",)), ...] on the part or a
    non-design solid; vertices and edges are refused (the limit is a faces' mean)."""
    from . import job as jobmod
    what = "displacement limit %d" % i
    if isinstance(faces, str):
        faces = [faces]
    if faces and all(isinstance(f, str) for f in faces):
        nd = [f for f in faces if f.startswith("NonDesign:")]
        total = sum(len(o.Shape.Faces) for o in study.NonDesign)
        for f in nd:
            n = f[len("NonDesign:Face"):]
            if not f.startswith("NonDesign:Face") or not n.isdigit() or not 1 <= int(n) <= total:
                raise TopOptError("%s: the non-design solids have no face %r (NonDesign:Face1 to NonDesign:Face%d)"
                                  % (what, f, total), "FaceNotFound")
        part = [f for f in faces if f not in nd]
        return (jobmod.face_names(study, _faces(study, part, None), what) if part else []) + nd
    refs = [(obj, (subs,) if isinstance(subs, str) else tuple(subs)) for obj, subs in (faces or [])]
    for obj, subs in refs:
        for sub in subs:
            if sub.startswith("Vertex") or sub.startswith("Edge"):
                raise TopOptError("%s is on %s of %s: displacement limits go on faces (their mean "
                                  "displacement is limited); pick a face" % (what, sub, obj.Label), "FaceNotFound")
    return jobmod.face_names(study, refs, what)


def set_responses(study, objective="compliance", compliance_limit=None, stress_limit=None, displacement_limits=()):
    """Sets what the study optimises and its limits (docs/optimization.md); called with no
    arguments it goes back to the stiffest design of the volume fraction.

    objective: "compliance" (stiffest design of VolumeFraction), "mass" (lightest design
    within the limits; needs at least one) or "frequency" (highest first eigenfrequency).
    compliance_limit: N·mm (with "mass" only). stress_limit: von Mises, MPa.
    displacement_limits: [(faces, direction [x, y, z], limit mm), ...] with faces as part face
    names ("Face7" or a list) or picked references [(obj, ("Face7",))]. Checked as a job file
    is; anything beyond compliance needs MMA, so the study's Update becomes "mma". Returns the
    responses as the job's dict. Raises TopOptError naming the value at fault."""
    r = {}
    if objective != "compliance":
        r["objective"] = str(objective)
    if compliance_limit is not None:
        r["compliance_limit"] = checks.number(compliance_limit, "compliance_limit (N·mm)")
    if stress_limit is not None:
        r["stress_limit"] = checks.number(stress_limit, "stress_limit (MPa)")
    limits = []
    for i, (faces, direction, limit) in enumerate(displacement_limits or (), 1):
        limits.append({"faces": _limit_faces(study, faces, i),
                       "direction": _vector(direction, "displacement limit %d direction" % i),
                       "limit": checks.number(limit, "displacement limit %d (mm)" % i)})
    if limits:
        r["displacement_limits"] = limits
    check_optimization(study, responses=r, update="mma" if r else None)
    if r and study.Update == "oc":
        study.Update = "mma"  # OC handles one volume constraint only; visible in the property editor
    study.Responses = json.dumps(r) if r else ""
    return r


def job_of(study):
    """The job dict the study runs (the same format as hand-written job files)."""
    from .job import study_to_job
    return study_to_job(study)


def run(study, on_progress=None, cancel=None, verbose=True):
    """Runs the study (mesh → SIMP → result surface → analysis of the last iterate) in the
    worker process and returns the result Mesh feature; the study's other results (FEM result,
    fields, density view) are linked from it. on_progress(record) is called per stage and
    iteration and returns True to cancel (False or None to go on); cancel(), if given, is
    polled several times a second and cancels on True. The document is only changed when the
    run succeeds, in one undo step. With `verbose`, one line per stage and the run summary
    (with where the results are) go to the report view, or standard output without the GUI."""
    from . import runner
    return runner.run(study, on_progress, cancel, verbose)


def save(doc, path=None):
    """Saves `doc` (as doc.saveAs(path) does, or doc.save() without a path) without FreeCAD's
    console progress lines in headless scripts. Returns the file's path."""
    return quiet.save(doc, path)


def _output_path(study, path, suffix):
    """`path` made absolute, checked before anything is written: the study has a result, the
    folder exists, the path is not a folder. Raises TopOptError saying what to fix."""
    if getattr(study, "Result", None) is None:
        raise TopOptError("the study has no result yet: run it first", "InvalidParameter")
    path = os.path.abspath(os.path.expanduser(str(path)))
    folder = os.path.dirname(path)
    if not os.path.isdir(folder):
        raise TopOptError("the folder %s does not exist: create it or pick another folder for %s"
                          % (folder, os.path.basename(path)), "Io")
    if os.path.isdir(path):
        raise TopOptError("%s is a folder: give a file name ending in %s" % (path, suffix), "Io")
    return path


def _written(path, write):
    """Runs write(); a failure or a missing file afterwards becomes TopOptError("Io")."""
    try:
        with quiet.no_progress_lines():
            write()
    except Exception as e:  # OSError, or FreeCAD's own exception types
        raise TopOptError("cannot write %s (%s): check that the folder is writable"
                          % (path, getattr(e, "strerror", None) or e), "Io") from None
    if not os.path.isfile(path):
        raise TopOptError("cannot write %s: check that the folder is writable" % path, "Io")
    return path


def export_stl(study, path):
    """Writes the study's result shape to an STL file at `path`. Raises TopOptError if the
    study has no result, if the folder does not exist, or if the file cannot be written."""
    path = _output_path(study, path, ".stl")
    return _written(path, lambda: study.Result.Mesh.write(path))


def export_step(study, path, threshold=None):
    """Writes the study's result as one CAD solid to a STEP file at `path`, at `threshold` (None:
    the study's current Threshold, where the threshold slider left it): the run's result.step at
    the run's threshold, else the shape at that threshold written by the core from the stored
    densities (asbuilt.step_at_threshold). Returns the path. Raises TopOptError if the study has
    no result, if its run wrote no STEP file (saying which setting to turn on), if the shape
    cannot become a valid solid, if the folder does not exist, or if the file cannot be
    written."""
    from . import asbuilt
    path = _output_path(study, path, ".step")
    folder = tempfile.mkdtemp(prefix="topopt-step-")
    try:
        source = asbuilt.step_at_threshold(study, folder, threshold)
        return _written(path, lambda: shutil.copyfile(source, path))
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def result_solid(study, threshold=None):
    """Adds (or refreshes) the study's ResultSolid: a Part::Feature holding the one solid read
    from the study's result as STEP at `threshold` (None: the study's current Threshold, where
    the threshold slider left it; asbuilt.step_at_threshold), in one undo step ("TopOpt result
    as solid"). Returns the feature. Raises TopOptError if the study has no result or its run
    wrote no STEP file (saying which setting to turn on), or if the file does not hold one
    valid solid; the document is then unchanged."""
    from . import asbuilt, runner
    from .study import is_study
    if not is_study(study):
        raise TopOptError("%r is not a TopOpt study: pass the object api.new_study returned" % (study,),
                          "InvalidParameter")
    folder = tempfile.mkdtemp(prefix="topopt-step-")
    try:
        shape = asbuilt.read_step(asbuilt.step_at_threshold(study, folder, threshold))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    with runner.transaction(study.Document, "TopOpt result as solid"):
        feature = asbuilt.make_solid_feature(study, shape)
        quiet.recompute(study.Document)
    return feature
