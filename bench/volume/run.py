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

With --product TOPOPT (a `topopt` executable, e.g. build/topopt or an older build's), it runs
instead the product's path on every part of ../shared/data (the examples with their
non-design solids, NIST 1-6 and 11, linkrods) at the default size and at the --factors given:
`topopt mesh --mesher native`, pinned to one CPU (taskset), and reads the written mesh back to
measure tets, the worst radius ratio, the share of tets below 0.1 and 0.2, the smallest
dihedral angle, the conformity check's verdict (flat and inverted tets), the time and the
tets below 0.1 by class (classify_slivers: boundary nodes, B-Rep edge or vertex, all four on one
face; --classes run.json tabulates them). Rows go
to --json as they finish, so two executables' runs can be tabulated side by side with
--table old.json,new.json.
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


def quality_shares(P, T):
    """(min radius ratio, share below 0.1, share below 0.2, min dihedral angle) of tets T."""
    rr = radius_ratios(P, T)
    return float(rr.min()), float((rr < 0.1).mean()), float((rr < 0.2).mean()), quality(P, T)[2]


def read_msh_tets(path):
    """Nodes (#V by 3, row = node tag; row 0 unused) and tets (#T by 4 node tags) of a Gmsh MSH 4.1 ASCII file."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = lines.index("$Nodes") + 1
    blocks, count = int(lines[i].split()[0]), int(lines[i].split()[1])
    tags, xyz = [], []
    i += 1
    for _ in range(blocks):
        n = int(lines[i].split()[3])
        tags += [int(x) for x in lines[i + 1:i + 1 + n]]
        xyz += lines[i + 1 + n:i + 1 + 2 * n]
        i += 1 + 2 * n
    P = np.zeros((max(tags) + 1, 3))
    P[tags] = np.array(" ".join(xyz).split(), dtype=float).reshape(-1, 3)
    i = lines.index("$Elements") + 1
    blocks = int(lines[i].split()[0])
    i += 1
    tets = []
    for _ in range(blocks):
        _, _, kind, n = (int(x) for x in lines[i].split())
        if kind == 4:
            tets.append(np.array(" ".join(lines[i + 1:i + 1 + n]).split(), dtype=np.int64).reshape(-1, 5)[:, 1:])
        i += 1 + n
    return P, np.vstack(tets)


def read_msh_faces(path):
    """Boundary triangles (#F by 3, node tags as read_msh_tets's rows) and the entity tag of each (#F) of a Gmsh MSH 4.1 ASCII file."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = lines.index("$Elements") + 1
    blocks = int(lines[i].split()[0])
    i += 1
    tris, tags = [], []
    for _ in range(blocks):
        dim, tag, kind, n = (int(x) for x in lines[i].split())
        if kind == 2:
            tris.append(np.array(" ".join(lines[i + 1:i + 1 + n]).split(), dtype=np.int64).reshape(-1, 4)[:, 1:])
            tags.append(np.full(n, tag))
        i += 1 + n
    if not tris:
        return np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.vstack(tris), np.concatenate(tags)


def radius_ratios(P, T):
    """The radius ratio 3 r_in / R of each tet (#T; 0 for a flat one)."""
    a, b, c, d = (P[T[:, i]] for i in range(4))
    vol = np.abs(np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))) / 6
    areas = sum(0.5 * np.linalg.norm(np.cross(y - x, z - x), axis=1) for x, y, z in ((b, c, d), (a, c, d), (a, b, d), (a, b, c)))
    u, v, w = b - a, c - a, d - a
    num = (np.einsum("ij,ij->i", u, u)[:, None] * np.cross(v, w) + np.einsum("ij,ij->i", v, v)[:, None] * np.cross(w, u)
           + np.einsum("ij,ij->i", w, w)[:, None] * np.cross(u, v))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(vol > 0, 3 * (3 * vol / areas) / (np.linalg.norm(num, axis=1) / (12 * vol)), 0.0)


