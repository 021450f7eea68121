"""Meshes for showing a study's tet mesh and density field (numpy only; colours are applied
by the GUI). Shared by the workbench's view and by headless scripts that export pictures."""
import numpy as np

# outward faces of a positively oriented tet, opposite vertex 0..3
_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


def boundary_of(tets, selected):
    """Faces (#K x 3, outward) used by exactly one of the selected tets, and for each the tet
    it belongs to."""
    idx = np.nonzero(selected)[0]
    if len(idx) == 0:
        return np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64)
    faces = tets[idx][:, _FACES].reshape(-1, 3)
    owner = np.repeat(idx, 4)
    key = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    once = counts[inverse.reshape(-1)] == 1
    return faces[once], owner[once]


def to_mesh(nodes, faces):
    """A Mesh.Mesh from points and triangles (points as FreeCAD.Vector: see runner.result_mesh)."""
    from .runner import result_mesh
    return result_mesh(nodes, faces)


def domain_meshes(nodes, tets, domain):
    """{domain: Mesh.Mesh of the boundary of that domain's tets}."""
    out = {}
    for d in np.unique(domain):
        faces, _ = boundary_of(tets, domain == d)
        out[int(d)] = to_mesh(nodes, faces)
    return out


def density_skin(nodes, tets, densities, cut=0.3, bins=6):
    """The boundary of the tets with density >= cut as a Mesh.Mesh, with one segment per density
    bin (bin k holds faces of tets whose density lies in [k/bins, (k+1)/bins)). Returns
    (mesh, bin of each segment)."""
    faces, owner = boundary_of(tets, densities >= cut)
    mesh = to_mesh(nodes, faces)
    b = np.minimum((densities[owner] * bins).astype(int), bins - 1)
    used = []
    for k in range(bins):
        members = np.nonzero(b == k)[0]
        if len(members):
            mesh.addSegment([int(i) for i in members])
            used.append(k)
    return mesh, used
