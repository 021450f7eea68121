"""The crisp design of a `topopt optimize` run, evaluated independently by CalculiX.

Reads the run's density.vtu (tets, domains, element densities and, when the run wrote it, the
`kept` field of the design it hands over), takes the problem deck that `topopt solve --inp`
wrote for the same mesh (nodes, *BOUNDARY, *CLOAD of one load case), keeps only the crisp
design's tets, writes that as a new deck and runs ccx on it. Compliance = F·u over the loaded
nodes, from ccx's printed displacements. Used by bench/result/run.py.
"""
import os, re, subprocess
import numpy as np


def read_vtu(path):
    """ASCII VTU as written by topopt: points (#V x 3), tets (#T x 4), cell arrays by name."""
    text = open(path).read()
    arrays = {}
    for m in re.finditer(r'<DataArray([^>]*)>(.*?)</DataArray>', text, re.S):
        head, body = m.group(1), m.group(2)
        name = re.search(r'Name="([^"]*)"', head)
        arrays[name.group(1) if name else "points"] = np.array(body.split(), dtype=float)
    points = arrays.pop("points").reshape(-1, 3)
    tets = arrays.pop("connectivity").astype(np.int64).reshape(-1, 4)
    for k in ("offsets", "types"):
        arrays.pop(k)
    return points, tets, arrays


def tet_volumes(points, tets):
    p = points[tets]
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6


def grey_share(density, domain, volume, lo=0.1, hi=0.9):
    """Share of the design volume (domain 0) whose element density lies strictly in (lo, hi)."""
    d = domain == 0
    grey = d & (density > lo) & (density < hi)
    return volume[grey].sum() / volume[d].sum()


def node_densities(points, tets, domain, density, product=False):
    """Volume-weighted mean of the tets' densities around each node, 1 on non-design nodes.
    product=True: what src/result/iso_surface's node_densities does — the mean over the design tets
    only, 1 on the nodes no design tet touches (a node on a non-design solid's face then reads the
    design beside it, not 1; the default reads every such node solid, a skin one tet thick over
    the non-design faces that the product's crisp design does not hold)."""
    vol = np.abs(tet_volumes(points, tets))
    if product:
        vol = vol * (domain == 0)
    num = np.zeros(len(points))
    den = np.zeros(len(points))
    for a in range(4):
        np.add.at(num, tets[:, a], vol * density)
        np.add.at(den, tets[:, a], vol)
    nd = num / np.maximum(den, 1e-300)
    if product:
        return np.where(den > 0, nd, 1.0)
    nd[np.unique(tets[domain != 0])] = 1.0
    return nd


def crisp_tets(points, tets, domain, density, threshold, product=False):
    """Tets of the crisp design: non-design tets, and design tets where the node-density field
    at the centroid (the mean of its four nodes) reaches the threshold of the result shape
    (product: node_densities' rule)."""
    nd = node_densities(points, tets, domain, density, product)
    return (domain != 0) | (nd[tets].mean(axis=1) >= threshold)


def run_crisp_design(out):
    """A `topopt optimize` run folder's mesh and the product's crisp design: (points, tets, domain,
    solid #T as 0/1 floats) from density.vtu at the threshold of history.json."""
    import json
    points, tets, arrays = read_vtu(os.path.join(out, "density.vtu"))
    h = json.load(open(os.path.join(out, "history.json")))
    domain = arrays["domain"].astype(np.int64)
    solid = crisp_tets(points, tets, domain, arrays["design"], h["threshold"], product=True).astype(float)
    return points, tets, domain, solid


def parse_inp(path):
    """Nodes (#V x 3, node i+1 on row i), *BOUNDARY lines and *CLOAD (node, dof, value) of a
    deck written by topopt solve --inp, and the *MATERIAL block's text."""
    lines = open(path).read().splitlines()
    nodes, bnd, cload, material, section = [], [], [], [], None
    for ln in lines:
        if ln.startswith("**"):
            continue
        if ln.startswith("*"):
            key = ln.split(",")[0].upper()
            section = key
            if key in ("*MATERIAL", "*ELASTIC", "*DENSITY"):
                material.append(ln)
            continue
        if section == "*NODE":
            nodes.append([float(v) for v in ln.split(",")[1:4]])
        elif section == "*BOUNDARY":
            bnd.append(ln)
        elif section == "*CLOAD":
            n, dof, v = ln.split(",")
            cload.append((int(n), int(dof), float(v)))
        elif section in ("*ELASTIC", "*DENSITY"):
            material.append(ln)
    return np.array(nodes), bnd, cload, material