def classify_slivers(P, T, F, ftag, floor=0.1):
    """The tets below `floor` by class: how many of their nodes lie on the boundary (0-4), how
    many of them have a node on a B-Rep edge or vertex (a node in triangles of two or more
    faces), and of those with four boundary nodes how many have all four on one face (a flat
    boundary configuration). P: #V by 3, T: #T by 4 tets, F: #F by 3 boundary triangles with
    face tags ftag (#F). Returns a dict of counts."""
    rr = radius_ratios(P, T)
    bad = T[rr < floor]
    nv = len(P)
    on_boundary = np.zeros(nv, dtype=bool)
    on_boundary[F.ravel()] = True
    # faces per node: distinct (node, tag) pairs counted per node
    pairs = np.unique(np.stack([F.ravel(), np.repeat(ftag, 3)], axis=1), axis=0) if len(F) else np.zeros((0, 2), int)
    faces_at = np.bincount(pairs[:, 0], minlength=nv) if len(pairs) else np.zeros(nv, int)
    node_faces = {}
    for v, t in pairs:
        node_faces.setdefault(int(v), set()).add(int(t))
    nb = on_boundary[bad].sum(axis=1)
    out = {"below": int(len(bad))}
    for k in range(5):
        out["boundary_nodes_%d" % k] = int((nb == k).sum())
    out["on_brep_edge"] = int((faces_at[bad] >= 2).any(axis=1).sum()) if len(bad) else 0
    out["on_brep_vertex"] = int((faces_at[bad] >= 3).any(axis=1).sum()) if len(bad) else 0
    one_face = 0
    for t in bad[nb == 4]:
        common = set.intersection(*(node_faces.get(int(v), set()) for v in t))
        one_face += bool(common)
    out["all_on_one_face"] = one_face
    out["free_node"] = int((nb < 4).sum())
    # a tet on a poor boundary triangle cannot be good whatever its fourth node: the slivers
    # with a face on the boundary whose triangle has 2 r_in / R below 0.2
    def tri_quality(a, b, c):
        la, lb, lc = (np.linalg.norm(y - x, axis=-1) for x, y in ((b, c), (c, a), (a, b)))
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=-1)
        s = (la + lb + lc) / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(area > 0, 2 * (area / s) / (la * lb * lc / (4 * area)), 0.0)
    keys = {tuple(sorted(map(int, f))) for f in F}
    poor = 0
    for t in bad:
        worst = 1.0
        for f in ((t[1], t[2], t[3]), (t[0], t[2], t[3]), (t[0], t[1], t[3]), (t[0], t[1], t[2])):
            if tuple(sorted(map(int, f))) in keys:
                worst = min(worst, float(tri_quality(P[f[0]], P[f[1]], P[f[2]])))
        poor += worst < 0.2
    out["on_poor_boundary_triangle"] = poor
    return out


def product_parts():
    """(name, part file, non-design file or None) for every single-solid part of the data."""
    data = os.path.normpath(os.path.join(ROOT, "..", "shared", "data"))
    out = [(n, os.path.join(data, "examples", n + ".step"), os.path.join(data, "examples", n + "_nondesign.step"))
           for n in ("rocker", "cantilever", "bracket")]
    out += [("NIST %d" % n, os.path.join(data, "nist", "NIST_MBE_PMI_%d.stp" % n), None) for n in (1, 2, 3, 4, 5, 6, 11)]
    return out + [("linkrods", os.path.join(data, "occt", "linkrods.step"), None)]


def product_row(topopt, part, nd, factor, tmp, cpu_id=0):
    """One `topopt mesh --mesher native` on one CPU (cpu_id): its row, or its error."""
    import json, subprocess
    msh, stats = os.path.join(tmp, "m.msh"), os.path.join(tmp, "m.json")
    cmd = ["taskset", "-c", str(cpu_id), topopt, "mesh", "--part", part, "--mesher", "native", "--out", msh, "--stats", stats]
    cmd += ["--non-design", nd] if nd else []
    if factor != 1.0:
        info = json.loads(subprocess.run([topopt, "info", "--part", part, "--json"], capture_output=True, text=True,
                                         check=True).stdout)
        lo, hi = info["part"]["bbox"]["min"], info["part"]["bbox"]["max"]
        cmd += ["--size", repr(factor * sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5 / 50)]
    import resource
    t, cpu0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, capture_output=True, text=True)
    dt, cpu1 = time.perf_counter() - t, resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)  # the load does not change it
    if not os.path.exists(stats):
        return {"error": p.stderr.strip()[-400:], "seconds": dt, "cpu_seconds": round(cpu, 1)}
    s = json.load(open(stats))
    P, T = read_msh_tets(msh)
    rmin, below1, below2, dih = quality_shares(P, T)
    F, ftag = read_msh_faces(msh)
    c = s["conformity"]
    os.remove(stats)
    return {"tets": len(T), "rr_min": rmin, "below_0.1": below1, "below_0.2": below2, "dihedral_min": dih,
            "conformity": c["ok"], "flat": c.get("flat_tets", "-"), "inverted": c["inverted_tets"],
            "seconds": round(dt, 1), "cpu_seconds": round(cpu, 1), "mesh_seconds": round(s["seconds"]["mesh"], 1),
            "slivers": classify_slivers(P, T, F, ftag)}


