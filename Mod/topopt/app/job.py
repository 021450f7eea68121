"""Turns a study into the job the native core runs: the same JSON a user can write by hand
(see docs/job-format.md), plus the shapes as BREP strings.

Face names: "FaceN" is face N of the part, as FreeCAD numbers it; "NonDesign:FaceN" is face N
of the compound of the non-design solids (their faces numbered one solid after another), for
loads on load pads whose faces lie on the part's boundary.
"""
import Part

from . import checks
from . import errors
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


def _vec(v):
    return [float(v.x), float(v.y), float(v.z)]


def constraint_to_job(study, c):
    """(kind, item) for one constraint object: kind is "support" or "load"."""
    t = c.TypeId
    proxy_type = getattr(getattr(c, "Proxy", None), "Type", "")
    label = "'%s'" % c.Label
    if t == "Fem::ConstraintFixed":
        return "support", {"type": "fixed", "faces": face_names(study, c.References, label)}
    if t == "Fem::ConstraintDisplacement":
        fix = [axis for axis in "xyz" if getattr(c, axis + "Fix")]
        moved = [axis for axis in "xyz" if not getattr(c, axis + "Fix") and not getattr(c, axis + "Free")
                 and abs(getattr(c, axis + "Displacement")) > 0]
        if moved:
            raise errors.TopOptError("%s prescribes a non-zero displacement; TopOpt supports only fixed "
                                     "components (tick Fix or Free)" % label, "InvalidParameter")
        if not fix:
            raise errors.TopOptError("%s fixes no component: tick xFix, yFix or zFix" % label,
                                     "InvalidParameter")
        return "support", {"type": "components", "faces": face_names(study, c.References, label), "fix": fix}
    if proxy_type == "TopOpt::SymmetryPlane":
        return "support", {"type": "symmetry", "faces": face_names(study, c.References, label)}
    if t == "Fem::ConstraintForce":
        force = checks.number(c.Force, "%s: Force" % label)
        d = c.TopOptDirection if "TopOptDirection" in c.PropertiesList else c.DirectionVector
        for axis in "xyz":
            checks.number(getattr(d, axis), "%s: the direction's %s" % (label, axis))
        if d.Length == 0:
            raise errors.TopOptError("%s has no direction: pick an edge or face for it" % label, "InvalidParameter")
        d = d.normalize() if hasattr(d, "normalize") else d
        return "load", {"type": "force", "faces": face_names(study, c.References, label),
                        "vector": [force * x for x in _vec(d)]}
    if t == "Fem::ConstraintPressure":
        p = checks.number(c.Pressure, "%s: Pressure" % label)
        return "load", {"type": "pressure", "faces": face_names(study, c.References, label),
                        "value": -p if c.Reversed else p}
    if t == "Fem::ConstraintSelfWeight":
        g = 9806.65  # mm/s², FreeCAD's self weight is in multiples of g
        return "load", {"type": "gravity", "vector": [checks.number(getattr(c, "Gravity_" + axis), "%s: Gravity_%s"
                                                                    % (label, axis)) * g for axis in "xyz"]}
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
        "optimization": {"volume_fraction": n["VolumeFraction"], "penalty": n["Penalty"], "filter": study.Filter,
                         "update": study.Update, "max_iterations": n["MaxIterations"]},
    }
    if n["FilterRadius"] > 0:
        job["optimization"]["filter_radius"] = n["FilterRadius"]
    if n["Threshold"] >= 0:
        job["optimization"]["threshold"] = n["Threshold"]
    return job


#: the study's numeric properties: (name, low, high, open low, open high); None = no bound
_NUMBERS = [
    ("VolumeFraction", 0.0, 1.0, True, True),
    ("YoungsModulus", 0.0, None, True, False),
    ("PoissonRatio", -1.0, 0.5, True, True),
    ("Density", 0.0, None, False, False),
    ("MeshSize", 0.0, None, False, False),
    ("WallLayers", 0, 4, False, False),
    ("Penalty", 1.0, 10.0, False, False),
    ("FilterRadius", 0.0, None, False, False),
    ("MaxIterations", 1, 10000, False, False),
]


def study_numbers(study):
    """The study's numeric properties as plain numbers, each checked: finite, in its range,
    the threshold -1 (automatic) or in (0, 1). Raises TopOptError naming the property."""
    out = {}
    for name, low, high, open_low, open_high in _NUMBERS:
        if name in study.PropertiesList:
            out[name] = checks.in_range(getattr(study, name), name, low, high, open_low, open_high)
    out.setdefault("WallLayers", 0)
    for name in ("WallLayers", "MaxIterations"):
        out[name] = int(out[name])
    threshold = checks.number(study.Threshold, "Threshold")
    if threshold >= 0:
        threshold = checks.in_range(threshold, "Threshold (-1 for automatic)", 0.0, 1.0, True, True)
    out["Threshold"] = threshold
    return out
