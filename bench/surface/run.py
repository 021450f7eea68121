#!/usr/bin/python3
"""Surface meshing benchmark: our surface mesher against Gmsh's, same parts, same sizes, one run.

For every part in ../shared/data (examples, nist, occt) and every size factor:
- ours: `topopt surface --part P --size H --stats` (its own meshing time, B-Rep read excluded);
- Gmsh: import the same file, Mesh.MeshSizeMax = H, Mesh.MeshSizeMin = H/10,
  Mesh.MeshSizeFromCurvature = 16 (our default: 2π/16 of turning per element), its default
  2D algorithm (Frontal-Delaunay), 2 threads; time of generate(2) only.
The angle figures are computed for both by the same function (smallest angle, mean of the
smallest angles, share and count of triangles with a smallest angle below 20°, and the count of
face corners below 20°, where any mesh must have such a triangle). H = diagonal / 50
(our default) times the factor.

usage: bench/surface/run.py [--build build] [--factors 1,0.5] [--parts rocker,NIST_MBE_PMI_1]
Prints a Markdown table for BENCHMARKS.md.
"""
import argparse, glob, json, math, os, subprocess, sys, tempfile, time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "..", "shared", "data")


def angles(P, T, face):
    """(smallest angle, mean smallest angle, share below 20°, triangles, triangles below 20°,
    face corners below 20°) in degrees. A face corner below 20° (the angles of one face's
    triangles at one node summing to less than 20°) forces a triangle below 20° on any mesh;
    the others are the mesher's doing."""
    a, b, c = P[T[:, 0]], P[T[:, 1]], P[T[:, 2]]

    def ang(x, y, z):  # angle at x
        u, v = y - x, z - x
        return np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v)))

    A = np.stack([ang(a, b, c), ang(b, c, a), ang(c, a, b)], axis=1)
    m = A.min(axis=1)
    # angle sums per (face, node)
    key = face.astype(np.int64)[:, None] * (int(T.max()) + 1) + T
    uniq, inv = np.unique(key.ravel(), return_inverse=True)
    sums = np.bincount(inv, weights=A.ravel(), minlength=len(uniq))
    return float(m.min()), float(m.mean()), float((m < 20).mean()), len(T), int((m < 20).sum()), int((sums < 20).sum())


def diagonal(path):
    import gmsh
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.occ.importShapes(path)
    gmsh.model.occ.synchronize()
    x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(-1, -1)
    gmsh.finalize()
    return math.dist((x0, y0, z0), (x1, y1, z1))


def run_gmsh(path, h):
    import gmsh
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 2)
    gmsh.model.occ.importShapes(path)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeMin", h / 10)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 16)
    t = time.perf_counter()
    gmsh.model.mesh.generate(2)
    dt = time.perf_counter() - t
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    P = np.asarray(xyz).reshape(-1, 3)
    index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    tris, face = [], []
    for dim, tag in gmsh.model.getEntities(2):
        types, _, nodes = gmsh.model.mesh.getElements(dim, tag)
        for ty, nd in zip(types, nodes):
            if ty == 2:
                tris.append(np.asarray(nd, dtype=np.int64).reshape(-1, 3))
                face.append(np.full(len(tris[-1]), tag))
    gmsh.finalize()
    T = index[np.concatenate(tris)]
    return dt, angles(P, T, np.concatenate(face))


def read_stl(path):
    """Nodes (merged: a node's copies are the same floats), triangles and the face numbers that
    `topopt surface` writes in each triangle's attribute bytes."""
    with open(path, "rb") as f:
        f.read(80)
        n = int(np.frombuffer(f.read(4), dtype=np.uint32)[0])
        rec = np.frombuffer(f.read(50 * n), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    P, T = np.unique(rec["v"].reshape(-1, 3), axis=0, return_inverse=True)
    return P.astype(np.float64), T.reshape(-1, 3), rec["a"].astype(np.int64)


def run_ours(build, path, h, tmp):
    stats, stl = os.path.join(tmp, "s.json"), os.path.join(tmp, "s.stl")
    r = subprocess.run([os.path.join(build, "topopt"), "surface", "--part", path, "--size", str(h), "--stats", stats, "--out", stl],
                       capture_output=True, text=True)
    s = json.load(open(stats))
    ok = r.returncode == 0
    P, T, face = read_stl(stl)  # the same angle function as for Gmsh (STL floats: angles to ~1e-5°)
    return s["seconds"]["mesh"], angles(P, T, face), ok, s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--factors", default="1,0.5")
    ap.add_argument("--parts", default="")
    args = ap.parse_args()
    files = sorted(glob.glob(os.path.join(DATA, "examples", "*.step"))) + sorted(glob.glob(os.path.join(DATA, "nist", "*.stp"))) + \
        sorted(glob.glob(os.path.join(DATA, "occt", "*.br*p"))) + sorted(glob.glob(os.path.join(DATA, "occt", "*.step")))
    if args.parts:
        keep = args.parts.split(",")
        files = [f for f in files if os.path.splitext(os.path.basename(f))[0] in keep]
    rows, tot_ours, tot_gmsh = [], 0.0, 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for path in files:
            d = diagonal(path)
            for fac in [float(x) for x in args.factors.split(",")]:
                h = d / 50 * fac
                to, qo, ok, s = run_ours(args.build, path, h, tmp)
                tg, qg = run_gmsh(path, h)
                tot_ours += to
                tot_gmsh += tg
                name = os.path.basename(path)
                rows.append((name, h, qo, to, qg, tg, ok, s))
                print(f"{name} h={h:.3g}: ours {qo[3]} tris {to:.3f}s min {qo[0]:.1f} <20 {100*qo[2]:.2f}% ({qo[4]}, {qo[5]} forced) | "
                      f"gmsh {qg[3]} tris {tg:.3f}s min {qg[0]:.1f} <20 {100*qg[2]:.2f}% ({qg[4]}, {qg[5]} forced) | closed+no-crossing {ok}",
                      file=sys.stderr, flush=True)
    print("| part | size (mm) | triangles ours / Gmsh | smallest angle ours / Gmsh | mean smallest ours / Gmsh | "
          "share < 20° ours / Gmsh | triangles < 20° ours / Gmsh (face corners < 20°) | time ours / Gmsh (s) | Gmsh time ÷ ours | "
          "closed, no self-intersection |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, h, qo, to, qg, tg, ok, s in rows:
        print(f"| {name} | {h:.3g} | {qo[3]} / {qg[3]} | {qo[0]:.2f}° / {qg[0]:.2f}° | {qo[1]:.1f}° / {qg[1]:.1f}° | "
              f"{100*qo[2]:.3f} % / {100*qg[2]:.3f} % | {qo[4]} / {qg[4]} ({qo[5]} / {qg[5]}) | {to:.3f} / {tg:.3f} | "
              f"{tg/max(to,1e-9):.1f}× | {'yes' if ok else 'NO'} |")
    print(f"\nTotal meshing time: ours {tot_ours:.2f} s, Gmsh {tot_gmsh:.2f} s ({tot_gmsh/max(tot_ours,1e-9):.1f}× ours).")


if __name__ == "__main__":
    main()
