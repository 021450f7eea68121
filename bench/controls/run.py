#!/usr/bin/python3
"""Geometry controls benchmark (issue 22): the cantilever and the bracket (suggested load cases
of ../shared/data/README.md, steel, volume fraction 0.3) through `topopt optimize`, once free
and once with each geometry control (docs/optimization.md, "controls"; the maximum member size on the
cantilever only, the minimum on both — with a minimum size the compliance is the eroded design's, what SIMP minimises). For each run: tets,
iterations, final compliance (SIMP's, on the tet mesh), SIMP wall time, whole-command wall
and CPU time (user + sys), all with OMP_NUM_THREADS=1 and one run after another in this one script; the overhang
share of the result surface built along +x and +y (45°); and a picture of the result surface
(result.stl, rendered with matplotlib) in the work folder. Runs with a minimum member size get a
second table: the smallest member and the share of thin solid tets of the crisp design the user
gets, by the product's member measure (`_native.measure_members`, reach of a mesh size; also
beyond one and two mesh sizes of the non-design tets, where the one-element layer over the supported
face sits and crumbs on its face), and that
design's compliance as `topopt optimize` prints it (the SIMP compliance is the eroded design's).

usage: bench/controls/run.py [--build build] [--work /tmp/controls_bench] [--only cantilever]
                             [--controls free,draw] [--volume 0.3] [--iterations 60]  (labels containing one of these words)
Prints Markdown for BENCHMARKS.md.
"""
import argparse, json, os, re, resource, subprocess, sys, time
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import benchlib  # noqa: E402

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "..", "shared", "data", "examples")
if not os.path.isdir(DATA):
    DATA = "/work/shared/data/examples"

EXAMPLES = benchlib.EXAMPLE_PROBLEMS


def controls_for(name, box):
    """The controls to try on an example whose bounding box is box = (min xyz, max xyz)."""
    lo, hi = np.array(box[0]), np.array(box[1])
    mid = ((lo + hi) / 2).tolist()
    out = {"free": None,
           "symmetry (xz mid-plane)": {"symmetry_planes": [{"point": mid, "normal": [0, 1, 0]}]},
           "extrusion along y": {"extrusion": [0, 1, 0]}}
    if name == "cantilever":
        out["pattern x (3 x 18 mm)"] = {"patterns": [{"direction": [1, 0, 0], "pitch": 18, "count": 3}]}
    if name == "cantilever":  # upright on its fixed end (Face1, x = 0), and on its side (y = 0)
        out["overhang upright (build +x from Face1)"] = {"overhang": {"direction": [1, 0, 0], "base_face": "Face1"}}
        out["overhang on its side (build +y)"] = {"overhang": {"direction": [0, 1, 0]}}
        # member sizes: 60 x 20 x 10 mm on a 2 mm mesh
        out["min member 6 mm"] = {"min_member_size": 6}
        # does not bind here (branch rows22): the free design's widest ball is 6.6 mm and the smallest
        # size this mesh allows is 7.24 mm (three mean edges of 2.41 mm); the property is tested in
        # MemberSize.MaximumSizeHoldsOnTheResultAndIsBrokenWithout
        out["max member 8 mm"] = {"max_member_size": 8}
    if name == "bracket":  # printed lying on its base plate, build +z from its lowest point
        out["overhang lying (build +z)"] = {"overhang": {"direction": [0, 0, 1]}}
        out["min member 9 mm"] = {"min_member_size": 9}  # three mesh sizes of 3 mm
    out["draw z one-sided"] = {"draw_direction": {"direction": [0, 0, 1]}}
    out["draw z split at mid-height"] = {"draw_direction": {"direction": [0, 0, 1], "parting_point": mid}}
    return out


def step_box(path):
    """Bounding box of a STEP file's CARTESIAN_POINTs (vertices, circle centres, placements):
    the part's box for the prismatic examples here."""
    pts = re.findall(r"CARTESIAN_POINT\s*\(\s*'[^']*'\s*,\s*\(([^)]*)\)", open(path).read())
    xyz = np.array([[float(v) for v in p.split(",")] for p in pts if p.count(",") == 2])
    return xyz.min(0).tolist(), xyz.max(0).tolist()


