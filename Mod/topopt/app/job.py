"""Turns a study into the job the native core runs: the same JSON a user can write by hand
(see docs/job-format.md), plus the shapes as BREP strings.

Face names: "FaceN" is face N of the part, as FreeCAD numbers it; "NonDesign:FaceN" is face N
of the compound of the non-design solids (their faces numbered one solid after another), for
loads on load pads whose faces lie on the part's boundary.
"""
import json
import Part

from . import checks
from . import directions
from . import errors
from . import units
from .study import is_study


def _shape_of(obj):
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull():
        raise errors.TopOptError("'%s' has no shape: pick a solid" % obj.Label, "InvalidShape")
    return shape


def nondesign_compound(study):
    shapes = [_shape_of(o) for o in study.NonDesign]
    return Part.makeCompound(shapes) if shapes else None


def _face_offsets(study):
    """Face-number offsets of each non-design object inside the non-design compound."""
    offsets, total = {}, 0
    for obj in study.NonDesign:
        offsets[obj.Name] = total
        total += len(_shape_of(obj).Faces)
    return offsets


def face_names(study, references, what):
    """The job's face names for a constraint's References [(obj, ("Face3", ...)), ...]."""
    offsets = _face_offsets(study)
    names = []
    for obj, subs in references:
        subs = [subs] if isinstance(subs, str) else list(subs)
        for sub in subs:
            if not sub.startswith("Face"):
                raise errors.TopOptError(
                    "%s refers to %s of %s: supports and loads go on faces" % (what, sub, obj.Label),
                    "FaceNotFound")
            if obj == study.Part:
                names.append(sub)
            elif obj.Name in offsets:
                names.append("NonDesign:Face%d" % (int(sub[4:]) + offsets[obj.Name]))
            else:
                raise errors.TopOptError(
                    "%s refers to %s, which is neither the study's part nor one of its non-design "
                    "solids: pick faces of those" % (what, obj.Label), "FaceNotFound")
    if not names:
        raise errors.TopOptError("%s has no faces: pick at least one face" % what, "FaceNotFound")
    return names


def _components(study, c, label):
    """FEM's displacement constraint: the fixed components (a prescribed non-zero value is
    refused: TopOpt fixes components, it does not move them)."""
    fix = [axis for axis in "xyz" if getattr(c, axis + "Fix")]
    moved = [axis for axis in "xyz" if not getattr(c, axis + "Fix") and not getattr(c, axis + "Free")
             and abs(units.prop(c, axis + "Displacement", "mm")) > 0]
    if moved:
        raise errors.TopOptError("%s prescribes a non-zero displacement; TopOpt supports only fixed "
                                 "components (tick Fix or Free)" % label, "InvalidParameter")
    if not fix:
        raise errors.TopOptError("%s fixes no component: tick xFix, yFix or zFix" % label, "InvalidParameter")
    return {"type": "components", "faces": face_names(study, c.References, label), "fix": fix}


def _force(study, c, label):
    """FEM's force: its magnitude (N; a float in FreeCAD 0.20, a quantity in 1.x) along the
    direction FEM applies and draws (directions.direction_of)."""
    force = units.prop(c, "Force", "N")
    d = directions.direction_of(c)
    return {"type": "force", "faces": face_names(study, c.References, label), "vector": [force * x for x in d]}


def _pressure(study, c, label):
    """FEM's pressure (MPa; a float in FreeCAD 0.20, a quantity in 1.x), negative when
    Reversed (a pull)."""
    p = units.prop(c, "Pressure", "MPa")
    return {"type": "pressure", "faces": face_names(study, c.References, label), "value": -p if c.Reversed else p}


def constraint_to_job(study, c):
    """(kind, item) for one constraint object: kind is "support" or "load". Values are read
    whether FreeCAD stores them as floats (0.20) or quantities (1.x)."""
    t = c.TypeId
    proxy_type = getattr(getattr(c, "Proxy", None), "Type", "")
    label = "'%s'" % c.Label
    if t == "Fem::ConstraintFixed":
        return "support", {"type": "fixed", "faces": face_names(study, c.References, label)}
    if t == "Fem::ConstraintDisplacement":
        return "support", _components(study, c, label)
    if proxy_type == "TopOpt::SymmetryPlane":
        return "support", {"type": "symmetry", "faces": face_names(study, c.References, label)}
    if t == "Fem::ConstraintForce":
        return "load", _force(study, c, label)
    if t == "Fem::ConstraintPressure":
        return "load", _pressure(study, c, label)
    if t == "Fem::ConstraintSelfWeight" or proxy_type == "Fem::ConstraintSelfWeight":
        return "load", {"type": "gravity", "vector": units.gravity(c)}
    raise errors.TopOptError("%s (%s) is not a support or load TopOpt knows: use fixed, displacement, "
                             "force, pressure, self weight or a TopOpt symmetry plane" % (label, t),
                             "InvalidParameter")


