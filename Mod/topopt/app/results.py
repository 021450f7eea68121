"""A run's results as FreeCAD objects, all linked from the study (and shown under it):

- Result: the smoothed result shape, a Mesh feature whose faces on non-design solids are
  coloured apart (a FaceColors list the mesh view uses, so the colours come back on reopen);
- AnalysisMesh: the tagged analysis mesh as a FEM mesh;
- FemResult: the last SIMP iterate as a FEM mechanical result on that mesh (displacement,
  von Mises stress): FEM's result panel and its post-processing work on it;
- Fields: a FEM post-processing pipeline with the run's fields, all per node (Density,
  Displacement, von Mises stress averaged by volume, Domain: the largest around the node, so
  a non-design solid's nodes count as its own), saved in the document;
- DensityView: a scalar clip of Fields on Density at the result's threshold, coloured by
  density with FEM's colour bar: where the material stays;
- DomainMeshes: the Mesh command's FEM meshes, one per domain (refreshed by a run).

A re-run updates these objects in place; nothing stale is left. Works headless (no view
settings then) and with the GUI.
"""
import os
import shutil
import tempfile

import FreeCAD
import numpy as np

from . import quiet, vtu

def _rgb(r, g, b):
    """A colour from 0–255 components: FreeCAD saves colours as 8-bit components, so these
    come back from a saved document exactly as they were set."""
    return (r / 255.0, g / 255.0, b / 255.0)


#: colours of the domains: design first, then the non-design solids in order
DOMAIN_COLOURS = [_rgb(191, 191, 199), _rgb(230, 115, 38), _rgb(51, 140, 230), _rgb(77, 179, 89),
                  _rgb(217, 179, 51), _rgb(153, 89, 204), _rgb(51, 191, 191), _rgb(217, 115, 166)]
#: the result shape's design part
RESULT_COLOUR = _rgb(158, 184, 214)

#: field names in the pipeline (units in the names: FEM's colour bar shows only numbers)
DENSITY = "Density"
DISPLACEMENT = "Displacement (mm)"
VON_MISES = "von Mises stress (MPa)"
DOMAIN = "Domain (0 design, k non-design solid k)"


def domain_colour(d):
    return DOMAIN_COLOURS[int(d) % len(DOMAIN_COLOURS)]


def tet_volumes(nodes, tets):
    """#T volumes (mm³) of the tets."""
    a, b, c, d = (nodes[tets[:, k]] for k in range(4))
    return np.abs(np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)) / 6.0


def nodal_average(tets, values, count, weights):
    """#V node values: the `weights`-weighted mean of the values of the tets around each node
    (0 at nodes no tet uses)."""
    total = np.zeros(count)
    weight = np.zeros(count)
    for k in range(4):
        np.add.at(total, tets[:, k], values * weights)
        np.add.at(weight, tets[:, k], weights)
    return np.divide(total, weight, out=np.zeros(count), where=weight > 0)


def nodal_maximum(tets, values, count):
    """#V: at each node the largest value of the tets around it (0 where no tet is), so that
    the largest nodal value is the largest tet value."""
    out = np.zeros(count)
    for k in range(4):
        np.maximum.at(out, tets[:, k], values)
    return out


def kept_volume_fraction(nodes, tets, domain, densities, threshold):
    """Share of the design domain's volume in tets whose density reaches `threshold` (what the
    threshold slider shows before it re-extracts the shape)."""
    vol = tet_volumes(nodes, tets)
    design = domain == 0
    total = vol[design].sum()
    return float(vol[design & (densities >= threshold)].sum() / total) if total > 0 else 0.0


def volume_threshold(nodes, tets, domain, densities, fraction):
    """The density threshold at which the design tets at or above it hold `fraction` of the
    design domain's volume (for documents of older versions that did not keep the run's)."""
    vol = tet_volumes(nodes, tets)
    design = domain == 0
    order = np.argsort(-densities[design])
    kept = np.cumsum(vol[design][order])
    if len(kept) == 0 or kept[-1] <= 0:
        return 0.5
    k = min(len(kept) - 1, int(np.searchsorted(kept, fraction * kept[-1])))
    return float(min(0.99, max(0.01, densities[design][order][k])))


# --- FEM meshes ----------------------------------------------------------------------------

def fem_mesh(nodes, tets, folder):
    """A Fem.FemMesh of the tets (read from a .vtu written into `folder`)."""
    import Fem
    path = vtu.write_tets(os.path.join(folder, "mesh.vtu"), nodes, tets)
    mesh = Fem.FemMesh()
    mesh.read(path)
    return mesh


def _object(doc, study, link, kind, name, label, make=None):
    """The object the study links as `link`, created (doc.addObject(kind) or make()) when
    missing or of another kind, and labelled."""
    obj = getattr(study, link, None)
    if obj is None or obj.TypeId != kind:
        obj = make() if make else doc.addObject(kind, study.Name + "_" + name)
        setattr(study, link, obj)
    obj.Label = label
    return obj


