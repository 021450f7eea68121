"""Picture of a two-B-Rep mesh for the README: the outer surface of the tets, each triangle
coloured by the domain of its tet (design grey, non-design solids in colours), whole and cut
open at a plane so the interface between the domains shows.

    /usr/bin/python3 docs/images/make_mount_picture.py MESH.msh OUT.png [--cut-y Y]

MESH.msh: `topopt mesh --out` (Gmsh MSH 4.1, physical volume 1 = design, 2.. = non-design).
Reads it with Gmsh's Python module; draws with matplotlib (no display needed). matplotlib sorts
whole triangles by depth, so faint edges of hidden triangles may show through the plate."""
import argparse
from collections import Counter

import gmsh
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

FACES = ((1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1))  # outward for a positive tet
COLOURS = ["#c8c8c8", "#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2"]


def read_tets(path):
    """Nodes (#V by 3), tets (#T by 4, 0-based) and their domain (0 = design, i = non-design i)."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(path)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = {int(t): i for i, t in enumerate(tags)}
    V = np.asarray(coords).reshape(-1, 3)
    T, D = [], []
    for dim, phys in gmsh.model.getPhysicalGroups(3):
        for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, phys):
            types, _, nodes = gmsh.model.mesh.getElements(3, ent)
            for ty, nd in zip(types, nodes):
                if ty != 4:
                    continue
                t = np.array([index[int(n)] for n in nd]).reshape(-1, 4)
                T.append(t)
                D.append(np.full(len(t), phys - 1))
    gmsh.finalize()
    return V, np.vstack(T), np.concatenate(D)


def outer_triangles(T, D):
    """Faces used by one tet of the set only: (triangles #F by 3, domain of their tet)."""
    count = Counter()
    for t in T:
        for f in FACES:
            count[tuple(sorted(t[list(f)]))] += 1
    tris, dom = [], []
    for t, d in zip(T, D):
        for f in FACES:
            if count[tuple(sorted(t[list(f)]))] == 1:
                tris.append(t[list(f)])
                dom.append(d)
    return np.array(tris), np.array(dom)


def draw(ax, V, tris, dom, title):
    light = np.array([0.3, -0.5, 0.8])
    light /= np.linalg.norm(light)
    P = V[tris]
    n = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None] + 1e-300
    shade = 0.55 + 0.45 * np.abs(n @ light)
    base = np.array([matplotlib.colors.to_rgb(COLOURS[d % len(COLOURS)]) for d in dom])
    col = np.clip(base * shade[:, None], 0, 1)
    ax.add_collection3d(Poly3DCollection(P, facecolors=col, edgecolors=(0, 0, 0, 0.1), linewidths=0.1))
    lo, hi = V.min(axis=0), V.max(axis=0)
    ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo, zoom=1.2)
    ax.view_init(elev=28, azim=-60)
    ax.set_axis_off()
    ax.set_title(title, fontsize=10)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mesh")
    ap.add_argument("out")
    ap.add_argument("--cut-y", type=float, default=15.0, help="keep the tets whose centroid has y above this")
    a = ap.parse_args()
    V, T, D = read_tets(a.mesh)
    fig = plt.figure(figsize=(14, 6), dpi=130)
    tris, dom = outer_triangles(T, D)
    draw(fig.add_subplot(1, 2, 1, projection="3d"), V, tris, dom, "whole mesh: design grey, non-design coloured")
    keep = V[T].mean(axis=1)[:, 1] > a.cut_y
    tris, dom = outer_triangles(T[keep], D[keep])
    draw(fig.add_subplot(1, 2, 2, projection="3d"), V, tris, dom, "cut open at y = %g" % a.cut_y)
    fig.tight_layout()
    fig.savefig(a.out, bbox_inches="tight")
    print("wrote", a.out, "(%d tets)" % len(T))


if __name__ == "__main__":
    main()
