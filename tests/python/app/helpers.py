"""Shared by the FreeCADCmd tests: where the reference data is."""
import os

SHARED = os.environ.get("TOPOPT_SHARED_DATA", "")


def example(name):
    return os.path.join(SHARED, "examples", name)


def bundled(name):
    """A file of the project's bundled examples (examples/)."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "examples", name)


def box_study(name="Box", iterations=6, mesh_size=4.0, load_face="Face2"):
    """A document with a 60 x 10 x 10 mm box fixed at x = 0 (Face1) and pulled down at x = 60
    (Face2), and a study on it that runs in a few seconds. Returns (doc, study)."""
    import FreeCAD
    import Part
    from topopt.app import api
    doc = FreeCAD.newDocument(name)
    part = doc.addObject("Part::Feature", "Beam")
    part.Shape = Part.makeBox(60, 10, 10)
    doc.recompute()
    study = api.new_study(doc, part, (), volume_fraction=0.4, mesh_size=mesh_size)
    study.MaxIterations = iterations
    api.add_fixed(study, "Face1")
    api.add_force(study, load_face, (0, 0, -100))
    doc.recompute()
    return doc, study


def top_loaded_box_study(name):
    """box_study's box fixed at x = 0 (Face1) but pressed down on its top (Face6, 100 N), 10
    iterations at 3 mm: both faces stay on the result, as the verification needs (since
    optimization.keep_loaded_faces, on by default, a tip load on the end face Face2 keeps its
    face too; without it the design left that face). Returns (doc, study)."""
    return box_study(name, iterations=10, mesh_size=3.0, load_face="Face6")


def _describe(value):
    """A comparable stand-in for a property value (objects by name, shapes and meshes by
    their counts and volume)."""
    if isinstance(value, (list, tuple)):
        return tuple(_describe(v) for v in value)
    if hasattr(value, "TypeId") and hasattr(value, "Document") and hasattr(value, "Name"):
        return ("object", value.Name)
    if hasattr(value, "CountFacets"):
        return ("mesh", value.CountPoints, value.CountFacets, round(value.Volume, 6))
    if hasattr(value, "ShapeType"):
        return ("shape", value.ShapeType, len(value.Faces), round(value.Volume, 6))
    if type(value).__name__ == "Quantity":  # a document keeps 16 decimals of its value in internal units
        return ("quantity", "%.16f" % value.Value, str(value.Unit))
    if type(value).__name__ in ("Vector", "Placement", "Rotation"):
        return str(value)
    if isinstance(value, float):  # a document keeps 16 significant digits of a float, not 17
        return "%.15g" % value
    text = repr(value)
    if " at 0x" in text:  # a Python object (a proxy): its class, not its address
        return ("instance", type(value).__module__, type(value).__name__)
    return text


def snapshot(doc):
    """{object name: (type, {property: value})} of every object of `doc`, to tell whether a
    failed call left the document exactly as it was."""
    out = {}
    for o in doc.Objects:
        props = {}
        for p in o.PropertiesList:
            try:
                value = o.getPropertyByName(p)
                if o.getTypeIdOfProperty(p) == "App::PropertyFileIncluded":  # a copy in the document's own folder
                    value = (os.path.basename(value), os.path.getsize(value)) if value else ""
                props[p] = _describe(value)
            except Exception as e:  # a property that cannot be read is recorded as such
                props[p] = "unreadable: %s" % type(e).__name__
        out[o.Name] = (o.TypeId, props)
    return out


def worker_children():
    """The worker processes (comm 'topopt') that this process started and that still exist."""
    import os
    mine = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open("/proc/%s/stat" % pid) as f:
                stat = f.read()
        except OSError:
            continue
        comm = stat[stat.index("(") + 1:stat.rindex(")")]
        ppid = int(stat[stat.rindex(")") + 2:].split()[1])
        if comm == "topopt" and ppid == os.getpid():
            mine.append(int(pid))
    return mine