def show_domains(study, nodes, tets, domain):
    """The study's DomainMeshes: one FEM mesh per domain (design first), coloured as the
    domain, the design one half transparent. Existing ones are updated, extra ones removed."""
    doc = study.Document
    old = [o for o in study.DomainMeshes if o is not None]
    made = []
    folder = tempfile.mkdtemp(prefix="topopt-domains-")
    try:
        for i, d in enumerate(np.unique(domain)):
            obj = old[i] if i < len(old) else doc.addObject("Fem::FemMeshObject", "%s_Domain%d" % (study.Name, d))
            obj.Label = "%s mesh: %s" % (study.Label, "design" if d == 0 else "non-design %d" % d)
            obj.FemMesh = fem_mesh(nodes, tets[domain == d], folder)
            made.append(obj)
            _style_domain(obj, int(d))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    study.DomainMeshes = made
    for obj in old[len(made):]:
        doc.removeObject(obj.Name)
    return made


def _style_domain(obj, d):
    vo = obj.ViewObject
    if vo is None:
        return
    vo.ShapeColor = domain_colour(d)
    vo.Transparency = 70 if d == 0 else 0  # the non-design solids show through the design domain
    if "LineWidth" in vo.PropertiesList:
        vo.LineWidth = 1.0
    # the design domain with its elements' edges; the non-design solids (finely meshed around
    # bores, where black edges would hide their colour) as coloured faces
    mode = "Faces & Wireframe" if d == 0 else "Faces"
    if mode in vo.getEnumerationsOfProperty("DisplayMode"):
        vo.DisplayMode = mode


# --- the result shape ----------------------------------------------------------------------

#: how far a result triangle's centre may lie off a non-design solid's boundary face and still lie
#: on it: across the face, this share of the face's longest edge (the surface stage projects points
#: on curved faces onto the true surface: a sagitta of a few per cent of an edge); beyond its edges,
#: this barycentric margin (the projection's tangential part, well under one per cent) — a design
#: triangle beside the solid has its centre a third of its own height beyond the face's edge
ON_FACE_ACROSS = 0.1
ON_FACE_BEYOND = 0.02
#: the least |cos| between a result triangle's normal and the face's for it to lie on the face
ON_FACE_COS = 0.9


def solid_boundary_faces(tets, domain):
    """(#B×3 node indices, #B solid numbers): the faces of each non-design solid's tets that no
    other tet of the same solid shares — that solid's boundary, against Ω's boundary or the design."""
    tets = np.asarray(tets, dtype=np.int64)
    domain = np.asarray(domain, dtype=np.int64)
    nd = domain > 0
    faces = np.concatenate([tets[nd][:, [1, 2, 3]], tets[nd][:, [0, 2, 3]], tets[nd][:, [0, 1, 3]],
                            tets[nd][:, [0, 1, 2]]])
    owner = np.tile(domain[nd], 4)
    key = np.column_stack([np.sort(faces, axis=1), owner])
    _, first, count = np.unique(key, axis=0, return_index=True, return_counts=True)
    single = first[count == 1]
    return faces[single], owner[single]


