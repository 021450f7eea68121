#!/usr/bin/python3
"""Two-B-Rep meshing benchmark: our 14-step advancing-front mesher against what a Gmsh user
does today for the same result (OCC fragments of the part with the non-design solids, then
Gmsh's 2D and 3D meshers, as src/mesh/two_brep/gmsh_fragments.cpp drives them), one run, same sizes.

Both go through `build/topopt mesh --mesher native|gmsh --stats`, so the same code checks
the results: conformity (duplicate nodes, shared faces, boundary, interface on the non-design
faces, volumes per domain against the B-Reps) and tet quality (radius ratio 3 r_in / R,
dihedral angles). Time = the meshing stage alone (reading and classifying excluded), the
best of --repeat runs.

usage: bench/twobrep/run.py [--build build] [--repeat 2] [--cases rocker:0,rocker:1.4,...]
(size 0 = the default, diagonal / 50). Prints a Markdown table for BENCHMARKS.md.

With --shared JSON, it instead runs both meshers on every part of ../shared/data (the examples
with their non-design solids, NIST 1-6 and 11, linkrods, CrankArm) at the default size, each
pinned to one CPU (taskset -c 0; Gmsh runs with General.NumThreads 1), native then Gmsh per
part in the same run, and keeps tets, mesh time, the largest volume error, the worst radius
ratio and the native mesher's per-face size reasons (counts) in JSON (rows are kept, so a run
can be resumed; --parts a,b re-runs only those). --shared-table JSON prints the ratio table.

With --rows JSON, issue 20's done-when table: the examples with their non-design solids and the
partial-contact fixtures (bench/twobrep/fixtures.py writes them as STEP) through the product's
`topopt mesh` end to end, native and Gmsh alternated --repeat times per row, each run pinned to
CPU --cpu (taskset) with one thread (OMP/OpenBLAS 1; the Gmsh route sets General.NumThreads 1),
nice 15; the CPU time (user + sys) of the whole command, the least of the repeats, is the
pipeline's time. --row-cases names the rows (example:size, size 0 = default, xF = F times the
default; fx:<fixture>:size for a fixture; nist:N:size, occt:linkrods:size for the shared single
solids, meshed without non-design solids); --rows-table JSON prints the table with a verdict per
done-when item (no fallback, conformal, no degenerate tet, radius ratio >= 0.1, tets <= 1.5x
Gmsh's, pipeline CPU <= Gmsh's).
"""
import argparse, json, os, platform, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "..", "shared", "data", "examples")
DEFAULT_CASES = "rocker:0,rocker:1.4,rocker:1,cantilever:0,cantilever:0.8,bracket:0,bracket:2"
ROW_CASES = ("rocker:0,rocker:1.4,cantilever:0,cantilever:0.8,bracket:0,bracket:2,mount:0,mount:x0.5,"
             "fx:bosses_one_side:0,fx:lug_cut_by_outer_face:0,fx:boss_on_cylinder_wall:0,"
             "fx:pad_spanning_two_faces:0,fx:pads_touching_unequal:0,fx:boss_on_bspline_wall:0")


def run(topopt, name, size, mesher, repeat):
    best = None
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeat):
            stats = os.path.join(tmp, "s.json")
            cmd = [topopt, "mesh", "--mesher", mesher, "--part", os.path.join(DATA, name + ".step"),
                   "--non-design", os.path.join(DATA, name + "_nondesign.step"),
                   "--out", os.path.join(tmp, "m.msh"), "--stats", stats]
            if size > 0:
                cmd += ["--size", str(size)]
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0:
                return {"error": (p.stderr.strip().splitlines() or ["failed"])[-1]}
            s = json.load(open(stats))
            if best is None or s["seconds"]["mesh"] < best["seconds"]["mesh"]:
                best = s
    return best