def product(args):
    """--product runs; with --before OLD, each row runs OLD first then --product, one after the
    other (the same load for both), OLD's rows going to --json with .before before its suffix."""
    import json, tempfile
    runs = [(args.product, args.json)]
    if args.before:
        runs.insert(0, (args.before, "%s.before%s" % os.path.splitext(args.json)))
    rows = {path: json.load(open(path)) if os.path.exists(path) else {} for _, path in runs}
    with tempfile.TemporaryDirectory() as tmp:
        for name, part, nd in product_parts():
            for f in (float(x) for x in args.factors.split(",")):
                key = "%s@%g" % (name, f)
                if args.parts and name not in args.parts.split(","):
                    continue
                for topopt, path in runs:
                    if key in rows[path]:
                        continue
                    rows[path][key] = product_row(topopt, part, nd, f, tmp, args.cpu)
                    print(key, topopt, json.dumps(rows[path][key]), file=sys.stderr, flush=True)
                    json.dump(rows[path], open(path, "w"), indent=1)


def table(files):
    """Two --json files (before, after) side by side as a Markdown table (rows of the second)."""
    import json
    old, new = (json.load(open(f)) for f in files.split(","))
    print("| part | size | tets before / after | radius ratio min before / after | tets < 0.1 before / after |"
          " share < 0.2 before / after | flat / inverted after | conformity after | CPU s before / after |")
    print("|---|---|---|---|---|---|---|---|---|")
    pct = lambda x: "%.3f %%" % (100 * x)
    for key in new:
        a, b = old.get(key, {}), new[key]
        name, f = key.split("@")
        size = "default" if float(f) == 1.0 else "%s×" % f
        if "error" in b or "error" in a or not a:
            print("| %s | %s | before: %s / after: %s | | | | | |" % (name, size, a.get("error", "-")[-80:],
                                                                    b.get("error", "-")[-80:]))
            continue
        below = lambda r: "%d (%s)" % (round(r["below_0.1"] * r["tets"]), pct(r["below_0.1"]))
        print("| %s | %s | %d / %d | %.4f / %.4f | %s / %s | %s / %s | %s / %s | %s | %s / %s |" % (
            name, size, a["tets"], b["tets"], a["rr_min"], b["rr_min"], below(a), below(b),
            pct(a["below_0.2"]), pct(b["below_0.2"]), b["flat"], b["inverted"], "ok" if b["conformity"] else "DEFECTS",
            a["cpu_seconds"], b["cpu_seconds"]))


def classes(path):
    """The sliver classes of a --json run (classify_slivers) as a Markdown table."""
    import json
    rows = json.load(open(path))
    print("| part | size | tets | worst radius ratio | < 0.1 | 4 / 3 / 2 / 1 / 0 boundary nodes | on a B-Rep edge / vertex |"
          " 4 nodes on one face | with a free node | on a boundary triangle < 0.2 | CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for key, r in rows.items():
        name, f = key.split("@")
        size = "default" if float(f) == 1.0 else "%s×" % f
        if "error" in r:
            print("| %s | %s | error: %s | | | | | | | | %s |" % (name, size, r["error"][-80:], r.get("cpu_seconds", "")))
            continue
        c = r["slivers"]
        print("| %s | %s | %d | %.4f | %d | %s | %d / %d | %d | %d | %d | %s |" % (
            name, size, r["tets"], r["rr_min"], c["below"], " / ".join(str(c["boundary_nodes_%d" % k]) for k in (4, 3, 2, 1, 0)),
            c["on_brep_edge"], c["on_brep_vertex"], c["all_on_one_face"], c["free_node"],
            c["on_poor_boundary_triangle"], r["cpu_seconds"]))


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
    ap.add_argument("--product", help="a topopt executable: its product path on every shared part (see above)")
    ap.add_argument("--before", help="with --product: an older topopt run on each row just before --product")
    ap.add_argument("--factors", default="1.0,0.6", help="with --product: sizes as factors of the default")
    ap.add_argument("--cpu", type=int, default=0, help="with --product: the CPU the runs are pinned to")
    ap.add_argument("--parts", default="", help="with --product: only these parts (names as in the table)")
    ap.add_argument("--json", default="product.json", help="with --product: rows kept here (a rerun skips them)")
    ap.add_argument("--table", help="old.json,new.json: the two --product runs as one Markdown table")
    ap.add_argument("--classes", help="a --product run's json: its slivers by class as a Markdown table")
    args = ap.parse_args()
    if args.classes:
        return classes(args.classes)
    if args.table:
        return table(args.table)
    if args.product:
        return product(args)
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