def _on_faces(centres, normals, nodes, faces):
    """#C: for each triangle centre (with its unit normal), whether it lies on one of `faces`
    (by ON_FACE_ACROSS, ON_FACE_BEYOND and ON_FACE_COS), and which (index into faces, -1 if none).
    Each centre is tested against the faces whose box (grown by the tolerance across) meets its
    cell of a grid two face sizes wide: all pairs took 11 s on the lever."""
    a, b, c = nodes[faces[:, 0]], nodes[faces[:, 1]], nodes[faces[:, 2]]
    n = np.cross(b - a, c - a)
    area2 = np.linalg.norm(n, axis=1)
    n = n / np.where(area2 > 0, area2, 1.0)[:, None]
    size = np.max(np.stack([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                            np.linalg.norm(a - c, axis=1)]), axis=0)
    grow = (ON_FACE_ACROSS * size)[:, None]
    lo = np.minimum(np.minimum(a, b), c) - grow
    hi = np.maximum(np.maximum(a, b), c) + grow
    which = np.full(len(centres), -1, dtype=np.int64)
    cell = max(float(np.median(size)) if len(size) else 1.0, 1e-9) * 2
    faces_in = {}  # grid cell -> the faces whose grown box meets it
    for f in np.flatnonzero(area2 > 0):
        c0, c1 = np.floor(lo[f] / cell).astype(np.int64), np.floor(hi[f] / cell).astype(np.int64)
        for i in range(c0[0], c1[0] + 1):
            for j in range(c0[1], c1[1] + 1):
                for k in range(c0[2], c1[2] + 1):
                    faces_in.setdefault((i, j, k), []).append(f)
    keys, inverse = np.unique(np.floor(centres / cell).astype(np.int64), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    by_cell = np.argsort(inverse, kind="stable")
    bounds = np.searchsorted(inverse[by_cell], np.arange(len(keys) + 1))
    for g, key in enumerate(map(tuple, keys)):
        near = faces_in.get(key)
        if near is None:
            continue
        near = np.asarray(near)
        rows = by_cell[bounds[g]:bounds[g + 1]]
        hit = _centres_on(centres[rows], normals[rows], a[near], b[near], c[near], n[near], area2[near], size[near])
        which[rows] = np.where(hit >= 0, near[np.maximum(hit, 0)], -1)
    return which


def _centres_on(p, normals, a, b, c, n, area2, size):
    """_on_faces' test of centres p (#C×3) against faces (corners a, b, c, unit normals n, twice
    their areas, their longest edges): the first face each lies on, -1 if none."""
    q = p[:, None, :]
    off = np.abs(np.einsum("ijk,jk->ij", q - a[None], n))
    aligned = np.abs(normals @ n.T) >= ON_FACE_COS
    # barycentric coordinates of p's projection, each signed area over the face's
    bary = [np.einsum("ijk,jk->ij", np.cross(v[None] - q, w[None] - q), n) / area2
            for v, w in ((b, c), (c, a), (a, b))]
    inside = np.minimum(np.minimum(bary[0], bary[1]), bary[2]) >= -ON_FACE_BEYOND
    near = (off <= ON_FACE_ACROSS * size[None]) & aligned & inside
    return np.where(near.any(axis=1), np.argmax(near, axis=1), -1)


def facet_domains(points, triangles, nodes, tets, domain, tags=None):
    """#Q: for each triangle of the result shape, the non-design solid it lies on (k > 0) or 0.
    `tags` (#Q, the core's surface_tags): -k marks a face of non-design solid k inside the part,
    0 the iso-surface (in the design). Elsewhere (Ω's boundary) a triangle lies on solid k when
    its centre lies on a boundary face of k's tets: by place, not by its corners being mesh
    nodes — the surface stage splits and projects triangles there (new points on a solid's faces)."""
    points = np.asarray(points, dtype=np.float64)
    triangles = np.asarray(triangles, dtype=np.int64)
    nodes = np.asarray(nodes, dtype=np.float64)
    out = np.zeros(len(triangles), dtype=np.int64)
    if len(triangles) == 0 or not (np.asarray(domain) > 0).any():
        return out
    tags = np.ones(len(triangles), dtype=np.int64) if tags is None else np.asarray(tags, dtype=np.int64)
    faces, owner = solid_boundary_faces(tets, domain)
    on_part = np.flatnonzero(tags > 0)
    corner = points[triangles[on_part]]
    normal = np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    which = _on_faces(corner.mean(axis=1), normal, nodes, faces)
    out[on_part] = np.where(which >= 0, owner[np.maximum(which, 0)], 0)
    return np.where(tags < 0, -tags, out)


def colour_result(feature, facet_domain):
    """Colours the result shape's faces: the design part RESULT_COLOUR, each non-design solid
    its domain colour. Kept in the feature (FaceColors), so the colours come back on reopen."""
    if "FaceColors" not in feature.PropertiesList:
        feature.addProperty("App::PropertyColorList", "FaceColors", "TopOpt",
                            "Colour of each face: non-design solids apart from the design")
        feature.setEditorMode("FaceColors", 2)
    feature.FaceColors = [RESULT_COLOUR if d == 0 else domain_colour(d) for d in facet_domain]


def style_result(feature):
    """With the GUI: the result shape smoothly shaded and coloured by its FaceColors. Call it
    after the document's recompute (which redraws the mesh without its colours)."""
    vo = feature.ViewObject
    if vo is not None:
        vo.CreaseAngle = 40.0  # smooth shading across the smoothed surface, sharp edges kept
        vo.Coloring = False
        vo.Coloring = True  # re-reads FaceColors


# --- FEM result and fields -----------------------------------------------------------------

def _fem_result(study, mesh_obj, displacement, von_mises_nodes):
    import ObjectsFem
    doc = study.Document
    res = _object(doc, study, "FemResult", "Fem::FemResultObjectPython", "FemResult",
                  "%s last iterate" % study.Label,
                  lambda: ObjectsFem.makeResultMechanical(doc, study.Name + "_FemResult"))
    return fill_mechanical_result(res, mesh_obj, displacement, von_mises_nodes)


def fill_mechanical_result(res, mesh_obj, displacement, von_mises_nodes):
    """Fills FEM's mechanical result `res` on `mesh_obj` (nodes numbered 1..#V in order):
    displacement #V x 3 (mm), von_mises_nodes #V (MPa), and FEM's statistics. Returns res."""
    res.Mesh = mesh_obj
    res.NodeNumbers = list(range(1, len(displacement) + 1))
    res.DisplacementVectors = [FreeCAD.Vector(*map(float, u)) for u in displacement]
    res.DisplacementLengths = [float(x) for x in np.linalg.norm(displacement, axis=1)]
    res.vonMises = [float(x) for x in von_mises_nodes]
    from femresult import resulttools
    resulttools.fill_femresult_stats(res)
    return res


def _fields(study, path, threshold):
    import ObjectsFem
    doc = study.Document
    pipe = _object(doc, study, "Fields", "Fem::FemPostPipeline", "Fields", "%s fields" % study.Label)
    pipe.read(path)
    clip = study.DensityView
    if clip is None or clip not in pipe.Filter:
        clip = ObjectsFem.makePostVtkFilterClipScalar(doc, pipe)
        study.DensityView = clip
    clip.Label = "%s density" % study.Label
    quiet.recompute(doc)
    clip.Scalars = DENSITY
    clip.Value = float(threshold)
    clip.InsideOut = False
    return pipe, clip


def set_density_cut(study, threshold):
    """Shows in DensityView the material whose density reaches `threshold`."""
    clip = study.DensityView
    if clip is not None:
        clip.Value = float(threshold)


def update_fem_objects(study, result, threshold):
    """The run's FEM objects (AnalysisMesh, FemResult, Fields, DensityView) made or refreshed
    from the worker's result dict (nodes, tets, domain, densities, and the last iterate's
    displacement #V x 3 and von_mises #T). Returns the FEM result object."""
    doc = study.Document
    nodes = np.asarray(result["nodes"], dtype=np.float64)
    tets = np.asarray(result["tets"], dtype=np.int64)
    domain = np.asarray(result["domain"], dtype=np.int64)
    densities = np.asarray(result["densities"], dtype=np.float64)
    displacement = np.asarray(result.get("displacement", np.zeros((len(nodes), 3))), dtype=np.float64)
    von_mises = np.asarray(result.get("von_mises", np.zeros(len(tets))), dtype=np.float64)
    vol = tet_volumes(nodes, tets)
    node_density = nodal_average(tets, densities, len(nodes), vol)
    node_density[np.unique(tets[domain > 0])] = 1.0  # as the core does: non-design solids stay whole
    node_von_mises = nodal_average(tets, von_mises, len(nodes), vol)
    folder = tempfile.mkdtemp(prefix="topopt-fields-")
    try:
        # every field per node: FreeCAD 0.20's pipeline view crashes when a cell field is
        # chosen as its Field (ViewProviderFemPostObject::updateProperties)
        path = vtu.write_tets(os.path.join(folder, "fields.vtu"), nodes, tets,
                              [(DENSITY, node_density), (DISPLACEMENT, displacement), (VON_MISES, node_von_mises),
                               (DOMAIN, nodal_maximum(tets, domain.astype(np.float64), len(nodes)))])
        import Fem
        mesh = Fem.FemMesh()
        mesh.read(path)
        mesh_obj = _object(doc, study, "AnalysisMesh", "Fem::FemMeshObjectPython", "AnalysisMesh",
                           "%s analysis mesh" % study.Label, lambda: _make_mesh_result(doc, study))
        mesh_obj.FemMesh = mesh
        res = _fem_result(study, mesh_obj, displacement, node_von_mises)
        pipe, clip = _fields(study, path, threshold)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    _style_fem_objects(study)
    return res


def _make_mesh_result(doc, study):
    import ObjectsFem
    return ObjectsFem.makeMeshResult(doc, study.Name + "_AnalysisMesh")


def _style_fem_objects(study):
    """With the GUI: the FEM objects hidden except the density view (coloured by Density, shown
    as a surface), which the user turns on next to the result shape."""
    for name in ("AnalysisMesh", "FemResult", "Fields"):
        obj = getattr(study, name, None)
        if obj is not None and obj.ViewObject is not None:
            obj.ViewObject.Visibility = False
    clip = study.DensityView
    if clip is not None and clip.ViewObject is not None:
        style_density_view(clip)
        clip.ViewObject.Visibility = False


def style_density_view(clip):
    """With the GUI: the density view as a surface coloured by Density (FEM's colour bar)."""
    vo = clip.ViewObject
    if vo is None:
        return
    if DENSITY not in vo.getEnumerationsOfProperty("Field"):
        vo.DisplayMode = "Outline"  # FEM's view lists a filter's fields again when its display mode changes
    vo.DisplayMode = "Surface"
    if DENSITY in vo.getEnumerationsOfProperty("Field"):
        vo.Field = DENSITY