def shared_parts():
    """(name, part file, non-design file or None) for every part of ../shared/data."""
    data = os.path.normpath(os.path.join(ROOT, "..", "shared", "data"))
    out = [(n, os.path.join(data, "examples", n + ".step"), os.path.join(data, "examples", n + "_nondesign.step"))
           for n in ("rocker", "cantilever", "bracket", "mount")]
    out += [("NIST %d" % n, os.path.join(data, "nist", "NIST_MBE_PMI_%d.stp" % n), None) for n in (1, 2, 3, 4, 5, 6, 11)]
    return out + [("linkrods", os.path.join(data, "occt", "linkrods.step"), None),
                  ("CrankArm", os.path.join(data, "occt", "CrankArm.brep"), None)]


def shared_row(topopt, part, nd, mesher, tmp, limit=None):
    """One `topopt mesh` of one part by one mesher on one CPU (nice 5; stopped after `limit`
    seconds of wall time when given): its figures with the CPU time of the whole command, or its
    error."""
    import resource
    stats = os.path.join(tmp, "s.json")
    if os.path.exists(stats):
        os.remove(stats)
    cmd = ["nice", "-n", "5", "taskset", "-c", "0", topopt, "mesh", "--mesher", mesher, "--part", part,
           "--out", os.path.join(tmp, "m.msh"), "--stats", stats] + (["--non-design", nd] if nd else [])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=limit)
    except subprocess.TimeoutExpired:
        return {"error": "did not finish within the bench's limit of %d s (wall)" % limit}
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if not os.path.exists(stats):
        return {"error": (p.stderr.strip().splitlines() or ["failed"])[-1][-300:], "cpu_seconds": round(cpu, 1)}
    s = json.load(open(stats))
    row = {"tets": s["tets"], "seconds": round(s["seconds"]["mesh"], 2), "cpu_seconds": round(cpu, 1),
           "volume_error": s["conformity"]["max_volume_error"], "rr_min": s["quality"]["radius_ratio"]["min"],
           "conformity": s["conformity"]["ok"], "mesher": s.get("mesher", mesher)}
    reasons = {}
    for f in s.get("face_sizes", []):
        reasons[f["reason"]] = reasons.get(f["reason"], 0) + 1
    if reasons:
        row["face_reasons"] = reasons
    return row


GMSH_SCRIPT = r'''
import json, sys, time
import numpy as np
import gmsh
part, nd, size, out = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setNumber("General.NumThreads", 1)
a = gmsh.model.occ.importShapes(part)
if nd:
    b = gmsh.model.occ.importShapes(nd)
    gmsh.model.occ.fragment(a, b)
gmsh.model.occ.synchronize()
brep = sum(gmsh.model.occ.getMass(3, t) for _, t in gmsh.model.getEntities(3))
gmsh.option.setNumber("Mesh.MeshSizeMax", size)
gmsh.option.setNumber("Mesh.MeshSizeMin", size / 10)
gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 40)
gmsh.option.setNumber("Mesh.Optimize", 1)
t = time.perf_counter()
gmsh.model.mesh.generate(3)
dt = time.perf_counter() - t
tags, xyz, _ = gmsh.model.mesh.getNodes()
P = np.zeros((int(tags.max()) + 1, 3))
P[tags.astype(int)] = xyz.reshape(-1, 3)
_, nt = gmsh.model.mesh.getElementsByType(4)
T = nt.astype(int).reshape(-1, 4)
A, B, C, D = (P[T[:, i]] for i in range(4))
vol = np.abs(np.einsum("ij,ij->i", B - A, np.cross(C - A, D - A))).sum() / 6
json.dump({"tets": len(T), "seconds": round(dt, 2), "volume_error": abs(vol - brep) / brep}, open(out, "w"))
np.save(out + ".npy", np.hstack([P[T[:, i]] for i in range(4)]))
'''


