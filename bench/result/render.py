#!/usr/bin/python3
"""Pictures of `topopt optimize` results from several sides (issue 19: every result looked at):
the result surface (result.stl) shaded, and the verification's von Mises field on the result
solid's boundary (verification.vtu: each boundary triangle coloured by its tet's stress, the
first load case), from four views in one PNG each.

usage: bench/result/render.py OUT_DIR [OUT_DIR ...]   (writes OUT_DIR/views.png, OUT_DIR/von_mises.png)
"""
import os, sys
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))
import benchlib  # noqa: E402
import crisp  # noqa: E402

VIEWS = [(25, -60, "front-left, above"), (25, 120, "back-right, above"), (-30, -60, "from below"), (90, -90, "top")]


def boundary_faces(tets):
    """The tets' boundary triangles (outward) and the tet each belongs to."""
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
    owner = np.tile(np.arange(len(tets)), 4)
    key = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    once = counts[inverse.ravel()] == 1
    return faces[once], owner[once]


def draw(tris, colours, png, title):
    """Four views of the triangles (#F x 3 x 3) with their RGB colours, in one PNG."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    c, r = (lo + hi) / 2, (hi - lo).max() / 2
    fig = plt.figure(figsize=(14, 10))
    for k, (elev, azim, name) in enumerate(VIEWS):
        ax = fig.add_subplot(2, 2, k + 1, projection="3d")
        ax.add_collection3d(Poly3DCollection(tris, facecolors=colours, edgecolor="none"))
        ax.set_xlim(c[0] - r, c[0] + r), ax.set_ylim(c[1] - r, c[1] + r), ax.set_zlim(c[2] - r, c[2] + r)
        ax.view_init(elev=elev, azim=azim)
        ax.set_title(name, fontsize=9)
        ax.set_axis_off()
    fig.suptitle(title, fontsize=11)
    fig.savefig(png, dpi=90, bbox_inches="tight")
    plt.close(fig)


def shaded(tris, base):
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1)[:, None], 1e-30)
    light = np.array([0.4, -0.5, 0.75])
    shade = 0.35 + 0.65 * np.abs(n @ (light / np.linalg.norm(light)))
    return np.clip(base * shade[:, None], 0, 1)


def render(out):
    name = os.path.basename(os.path.normpath(out))
    tris = benchlib.read_stl(os.path.join(out, "result.stl"))
    draw(tris, shaded(tris, np.tile([0.55, 0.65, 0.85], (len(tris), 1))), os.path.join(out, "views.png"),
         "%s: result.stl (%d triangles)" % (name, len(tris)))
    vtu = os.path.join(out, "verification.vtu")
    if not os.path.exists(vtu):
        return
    import matplotlib.cm as cm
    points, tets, arrays = crisp.read_vtu(vtu)
    key = sorted(k for k in arrays if k.startswith("von_mises"))[0]
    vm = arrays[key]
    faces, owner = boundary_faces(tets)
    ftris = points[faces]
    top = np.percentile(vm, 99.5)
    colours = cm.jet(np.clip(vm[owner] / top, 0, 1))[:, :3]
    draw(ftris, shaded(ftris, colours), os.path.join(out, "von_mises.png"),
         "%s: verification, %s on the result solid (%d tets); blue 0 .. red %.0f MPa (99.5th percentile), max %.0f MPa"
         % (name, key, len(tets), top, vm.max()))


if __name__ == "__main__":
    for d in sys.argv[1:]:
        render(d)
        print("rendered", d)