BUILDS = {"+x": np.array([1.0, 0, 0]), "+y": np.array([0, 1.0, 0]), "+z": np.array([0, 0, 1.0])}  # shares reported


def overhang_share(stl, up, angle=45.0, tol=1e-3):
    """Share of the surface's downward-facing area (normal n with n·up < 0, off the base plate
    at the lowest point along up) whose normal lies within `angle` of −up: too flat to print
    without supports (the measure of simp/controls/overhang_measure.h)."""
    _, area, down, flat = _down_and_flat(stl, up, angle, tol)
    return area[flat].sum() / max(area[down].sum(), 1e-30)


def _down_and_flat(stl, up, angle, tol):
    """The STL's triangles (#T x 3 x 3), their areas, and flags: facing down along `up` (off the
    base plate at the lowest point), and of those, within `angle` of −up."""
    tris = benchlib.read_stl(stl)
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    area = np.linalg.norm(n, axis=1) / 2
    s = tris @ up
    plate = s.min()
    on_plate = (s.min(1) >= plate - tol) & (s.max(1) <= plate + tol)
    down = (n @ up < 0) & ~on_plate & (area > 0)
    flat = down & (-(n @ up) > np.cos(np.radians(angle)) * 2 * area)
    return tris, area, down, flat


def _nondesign_boundary(points, tets, domain):
    """The non-design solids' boundary triangles, each #B x 3 x 3: those inside Ω (faces of
    non-design tets that a design tet shares) and those on Ω's boundary (no other tet shares them)."""
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
    fixed = np.tile(domain != 0, 4)
    _, inverse, count = np.unique(np.sort(faces, axis=1), axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    fixed_count = np.bincount(inverse, weights=fixed, minlength=len(count))
    inside = fixed & (count[inverse] == 2) & (fixed_count[inverse] == 1)
    outside = fixed & (count[inverse] == 1)
    return points[faces[inside]], points[faces[outside]]


def _on_triangles(p, tris, tol=1e-3):
    """#P flags: point p[i] lies within tol of one of the triangles tris (#B x 3 x 3)."""
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    n = np.cross(b - a, c - a)
    n2 = np.einsum("ij,ij->i", n, n)
    out = np.zeros(len(p), dtype=bool)
    for i, q in enumerate(p):
        dist = np.einsum("ij,ij->i", q - a, n) / np.sqrt(n2)
        near = np.abs(dist) < tol
        if not near.any():
            continue
        # barycentric coordinates of q's projection on the near triangles
        w = np.stack([np.einsum("ij,ij->i", np.cross(c - b, q - b), n), np.einsum("ij,ij->i", np.cross(a - c, q - c), n),
                      np.einsum("ij,ij->i", np.cross(b - a, q - a), n)], axis=1) / n2[:, None]
        out[i] = (near & (w >= -1e-6).all(axis=1)).any()
    return out


def overhang_on_given_faces(stl, up, vtu, angle=45.0, tol=1e-3):
    """The overhang of a result surface split as simp/controls/overhang_measure.h splits it, a
    triangle being on a non-design face when its centroid lies on one of the run's non-design
    boundary triangles (density.vtu): (overhang area, of it on non-design faces inside Ω — a load
    pad's face the design leaves bare, counted —, of it on non-design faces on Ω's boundary — a
    bore's roof, the part's given shape —, the share without the given faces: what the measure
    holds the control to), areas in mm² (docs/optimization.md, "Overhang", what counts)."""
    sys.path.insert(0, os.path.join(ROOT, "bench", "result"))
    import crisp  # noqa: E402
    points, tets, arrays = crisp.read_vtu(vtu)
    inside, outside = _nondesign_boundary(points, tets, arrays["domain"].astype(np.int64))
    tris, area, down, flat = _down_and_flat(stl, up, angle, tol)
    centroids = tris[down].mean(axis=1)
    bared, given = np.zeros(len(tris), dtype=bool), np.zeros(len(tris), dtype=bool)
    if len(inside):
        bared[down] = _on_triangles(centroids, inside, tol)
    if len(outside):
        given[down] = _on_triangles(centroids, outside, tol) & ~bared[down]
    counted = area[down & ~given].sum()
    return (area[flat].sum(), area[flat & bared].sum(), area[flat & given].sum(),
            area[flat & ~given].sum() / max(counted, 1e-30))


def member_columns(build, out, size, mesh_size, stdout):
    """For a run with a minimum member size: the crisp design the user gets (the run's cleaned
    densities, `design` in density.vtu, through the node densities at the run's threshold, by the
    product's rule: crisp.crisp_tets(product=True); before branch member10 every node of a
    non-design tet read 1 here, which added a skin one tet thick over the non-design faces) measured by the product's member measure
    (simp/controls/member_measure.h, reach of a mesh size): its smallest member, the share of its
    solid design tets thinner than the size less a mesh size (the measure's resolution), and the
    crisp design's compliance that `topopt optimize` prints with its verification."""
    sys.path.insert(0, os.path.join(build, "workbench", "TopOpt", "topopt"))
    sys.path.insert(0, os.path.join(ROOT, "bench", "result"))
    import _native  # noqa: E402
    import crisp  # noqa: E402
    # the product's crisp design (src/result/design_hygiene's crisp_tets of iso_surface's node densities)
    points, tets, domain, solid = crisp.run_crisp_design(out)
    h = json.load(open(os.path.join(out, "history.json")))
    m = _native.measure_members(points, tets, domain, solid, mesh_size)
    design_solid = (domain == 0) & (solid > 0.5)
    thin = (np.asarray(m["thickness"])[design_solid] < size - mesh_size).mean() if design_solid.any() else 0.0
    # beyond a mesh size of every non-design tet (the layer keep_loaded_faces holds over the
    # supported face is one element thick, and the design row on it reads as thin as that layer)
    from scipy.spatial import cKDTree
    centre = points[tets].mean(axis=1)
    # ... and beyond two (crumbs on that layer's face sit in the second row)
    gap = cKDTree(centre[domain != 0]).query(centre)[0] if (domain != 0).any() else np.full(len(tets), np.inf)
    beyond = np.asarray(m["thickness"])[design_solid & (gap > mesh_size)]
    beyond2 = np.asarray(m["thickness"])[design_solid & (gap > 2 * mesh_size)]
    c = re.search(r"crisp design ([0-9.eE+-]+) N\*mm", stdout)
    apart = "came apart" if "eroded design came apart" in stdout else \
        "not joined" if "does not join the supports" in stdout else "no"
    # the crisp design's share of the design domain, and what the minimum size's pass added (mm³)
    vol = np.abs(np.einsum("ij,ij->i", np.cross(points[tets[:, 1]] - points[tets[:, 0]], points[tets[:, 2]] - points[tets[:, 0]]),
                           points[tets[:, 3]] - points[tets[:, 0]])) / 6
    share = vol[design_solid].sum() / vol[domain == 0].sum()
    added = h.get("design", {}).get("min_member", {}).get("volume_added", 0.0)
    return (m["smallest_member"], beyond.min() if beyond.size else float("nan"),
            beyond2.min() if beyond2.size else float("nan"), thin, float(c.group(1)) if c else float("nan"), apart,
            share, added)


def run(cmd):
    """cmd with OpenMP and OpenBLAS held to one thread: (wall s, CPU s (user + sys of the command), the
    completed process)."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), p


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--work", default="/tmp/controls_bench")
    ap.add_argument("--only", default="")
    ap.add_argument("--iterations", type=int, default=60)
    ap.add_argument("--volume", type=float, default=0.3, help="the volume fraction of every run")
    ap.add_argument("--controls", default="", help="comma-separated words: run only the controls whose label has one")
    ap.add_argument("--pictures-only", action="store_true", help="render the result.stl files of an earlier run")
    a = ap.parse_args()
    if a.pictures_only:
        for d in sorted(os.listdir(a.work)):
            stl = os.path.join(a.work, d, "result.stl")
            if os.path.exists(stl):
                h = json.load(open(os.path.join(a.work, d, "history.json")))
                benchlib.picture(stl, os.path.join(a.work, d + ".png"), "%s: compliance %.4g" % (d, h["history"][-1]["compliance"]))
        return
    os.makedirs(a.work, exist_ok=True)
    topopt = os.path.join(a.build, "topopt")
    print("| example | control | tets | variables | iterations | compliance (N·mm) | vs free | SIMP wall (s) | command wall / CPU (s) | "
          "overhang share, build +x / +y / +z | picture |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    members = []
    for name, (size, case) in EXAMPLES.items():
        if a.only and name != a.only:
            continue
        part = os.path.join(DATA, name + ".step")
        box = step_box(part)
        free_c = None
        for label, controls in controls_for(name, box).items():
            if a.controls and not any(w in label for w in a.controls.split(",")):
                continue
            slug = re.sub(r"[^a-z0-9]+", "_", label.lower()).strip("_")
            out = os.path.join(a.work, name + "_" + slug + ("" if a.volume == 0.3 else "_vf%g" % a.volume))
            opt = {"volume_fraction": a.volume, "max_iterations": a.iterations}
            if controls:
                opt["controls"] = controls
            job = {"part": part, "nondesign": os.path.join(DATA, name + "_nondesign.step"), "mesh": {"size": size},
                   "material": {"E": 210000.0, "nu": 0.3}, "optimization": opt, "output": {"directory": out}}
            job.update(case)
            path = out + ".json"
            json.dump(job, open(path, "w"), indent=1)
            wall, cpu, p = run([topopt, "optimize", path, "--verbose"])
            with open(out + ".log", "w") as log:  # the command's messages (the overhang pass's line among them)
                log.write(p.stdout + p.stderr)
            if p.returncode:
                print("| %s | %s | failed: %s |" % (name, label, (p.stderr or p.stdout).strip().splitlines()[-1]))
                continue
            h = json.load(open(os.path.join(out, "history.json")))
            c = h["history"][-1]["compliance"]
            free_c = c if controls is None else free_c
            simp_s = sum(r["seconds"] for r in h["history"])
            tets = re.search(r"(\d+) tets", p.stdout + p.stderr)
            nvar = re.search(r"(\d+) variables for", p.stdout + p.stderr)
            png = out + ".png"
            benchlib.picture(os.path.join(out, "result.stl"), png, "%s, %s: compliance %.4g" % (name, label, c))
            stl = os.path.join(out, "result.stl")
            shares = " / ".join("%.1f %%" % (100 * overhang_share(stl, up)) for up in BUILDS.values())
            if controls and "overhang" in controls:
                up = np.array(controls["overhang"]["direction"], dtype=float)
                over, bared, given, share = overhang_on_given_faces(stl, up / np.linalg.norm(up),
                                                                     os.path.join(out, "density.vtu"))
                shares += " (%.1f mm²: %.1f on bared non-design faces, %.1f on non-design faces on Ω's boundary; " \
                          "without those: **%.1f %%**)" % (over, bared, given, 100 * share)
            if controls and "min_member_size" in controls:
                small, beyond, beyond2, thin, crisp_c, apart, share, added = member_columns(
                    a.build, out, controls["min_member_size"], size, p.stdout + p.stderr)
                members.append("| %s | %s | %g | %.2f mm | %.2f / %.2f mm | %.1f %% | %.4g | %.4g | %.4f | %.0f | %s | %d | %.1f |" % (
                    name, label, a.volume, small, beyond, beyond2, 100 * thin, c, crisp_c, share, added, apart,
                    len(h["history"]), cpu))
            print("| %s | %s | %s | %s | %d | %.4g | %s | %.1f | %.1f / %.1f | %s | %s |" % (
                name, label, tets.group(1) if tets else "?", nvar.group(1) if nvar else "all", len(h["history"]), c,
                "%.2f" % (c / free_c) if free_c else "-", simp_s, wall, cpu, shares, os.path.basename(png)))
            sys.stdout.flush()
    if members:
        print("\n| example | control | volume | smallest member (reach 1 mesh size) | beyond one / two mesh sizes of the non-design tets | "
              "solid design tets thinner than size − mesh size | SIMP compliance (eroded) | crisp design's compliance (N·mm) | "
              "crisp volume (of the design domain) | added by the size (mm³) | eroded design warned | iterations | CPU (s) |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        print("\n".join(members))


if __name__ == "__main__":
    main()