def gmsh_row(part, nd, size, tmp, limit):
    """Gmsh (python3-gmsh, 1 thread) with the product's settings (MeshSizeMax = size, MeshSizeMin =
    size / 10, 40 elements per 2π, Optimize): tets, time of generate(3), total volume error and
    the worst radius ratio; used where the product's Gmsh fallback stops at its time budget."""
    import importlib.util
    import numpy as np
    spec = importlib.util.spec_from_file_location("volume_bench", os.path.join(ROOT, "bench", "volume", "run.py"))
    volume_bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(volume_bench)
    out = os.path.join(tmp, "g.json")
    script = os.path.join(tmp, "g.py")
    open(script, "w").write(GMSH_SCRIPT)
    try:
        subprocess.run(["taskset", "-c", "0", "/usr/bin/python3", script, part, nd or "", repr(size), out],
                       capture_output=True, text=True, timeout=limit)
    except subprocess.TimeoutExpired:
        return {"error": "python3-gmsh did not finish in %d s" % limit}
    if not os.path.exists(out):
        return {"error": "python3-gmsh failed"}
    row = json.load(open(out))
    X = np.load(out + ".npy")
    P = X.reshape(-1, 3)
    T = np.arange(len(P)).reshape(-1, 4)
    row["rr_min"] = volume_bench.quality_shares(P, T)[0]
    row["conformity"] = None
    row["mesher"] = "python3-gmsh"
    return row


def part_size(topopt, part):
    """The default mesh size of part (diagonal / 50), or None when topopt refuses the part (the
    refusal is then the row's error on both sides, e.g. CrankArm's two solids)."""
    p = subprocess.run([topopt, "info", "--part", part, "--json"], capture_output=True, text=True)
    if p.returncode:
        return None
    info = json.loads(p.stdout)
    lo, hi = info["part"]["bbox"]["min"], info["part"]["bbox"]["max"]
    return sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5 / 50


def shared(args):
    rows = json.load(open(args.shared)) if os.path.exists(args.shared) else {}
    topopt = os.path.join(args.build, "topopt")
    only = args.parts.split(",") if args.parts else None
    with tempfile.TemporaryDirectory() as tmp:
        for name, part, nd in shared_parts():
            if (only and name not in only) or (not only and name in rows):
                continue
            rows[name] = {m: shared_row(topopt, part, nd, m, tmp, args.limit) for m in ("native", "gmsh")}
            if "error" in rows[name]["gmsh"]:  # the product's budget: Gmsh through python3-gmsh instead
                rows[name]["gmsh_cli_error"] = rows[name]["gmsh"]["error"]
                size = part_size(topopt, part)
                if size is not None:
                    rows[name]["gmsh"] = gmsh_row(part, nd, size, tmp, args.gmsh_limit)
            print(name, json.dumps(rows[name]), file=sys.stderr, flush=True)
            json.dump(rows, open(args.shared, "w"), indent=1)


