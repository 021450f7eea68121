"""Before/after picture of an example for the README: the input (the design space Ω in grey and
the non-design solids in red, as the user gives them) next to the result surface of
`topopt optimize` (result.stl), both from the same isometric view and at the same scale.

    /usr/bin/python3 docs/images/make_before_after.py EXAMPLE RESULT.stl OUT.png

EXAMPLE: a name of ../shared/data/examples (cantilever, rocker, bracket, mount); its
EXAMPLE.step and EXAMPLE_nondesign.step are triangulated by Gmsh's Python module (OCC kernel,
surface mesh only). Draws with matplotlib (no display needed); a small PNG (about 100 kB)."""
import argparse
import os
import sys

import gmsh
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench"))
import benchlib  # noqa: E402

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "data", "examples")
LIGHT = np.array([0.4, -0.5, 0.75]) / np.linalg.norm([0.4, -0.5, 0.75])


def step_triangles(path):
    """The triangles (#F by 3 by 3) of Gmsh's surface mesh of the STEP file's faces."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.occ.importShapes(path)
    gmsh.model.occ.synchronize()
    box = gmsh.model.getBoundingBox(-1, -1)
    gmsh.option.setNumber("Mesh.MeshSizeMax", max(box[3] - box[0], box[4] - box[1], box[5] - box[2]) / 40)
    gmsh.model.mesh.generate(2)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    where = {t: k for k, t in enumerate(tags)}
    points = coords.reshape(-1, 3)
    tris = []
    for etype, _, nodes in zip(*gmsh.model.mesh.getElements(2)):
        if etype == 2:  # 3-node triangles
            tris.append(points[[where[n] for n in nodes]].reshape(-1, 3, 3))
    gmsh.finalize()
    return np.concatenate(tris)


def shaded(tris, rgb):
    """Per-triangle colours: rgb lit by a fixed light (two-sided)."""
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1)[:, None], 1e-30)
    return np.clip(np.outer(0.35 + 0.65 * np.abs(n @ LIGHT), rgb), 0, 1)


def panel(fig, k, parts, title, lo, hi):
    """Subplot k of 2: the (triangles, colour) parts from the isometric view."""
    ax = fig.add_subplot(1, 2, k, projection="3d")
    # one collection, so that matplotlib sorts the triangles of every part together by depth
    tris = np.concatenate([t for t, _ in parts])
    colours = np.concatenate([shaded(t, rgb) for t, rgb in parts])
    ax.add_collection3d(Poly3DCollection(tris, facecolors=colours, edgecolor="none"))
    for set_lim, l, h in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), lo, hi):
        set_lim(l, h)
    ax.set_box_aspect(hi - lo, zoom=1.1)  # equal scale on the three axes, the part filling the panel
    ax.view_init(elev=25, azim=-60)
    ax.set_title(title, fontsize=10)
    ax.set_axis_off()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("example")
    ap.add_argument("stl")
    ap.add_argument("png")
    a = ap.parse_args()
    omega = step_triangles(os.path.join(DATA, a.example + ".step"))
    nondesign = step_triangles(os.path.join(DATA, a.example + "_nondesign.step"))
    result = benchlib.read_stl(a.stl)
    every = np.concatenate([omega, nondesign, result]).reshape(-1, 3)
    lo, hi = every.min(0), every.max(0)
    fig = plt.figure(figsize=(9, 3.6))
    panel(fig, 1, [(omega, [0.75, 0.75, 0.75]), (nondesign, [0.85, 0.2, 0.2])],
          "%s: input (design space grey, non-design red)" % a.example, lo, hi)
    panel(fig, 2, [(result, [0.55, 0.65, 0.85])], "%s: result (result.stl, %d triangles)" % (a.example, len(result)), lo, hi)
    fig.subplots_adjust(left=0, right=1, bottom=0, top=0.92, wspace=0)
    fig.savefig(a.png, dpi=80)
    plt.close(fig)


if __name__ == "__main__":
    main()