def face_connected_part(tets, keep, seeds):
    """The kept tets face-connected to a kept tet holding one of the seed nodes (#V bool):
    pieces hanging on by an edge or a node would make the stiffness matrix singular."""
    idx = np.nonzero(keep)[0]
    faces = {}
    parent = np.arange(len(idx))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for k, t in enumerate(tets[idx]):
        for f in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
            key = tuple(sorted(t[list(f)]))
            other = faces.pop(key, None)
            if other is None:
                faces[key] = k
            else:
                a, b = find(k), find(other)
                if a != b:
                    parent[a] = b
    roots = np.array([find(k) for k in range(len(idx))])
    seeded = np.unique(roots[seeds[tets[idx]].any(axis=1)])
    out = np.zeros(len(tets), bool)
    out[idx[np.isin(roots, seeded)]] = True
    return out


def ccx_compliance(deck, points, tets, keep, workdir, name):
    """Compliance F·u of the kept tets under the deck's supports and one load case, by ccx.
    Returns (compliance, number of tets solved)."""
    nodes, bnd, cload, material = parse_inp(deck)
    if nodes.shape != points.shape or np.abs(nodes - points).max() > 1e-6:
        raise SystemExit(deck + ": its mesh is not the one of the optimisation run")
    seeds = np.zeros(len(points), bool)
    for n, _, _ in cload:
        seeds[n - 1] = True
    keep = face_connected_part(tets, keep, seeds)
    used = np.unique(tets[keep])
    usedset = np.zeros(len(points), bool)
    usedset[used] = True
    os.makedirs(workdir, exist_ok=True)
    path = os.path.join(workdir, name + ".inp")
    with open(path, "w") as f:
        f.write("*HEADING\ncrisp design of %s\n*NODE, NSET=NALL\n" % name)
        for i in used:
            f.write("%d, %.12g, %.12g, %.12g\n" % (i + 1, *points[i]))
        f.write("*ELEMENT, TYPE=C3D4, ELSET=EALL\n")
        for k in np.nonzero(keep)[0]:
            t = tets[k] + 1
            f.write("%d, %d, %d, %d, %d\n" % (k + 1, *t))
        f.write("\n".join(material) + "\n*SOLID SECTION, ELSET=EALL, MATERIAL=%s\n" % material[0].split("=")[1].strip())
        f.write("*STEP\n*STATIC\n*BOUNDARY\n")
        for ln in bnd:
            if usedset[int(ln.split(",")[0]) - 1]:
                f.write(ln + "\n")
        f.write("*CLOAD\n")
        for n, dof, v in cload:
            if usedset[n - 1]:
                f.write("%d, %d, %.12g\n" % (n, dof, v))
        f.write("*NODE PRINT, NSET=NALL\nU\n*END STEP\n")
    threads = os.environ.get("OMP_NUM_THREADS", "2")  # run.py --threads 1 sets 1
    env = dict(os.environ, OMP_NUM_THREADS=threads, CCX_NPROC_EQUATION_SOLVER=threads)
    p = subprocess.run(["ccx", "-i", name], cwd=workdir, capture_output=True, text=True, env=env)
    dat = os.path.join(workdir, name + ".dat")
    if p.returncode or not os.path.exists(dat):
        raise SystemExit("ccx failed on %s:\n%s" % (path, p.stdout[-2000:]))
    U = np.zeros((len(points), 3))
    table = False
    for ln in open(dat):
        if "displacements (vx,vy,vz)" in ln:
            table = True
            continue
        parts = ln.split()
        if table and len(parts) == 4:
            U[int(parts[0]) - 1] = [float(v) for v in parts[1:]]
    lost = sum(1 for n, _, _ in cload if not usedset[n - 1])
    if lost:
        raise SystemExit("%s: %d loaded nodes are not on the crisp design" % (name, lost))
    return sum(v * U[n - 1, dof - 1] for n, dof, v in cload), int(keep.sum())