def shared_table(path):
    """The ratio table of a --shared JSON: native against Gmsh per part (an error in full)."""
    rows = json.load(open(path))
    print("| part | tets native / gmsh | ratio | time native / gmsh (s) | ratio | CPU native / gmsh (s) | ratio |"
          " volume error native / gmsh | worst radius ratio native / gmsh | conformal (native) |"
          " faces by binding size rule (native) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        a, b = r["native"], r["gmsh"]
        if "error" in a or "error" in b:
            print("| %s | native: %s / gmsh: %s | | | | | | | | | |" % (name, a.get("error", "ok")[-160:],
                                                                      b.get("error", "ok")[-160:]))
            continue
        why = ", ".join("%s %d" % kv for kv in sorted(a.get("face_reasons", {}).items()))
        ca, cb = a.get("cpu_seconds"), b.get("cpu_seconds")
        cpu = ("%.1f / %.1f | %.2f" % (ca, cb, ca / max(cb, 1e-9))) if ca and cb else " | "
        print("| %s | %d / %d | %.2f | %.2f / %.2f | %.2f | %s | %.3f %% / %.3f %% | %.3f / %.3f | %s | %s |" % (
            name, a["tets"], b["tets"], a["tets"] / b["tets"], a["seconds"], b["seconds"],
            a["seconds"] / max(b["seconds"], 1e-9), cpu, 100 * a["volume_error"], 100 * b["volume_error"],
            a["rr_min"], b["rr_min"], "yes" if a.get("conformity") else "NO", why))


def row_case(case, fixtures_dir):
    """(row name, size label, part file, non-design file or None, size spec) of one --row-cases
    item: example:size, fx:fixture:size, or nist:N:size / occt:linkrods:size (single solids)."""
    bits = case.split(":")
    if bits[0] in ("nist", "occt"):
        name, size, nd = ("NIST " if bits[0] == "nist" else "") + bits[1], bits[2], None
        base = "NIST_MBE_PMI_%s.stp" % bits[1] if bits[0] == "nist" else bits[1] + ".step"
        part = os.path.normpath(os.path.join(DATA, "..", bits[0], base))
    else:
        folder, name, size = (fixtures_dir, bits[1], bits[2]) if bits[0] == "fx" else (DATA, bits[0], bits[1])
        part, nd = os.path.join(folder, name + ".step"), os.path.join(folder, name + "_nondesign.step")
    label = "default" if size in ("0", "x1") else (size.replace("x", "") + "x default" if size.startswith("x")
                                                   else size + " mm")
    return name, label, part, nd, size


def pipeline_run(topopt, part, nd, size, mesher, cpu, tmp, in_process=False):
    """`topopt mesh` end to end (read, classify, mesh, check, write) of one row by one mesher on
    CPU `cpu`, one thread, nice 15: the stats' figures, the CPU time (user + sys) of the command,
    its warnings; or its error (with the CPU used until then). in_process: TOPOPT_NO_ISOLATION=1,
    the readers and Gmsh in topopt's own process, without the wall-time budget of the isolated
    child (on a loaded machine the product's Gmsh stops at it)."""
    stats = os.path.join(tmp, "s.json")
    if os.path.exists(stats):
        os.remove(stats)
    cmd = ["nice", "-n", "15", "taskset", "-c", str(cpu), topopt, "mesh", "--mesher", mesher, "--part", part,
           "--out", os.path.join(tmp, "m.msh"), "--stats", stats] + (["--non-design", nd] if nd else [])
    if size > 0:
        cmd += ["--size", repr(size)]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    if in_process:
        env["TOPOPT_NO_ISOLATION"] = "1"
    with tempfile.TemporaryFile("w+") as log:
        p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, text=True, env=env)
        _, status, usage = os.wait4(p.pid, 0)
        log.seek(0)
        out = log.read()
    cpu_s = round(usage.ru_utime + usage.ru_stime, 2)
    warnings = [l[len("warning: "):] for l in out.splitlines() if l.startswith("warning: ")]
    if os.waitstatus_to_exitcode(status) != 0 or not os.path.exists(stats):
        return {"error": (out.strip().splitlines() or ["failed"])[-1][-300:], "cpu_seconds": cpu_s}
    s = json.load(open(stats))
    q, c = s["quality"], s["conformity"]
    return {"tets": s["tets"], **below_counts(os.path.join(tmp, "m.msh")), "mesh_seconds": round(s["seconds"]["mesh"], 2), "cpu_seconds": cpu_s,
            "rr_min": q["radius_ratio"]["min"], "rr_mean": q["radius_ratio"]["mean"],
            "share_below_01": q["radius_ratio"]["share_below_0.1"], "dihedral_min": q["dihedral_deg"]["min"],
            "volume_error": c["max_volume_error"], "conformal": c["ok"],
            "degenerate": c["flat_tets"] + c["inverted_tets"], "mesher": s.get("mesher", mesher),
            "native_failed": s.get("native_failed"), "warnings": warnings}


