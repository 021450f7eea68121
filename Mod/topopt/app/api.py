"""Plain scripting API for FreeCADCmd and the Python console.

Shapes go to the native core as BREP strings (Shape.exportBrepToString()), so the core links
only OCCT, the same OCCT FreeCAD loads.
"""
import Part

from .. import native


from .errors import TopOptError  # noqa: F401  (part of the API)


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


def info(part, nondesign=None, tolerance=-1.0):
    """Check the part and the non-design solids and classify one against the other.

    part: a Part.Shape holding one solid (Ω). nondesign: a solid, a compound of solids or a
    list of solids (Ω̄, in order), or None. Returns a dict (see `topopt info --json`):
    counts, volumes, where each non-design face lies on the part, contacts.
    Raises TopOptError with a message saying what to fix.
    """
    try:
        return native().info(_brep(part), _brep(nondesign), tolerance)
    except native().TopOptError as e:
        raise TopOptError(str(e), getattr(e, "code", "Internal")) from None


def surface_mesh(shape, size=0.0, doc=None, name="SurfaceMesh"):
    """The native surface mesh of one shape (every solid closed and outward, each triangle
    tagged with its FreeCAD face number) and its checks.

    size: target edge length in mm (0: the shape's diagonal / 50). Returns the dict of the
    native `surface_mesh` (nodes, triangles, faces, failed_faces, open_edges_per_solid,
    self_intersecting_pairs, min_angle, share_below_20deg); with `doc`, also adds a Mesh
    feature `name` to it and returns (dict, feature).
    """
    try:
        result = native().surface_mesh(_brep(shape), float(size))
    except native().TopOptError as e:
        raise TopOptError(str(e), getattr(e, "code", "Internal")) from None
    if doc is None:
        return result
    import FreeCAD
    import Mesh
    pts = [FreeCAD.Vector(*map(float, p)) for p in result["nodes"]]  # Vectors: FreeCAD 0.20 needs them
    tri = [tuple(int(i) for i in t) for t in result["triangles"]]
    feature = doc.addObject("Mesh::Feature", name)
    feature.Mesh = Mesh.Mesh([[pts[a], pts[b], pts[c]] for a, b, c in tri])
    doc.recompute()
    return result, feature


# --- Studies -------------------------------------------------------------------------------

def new_study(doc, part, nondesign=(), volume_fraction=0.3, mesh_size=0.0, name="TopOptStudy"):
    """Adds a study to `doc`: `part` is the document object of the whole part (one solid),
    `nondesign` the document objects of the solids to keep. Returns the study object."""
    from .study import make_study
    if not 0.0 < volume_fraction < 1.0:
        raise TopOptError("volume fraction %g is out of range: give a value between 0 and 1"
                          % volume_fraction, "InvalidParameter")
    study = make_study(doc, part, nondesign, name)
    study.VolumeFraction = volume_fraction
    study.MeshSize = mesh_size
    return study


def _faces(obj, faces):
    faces = [faces] if isinstance(faces, str) else list(faces)
    shape = obj.Shape
    for f in faces:
        if not f.startswith("Face") or not f[4:].isdigit() or not 1 <= int(f[4:]) <= len(shape.Faces):
            raise TopOptError("%s has no face '%s': it has Face1 to Face%d"
                              % (obj.Label, f, len(shape.Faces)), "FaceNotFound")
    return [(obj, tuple(faces))]


def _attach(study, constraint):
    study.Constraints = list(study.Constraints) + [constraint]
    return constraint


def add_fixed(study, faces, obj=None):
    """Fixes the given faces ("Face3" or ["Face3", "Face4"]) of the part (or of `obj`)."""
    import ObjectsFem
    c = ObjectsFem.makeConstraintFixed(study.Document, "Fixed")
    c.References = _faces(obj or study.Part, faces)
    return _attach(study, c)


def add_fixed_components(study, faces, x=False, y=False, z=False, obj=None):
    """Fixes only some displacement components on the faces (a roller support)."""
    import ObjectsFem
    c = ObjectsFem.makeConstraintDisplacement(study.Document, "Displacement")
    c.References = _faces(obj or study.Part, faces)
    for axis, fixed in zip("xyz", (x, y, z)):
        setattr(c, axis + "Fix", bool(fixed))
        setattr(c, axis + "Free", not fixed)
    return _attach(study, c)


def add_symmetry(study, faces, obj=None):
    """A symmetry plane on planar faces of the part: their normal displacement is fixed."""
    from .symmetry import make_symmetry_plane
    return _attach(study, make_symmetry_plane(study.Document, _faces(obj or study.Part, faces)))


def add_force(study, faces, vector, obj=None):
    """A total force (N, a 3-vector) spread over the faces by area."""
    import FreeCAD
    import ObjectsFem
    v = FreeCAD.Vector(*vector)
    if v.Length == 0:
        raise TopOptError("the force is zero: give a non-zero vector", "InvalidParameter")
    c = ObjectsFem.makeConstraintForce(study.Document, "Force")
    c.References = _faces(obj or study.Part, faces)
    c.Force = v.Length
    # FreeCAD's force takes its direction from a reference edge or face; scripted forces get
    # their direction stored directly in DirectionVector's place through a hidden property.
    c.addProperty("App::PropertyVector", "TopOptDirection", "TopOpt", "Force direction (script)")
    c.TopOptDirection = v.normalize()
    return _attach(study, c)


def add_pressure(study, faces, value, obj=None):
    """A pressure (MPa) on the faces; positive pushes into the part."""
    import ObjectsFem
    c = ObjectsFem.makeConstraintPressure(study.Document, "Pressure")
    c.References = _faces(obj or study.Part, faces)
    c.Pressure = abs(value)
    c.Reversed = value < 0
    return _attach(study, c)


def job_of(study):
    """The job dict the study runs (the same format as hand-written job files)."""
    from .job import study_to_job
    return study_to_job(study)


def run(study, on_progress=None):
    """Runs the study (mesh → SIMP → result surface) and returns the result Mesh feature.
    on_progress(record) is called per stage and iteration; returning True cancels."""
    from . import runner
    return runner.run(study, on_progress)


def export_stl(study, path):
    """Writes the study's result shape to an STL file."""
    if study.Result is None:
        raise TopOptError("the study has no result yet: run it first", "InvalidParameter")
    study.Result.Mesh.write(path)
    return path