def study_to_job(study):
    """The job dict of a study (paths are left out: shapes travel as BREP strings)."""
    if not is_study(study):
        raise errors.TopOptError("not a TopOpt study", "InvalidParameter")
    if study.Part is None:
        raise errors.TopOptError("the study has no part: set its Part to a solid", "InvalidShape")
    n = study_numbers(study)
    supports, loads = [], []
    for c in study.Constraints:
        kind, item = constraint_to_job(study, c)
        (supports if kind == "support" else loads).append(item)
    if not supports:
        raise errors.TopOptError("the study has no support: add a fixed support (or fixed components) "
                                 "on a face of the part", "NoSupport")
    if not loads:
        raise errors.TopOptError("the study has no load: add a force, pressure or self weight", "InvalidParameter")
    job = {
        "mesh": dict({"mesher": str(getattr(study, "Mesher", "auto"))},
                     **({"size": n["MeshSize"]} if n["MeshSize"] > 0 else {}),
                     **({"wall_layers": n["WallLayers"]} if n["WallLayers"] > 0 else {})),
        "material": {"E": n["YoungsModulus"], "nu": n["PoissonRatio"], "density": n["Density"]},
        "supports": supports,
        "load_cases": [{"name": "loads", "weight": 1.0, "loads": loads}],
        "optimization": study_optimization(study, n),
    }
    job["result"] = {"join_non_design": bool(getattr(study, "JoinNonDesign", True))}
    job["output"] = {"step": bool(getattr(study, "WriteStep", True)), "verification": bool(getattr(study, "Verify", False))}
    if "StepMaxTriangles" in n:
        job["output"]["step_max_triangles"] = n["StepMaxTriangles"]
    # no threshold: a run always extracts the shape that keeps the volume fraction; the study's
    # Threshold is the shown result's (the slider's), never an input of the next run
    return job


def study_optimization(study, numbers=None):
    """The job's "optimization" section of a study: what a run optimises with, and where a
    re-extraction of its result (runner.extract_at, the threshold slider) takes the run's surface
    settings from, its overhang control's lift among them. numbers: study_numbers(study) when
    the caller has them. Raises TopOptError naming a property out of range or malformed."""
    n = numbers if numbers is not None else study_numbers(study)
    optimization = {"volume_fraction": n["VolumeFraction"], "penalty": n["Penalty"], "filter": study.Filter,
                    "update": study.Update, "max_iterations": n["MaxIterations"],
                    "keep_loaded_faces": bool(getattr(study, "KeepLoadedFaces", True))}
    if n["FilterRadius"] > 0:
        optimization["filter_radius"] = n["FilterRadius"]
    optimization.update(study_responses(study))
    controls = study_controls(study)
    if controls:
        optimization["controls"] = controls
    return optimization


def _json_property(study, name, example):
    """The study's JSON text property `name` as a dict, {} when empty. Raises TopOptError
    naming the property when the text is not a JSON object."""
    text = str(getattr(study, name, "") or "").strip()
    if not text:
        return {}
    try:
        value = json.loads(text)
    except ValueError as e:
        raise errors.TopOptError("the study's %s is not valid JSON (%s): set it with the API or the study's "
                                 "panel, or clear it" % (name, e), "InvalidParameter")
    if not isinstance(value, dict):
        raise errors.TopOptError("the study's %s must be a JSON object such as %s" % (name, example),
                                 "InvalidParameter")
    return value


def study_responses(study):
    """The study's objective and limits (its Responses property, JSON text) as the job's
    optimization keys, {} for the default (compliance of the volume fraction)."""
    return _json_property(study, "Responses", '{"objective": "mass", "stress_limit": 200}')


def study_controls(study):
    """The study's geometry controls (its GeometryControls property, JSON text) as a dict, {}
    for none. Raises TopOptError naming the property when the text is not a JSON object."""
    return _json_property(study, "GeometryControls", '{"extrusion": [0, 0, 1]}')


#: the study's numeric properties: (name, unit or None, low, high, open low, open high); None = no bound
_NUMBERS = [
    ("VolumeFraction", None, 0.0, 1.0, True, True),
    ("YoungsModulus", "MPa", 0.0, None, True, False),
    ("PoissonRatio", None, -1.0, 0.5, True, True),
    ("Density", "t/mm^3", 0.0, None, False, False),
    ("MeshSize", "mm", 0.0, None, False, False),
    ("WallLayers", None, 0, 4, False, False),
    ("Penalty", None, 1.0, 10.0, False, False),
    ("FilterRadius", "mm", 0.0, None, False, False),
    ("MaxIterations", None, 1, 10000, False, False),
    ("StepMaxTriangles", None, 0, 2000000000, False, False),
]


def study_numbers(study):
    """The study's numeric properties as plain numbers in the core's units (MPa, t/mm³, mm),
    each checked: finite, in its range, with a unit of the right kind. Raises TopOptError
    naming the property."""
    out = {}
    for name, unit, low, high, open_low, open_high in _NUMBERS:
        if name in study.PropertiesList:
            value = getattr(study, name)
            if unit is not None:
                value = units.value_in(value, unit, name)
            out[name] = checks.in_range(value, name, low, high, open_low, open_high)
    out.setdefault("WallLayers", 0)
    for name in ("WallLayers", "MaxIterations", "StepMaxTriangles"):
        if name not in out:
            continue
        out[name] = int(out[name])
    return out