def below_counts(msh):
    """The written mesh's tets below radius ratio 0.1 and 0.2 (counts, by bench/volume's reader)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("volume_bench", os.path.join(ROOT, "bench", "volume", "run.py"))
    volume_bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(volume_bench)
    rr = volume_bench.radius_ratios(*volume_bench.read_msh_tets(msh))
    return {"below_01": int((rr < 0.1).sum()), "below_02": int((rr < 0.2).sum())}


def rows(args):
    """Issue 20's done-when rows (see the module's doc): native and Gmsh alternated per row."""
    sys.path.insert(0, HERE)
    import fixtures
    if not all(os.path.exists(os.path.join(args.fixtures, n + ".step")) for n in fixtures.NAMES):
        fixtures.write_all(args.fixtures)
    table = json.load(open(args.rows)) if os.path.exists(args.rows) else {}
    topopt = os.path.join(args.build, "topopt")
    with tempfile.TemporaryDirectory() as tmp:
        for case in args.row_cases.split(","):
            name, label, part, nd, spec = row_case(case, args.fixtures)
            key = name + " @ " + label
            if key in table and not args.again:
                continue
            size = float(spec) if not spec.startswith("x") else float(spec[1:]) * part_size(topopt, part)
            runs = {"native": [], "gmsh": []}
            for _ in range(args.repeat):
                for m in ("native", "gmsh"):
                    runs[m].append(pipeline_run(topopt, part, nd, size, m, args.cpu, tmp, args.in_process))
            best = {}
            for m, rs in runs.items():
                ok = [r for r in rs if "error" not in r]
                best[m] = min(ok, key=lambda r: r["cpu_seconds"]) if ok else rs[-1]
                best[m]["cpu_all"] = [r.get("cpu_seconds") for r in rs]
            table[key] = dict(best, size=round(size, 4), load=os.getloadavg()[0], in_process=args.in_process)
            print(key, json.dumps(table[key]), file=sys.stderr, flush=True)
            json.dump(table, open(args.rows, "w"), indent=1)


def verdicts(a, b):
    """The done-when items of one row, native `a` against Gmsh `b`: {item: True/False/None}."""
    ok = "error" not in a
    both = ok and "error" not in b
    return {"native, no fallback": ok and a["mesher"] == "native",
            "conformal": ok and bool(a["conformal"]),
            "no degenerate tet": ok and a["degenerate"] == 0,
            "radius ratio >= 0.1": ok and a["rr_min"] >= 0.1,
            "tets <= 1.5x Gmsh": (a["tets"] <= 1.5 * b["tets"]) if both else None,
            "CPU <= Gmsh": (a["cpu_seconds"] <= b["cpu_seconds"]) if both else
            (True if ok and b.get("cpu_seconds", 0) >= a["cpu_seconds"] else None)}


def rows_table(path):
    """The done-when table of a --rows JSON: the figures, then yes / NO per done-when item."""
    items = list(verdicts({"error": ""}, {"error": ""}))
    print("| part | size | tets native / Gmsh | ratio | mesh stage native / Gmsh (s) | pipeline CPU native / Gmsh (s)"
          " | ratio | radius ratio min native / Gmsh | share < 0.1 (native) | min dihedral (native) |"
          " volume error native / Gmsh | " + " | ".join(items) + " |")
    print("|---" * (11 + len(items)) + "|")
    mark = {True: "yes", False: "**NO**", None: "–"}
    for key, r in json.load(open(path)).items():
        name, label = key.split(" @ ")
        a, b = r["native"], r["gmsh"]
        v = " | ".join(mark[x] for x in verdicts(a, b).values())
        if "error" in a:
            print("| %s | %s | native: %s / Gmsh: %s | | | | | | | | | %s |" % (
                name, label, a["error"][-200:], b.get("error", "ok")[-200:], v))
            continue
        if "error" in b:  # Gmsh stopped: the native figures, and the CPU Gmsh had used by then
            print("| %s | %s | %d / – | | %.2f / – | %.2f / > %.2f (Gmsh: %s) | < %.2f | %.3f / – | %.4f %% | %.1f° |"
                  " %.3f %% / – | %s |" % (
                      name, label, a["tets"], a["mesh_seconds"], a["cpu_seconds"], b.get("cpu_seconds", 0),
                      b["error"][-120:], a["cpu_seconds"] / max(b.get("cpu_seconds", 0), 1e-9), a["rr_min"],
                      100 * a["share_below_01"], a["dihedral_min"], 100 * a["volume_error"], v))
            continue
        name += " (in process)" if r.get("in_process") else ""
        print("| %s | %s | %d / %d | %.2f | %.2f / %.2f | %.2f / %.2f | %.2f | %.3f / %.3f | %.4f %% | %.1f° |"
              " %.3f %% / %.3f %% | %s |" % (
                  name, label, a["tets"], b["tets"], a["tets"] / b["tets"], a["mesh_seconds"], b["mesh_seconds"],
                  a["cpu_seconds"], b["cpu_seconds"], a["cpu_seconds"] / max(b["cpu_seconds"], 1e-9), a["rr_min"],
                  b["rr_min"], 100 * a["share_below_01"], a["dihedral_min"], 100 * a["volume_error"],
                  100 * b["volume_error"], v))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--cases", default=DEFAULT_CASES)
    ap.add_argument("--shared", help="JSON: both meshers on every shared part, one CPU each (see above)")
    ap.add_argument("--parts", help="with --shared: only these parts (re-run)")
    ap.add_argument("--gmsh-limit", type=int, default=900, help="with --shared: seconds for python3-gmsh")
    ap.add_argument("--limit", type=int, default=None, help="with --shared: wall seconds per topopt mesh")
    ap.add_argument("--shared-table", help="print the ratio table of a --shared JSON")
    ap.add_argument("--rows", help="JSON: issue 20's done-when rows, both meshers end to end (see above)")
    ap.add_argument("--row-cases", default=ROW_CASES, help="with --rows: example:size,..., fx:fixture:size, nist:N:size")
    ap.add_argument("--fixtures", default="/tmp/twobrep_fixtures", help="with --rows: the fixtures' STEP folder")
    ap.add_argument("--cpu", type=int, default=1, help="with --rows: the CPU each run is pinned to")
    ap.add_argument("--again", action="store_true", help="with --rows: re-run rows already in the JSON")
    ap.add_argument("--in-process", action="store_true", help="with --rows: TOPOPT_NO_ISOLATION=1 (no wall budget)")
    ap.add_argument("--rows-table", help="print the done-when table of a --rows JSON")
    args = ap.parse_args()
    if args.rows:
        return rows(args)
    if args.rows_table:
        return rows_table(args.rows_table)
    if args.shared:
        return shared(args)
    if args.shared_table:
        return shared_table(args.shared_table)
    topopt = os.path.join(args.build, "topopt")
    cpu = "?"
    try:
        cpu = [l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")][0]
    except (OSError, IndexError):
        pass
    print("Machine: %s, %d cores, %s" % (cpu, os.cpu_count(), platform.platform()))
    print()
    print("| part | size (mm) | mesher | tets | mesh time (s) | native / gmsh time | radius ratio min / mean | "
          "share < 0.1 | min dihedral | largest volume error | conformity |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for case in args.cases.split(","):
        name, size = case.split(":")
        size = float(size)
        res = {m: run(topopt, name, size, m, args.repeat) for m in ("native", "gmsh")}
        for m in ("native", "gmsh"):
            r = res[m]
            label = "default" if size <= 0 else "%g" % size
            if "error" in r:
                print("| %s | %s | %s | FAILED: %s | | | | | | | |" % (name, label, m, r["error"]))
                continue
            q, c = r["quality"], r["conformity"]
            ratio = ""
            if m == "native" and "error" not in res["gmsh"]:
                ratio = "%.2f" % (r["seconds"]["mesh"] / res["gmsh"]["seconds"]["mesh"])
            print("| %s | %s | %s | %d | %.2f | %s | %.3f / %.3f | %.4f %% | %.1f° | %.3f %% | %s |" % (
                name, label, m, r["tets"], r["seconds"]["mesh"], ratio, q["radius_ratio"]["min"],
                q["radius_ratio"]["mean"], 100 * q["radius_ratio"]["share_below_0.1"], q["dihedral_deg"]["min"],
                100 * c["max_volume_error"], "ok" if c["ok"] else "DEFECTS"))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
