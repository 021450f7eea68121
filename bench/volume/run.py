#!/usr/bin/python3
"""Volume meshing benchmark: our volume fill (Delaunay bulk finished by the 3D advancing front,
the default, and the front alone) against Gmsh's default 3D algorithm (Delaunay, 2 threads)
and Netgen's, filling the SAME surface mesh (ours) at the same size, one run.

For each part and size: our surface mesher makes the surface (native module); then
- ours: fill_volume through the native module (its own timer: the fill alone), with the
  Delaunay bulk and with the front alone;
- Gmsh: the surface as a discrete entity, a geo volume on it, generate(3) timed;
- Netgen: the surface as 2D elements, GenerateVolumeMesh timed.
Tets, radius ratio (3 r_in / R: min, mean) and smallest dihedral angle are computed for all
three by the same numpy code.

Every mesher runs --repeat times (default 3) and its best time counts (the machines are
shared and noisy); the mesh of the last run is measured.

usage: bench/volume/run.py [--build build] [--repeat 3] [--cases rocker:1.0,rocker:2.77,cantilever:1.28]
Prints a Markdown table for BENCHMARKS.md.
"""
import argparse, os, sys, time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "..", "shared", "data", "examples")


def quality(P, T):
    """(min radius ratio, mean radius ratio, min dihedral angle in degrees) of tets T."""
    a, b, c, d = (P[T[:, i]] for i in range(4))
    vol = np.abs(np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))) / 6
    faces = [(b, c, d), (a, c, d), (a, b, d), (a, b, c)]
    areas = [0.5 * np.linalg.norm(np.cross(y - x, z - x), axis=1) for x, y, z in faces]
    r_in = 3 * vol / sum(areas)
    # circumradius: |(|u|² v×w + |v|² w×u + |w|² u×v)| / (12 V)
    u, v, w = b - a, c - a, d - a
    num = (np.einsum("ij,ij->i", u, u)[:, None] * np.cross(v, w) + np.einsum("ij,ij->i", v, v)[:, None] * np.cross(w, u)
           + np.einsum("ij,ij->i", w, w)[:, None] * np.cross(u, v))
    R = np.linalg.norm(num, axis=1) / (12 * vol)
    rr = 3 * r_in / R
    # dihedral angle at each edge (p, q): the angle between the other two nodes seen across
    # the edge, both projected onto the plane normal to it
    X = [a, b, c, d]
    dmin = np.full(len(T), 180.0)
    for i, j, k, l in ((0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2), (1, 2, 0, 3), (1, 3, 0, 2), (2, 3, 0, 1)):
        e = X[j] - X[i]
        e = e / np.linalg.norm(e, axis=1)[:, None]
        uu, vv = X[k] - X[i], X[l] - X[i]
        uu = uu - np.einsum("ij,ij->i", uu, e)[:, None] * e
        vv = vv - np.einsum("ij,ij->i", vv, e)[:, None] * e
        cosang = np.einsum("ij,ij->i", uu, vv) / (np.linalg.norm(uu, axis=1) * np.linalg.norm(vv, axis=1))
        dmin = np.minimum(dmin, np.degrees(np.arccos(np.clip(cosang, -1, 1))))
    return float(rr.min()), float(rr.mean()), float(dmin.min())


def run_gmsh(P, F, h):
    import gmsh
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 2)
    s = gmsh.model.addDiscreteEntity(2)
    gmsh.model.mesh.addNodes(2, s, list(range(1, len(P) + 1)), P.flatten().tolist())
    gmsh.model.mesh.addElementsByType(s, 2, [], (F + 1).flatten().tolist())
    loop = gmsh.model.geo.addSurfaceLoop([s])
    gmsh.model.geo.addVolume([loop])
    gmsh.model.geo.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    t = time.perf_counter()
    gmsh.model.mesh.generate(3)
    dt = time.perf_counter() - t
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    Pg = np.zeros((int(tags.max()) + 1, 3))
    Pg[tags.astype(int)] = np.asarray(xyz).reshape(-1, 3)
    _, _, nodes = gmsh.model.mesh.getElements(3)
    T = np.asarray(nodes[0], dtype=np.int64).reshape(-1, 4)
    gmsh.finalize()
    return dt, Pg, T


def run_netgen(P, F, h):
    from netgen.meshing import Element2D, FaceDescriptor, Mesh, MeshingParameters, MeshPoint
    from netgen.csg import Pnt
    try:
        from netgen.meshing import SetMessageImportance
        SetMessageImportance(0)  # Netgen's progress messages would mix into the table
    except ImportError:
        pass
    m = Mesh()
    m.dim = 3
    ids = [m.Add(MeshPoint(Pnt(*map(float, p)))) for p in P]
    fd = m.Add(FaceDescriptor(bc=1, domin=1, domout=0, surfnr=1))
    for t in F:
        m.Add(Element2D(fd, [ids[int(i)] for i in t]))
    # Netgen's C++ still writes "generate vol mesh" to stdout, which would land in the table
    sys.stdout.flush()
    saved, devnull = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        t = time.perf_counter()
        m.GenerateVolumeMesh(MeshingParameters(maxh=h))
        dt = time.perf_counter() - t
    finally:
        os.dup2(saved, 1)
        os.close(saved), os.close(devnull)
    Pn = np.array([[p[0], p[1], p[2]] for p in m.Points()])
    T = np.array([[v.nr - 1 for v in e.vertices] for e in m.Elements3D()], dtype=np.int64)
    return dt, Pn, T


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--cases", default="rocker:1.0,rocker:2.77,cantilever:1.28,bracket:2.72")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    sys.path.insert(0, os.path.join(args.build, "workbench", "TopOpt", "topopt"))
    import _native
    rows = []
    for case in args.cases.split(","):
        name, h = case.split(":")
        h = float(h)
        s = _native.surface_mesh(_native.read_shape_file(os.path.join(DATA, name + ".step")), h)
        P, F = np.asarray(s["nodes"]), np.asarray(s["triangles"])
        def ours(bulk):
            r = _native.volume_mesh(P, F, h, bulk)
            return r["seconds"], np.asarray(r["nodes"]), np.asarray(r["tets"])

        def best(mesher):  # the best time of --repeat runs, with the last run's mesh
            results = [mesher() for _ in range(args.repeat)]
            return (min(r[0] for r in results),) + tuple(results[-1][1:])

        runs = [("ours (Delaunay bulk + front)", best(lambda: ours(True))), ("ours (front alone)", best(lambda: ours(False))),
                ("Gmsh 3D (Delaunay)", best(lambda: run_gmsh(P, F, h))), ("Netgen", best(lambda: run_netgen(P, F, h)))]
        gmsh_dt = runs[2][1][0]
        for tool, (dt, Q, T) in runs:
            q = quality(Q, T)
            rows.append((name, h, len(F), tool, len(T), q, dt, dt / gmsh_dt))
            print(f"{name} h={h} {tool}: {len(T)} tets {dt:.3f}s rr {q[0]:.3f}/{q[1]:.3f} dihedral {q[2]:.1f}",
                  file=sys.stderr, flush=True)
    print("| part | size (mm) | surface triangles | volume mesher | tets | radius ratio min / mean | smallest dihedral | time (s) | time / Gmsh's |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, h, nf, tool, nt, q, dt, ratio in rows:
        print(f"| {name} | {h:g} | {nf} | {tool} | {nt} | {q[0]:.3f} / {q[1]:.3f} | {q[2]:.1f}° | {dt:.3f} | {ratio:.2f} |")


if __name__ == "__main__":
    main()
