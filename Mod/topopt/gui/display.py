"""Showing a study's tagged mesh (coloured by domain) and its density field (coloured by
density) as Mesh features in the document, grouped under the study's result group."""
import FreeCAD
import numpy as np

from topopt.app import checks, display

_DOMAIN_COLOURS = [(0.75, 0.75, 0.78), (0.90, 0.35, 0.20), (0.20, 0.55, 0.90), (0.30, 0.75, 0.35),
                   (0.85, 0.70, 0.20), (0.60, 0.35, 0.80), (0.20, 0.75, 0.75), (0.85, 0.45, 0.65)]


def _colour_map(t):
    """Blue (void) → green → red (solid) for t in [0, 1]."""
    return (float(min(1.0, 2 * t)), float(1 - abs(2 * t - 1)), float(max(0.0, 1 - 2 * t)))


def _feature(doc, name, label):
    obj = doc.getObject(name)
    if obj is None:
        obj = doc.addObject("Mesh::Feature", name)
    obj.Label = label
    return obj


def _arrays(study):
    """The study's stored mesh, checked (a damaged document gives a TopOptError, not a crash)."""
    return checks.stored_tets(study)


def show_domains(study):
    """One Mesh feature per domain (design first), coloured; the design one half transparent."""
    doc = study.Document
    nodes, tets, domain = _arrays(study)
    made = []
    for d, mesh in display.domain_meshes(nodes, tets, domain).items():
        label = "%s mesh: design" % study.Label if d == 0 else "%s mesh: non-design %d" % (study.Label, d)
        obj = _feature(doc, "%s_MeshDomain%d" % (study.Name, d), label)
        obj.Mesh = mesh
        vo = obj.ViewObject
        if vo is not None:
            vo.ShapeColor = _DOMAIN_COLOURS[d % len(_DOMAIN_COLOURS)]
            vo.DisplayMode = "Flat Lines"
            vo.Transparency = 60 if d == 0 else 0
        made.append(obj)
    doc.recompute()
    return made


def show_density(study, cut=0.3, bins=6):
    """The tets with density >= cut, their outer faces coloured by density."""
    doc = study.Document
    nodes, tets, _ = _arrays(study)
    dens = np.array(study.Densities)
    if len(dens) != len(tets):
        return None
    mesh, used = display.density_skin(nodes, tets, dens, cut, bins)
    obj = _feature(doc, study.Name + "_Density", "%s density" % study.Label)
    obj.Mesh = mesh
    doc.recompute()
    vo = obj.ViewObject
    if vo is not None and used:
        vo.DisplayMode = "Flat Lines"
        try:
            vo.highlightSegments([_colour_map((k + 0.5) / bins) for k in used])
        except Exception as e:  # colouring is a nicety; the feature is there regardless
            FreeCAD.Console.PrintWarning("TopOpt: could not colour the density field: %s\n" % e)
        vo.Visibility = False  # the result shape is what the user looks at first
    return obj
