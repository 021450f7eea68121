#!/usr/bin/python3
"""Result benchmark (issue 19): the design `topopt optimize` hands over, per example, before
and after the crisp defaults, in one run of this script on this machine.

For each example (cantilever, rocker, bracket; suggested load cases of
../shared/data/README.md, steel, volume fraction 0.3) and each setting:
- `topopt optimize` with OMP_NUM_THREADS=2: iterations, status, SIMP wall time and the CPU
  time of the whole command (user + system; the machine is shared, so CPU time is the fairer
  comparison), grey share (design volume with 0.1 < rho < 0.9, element densities);
- `topopt solve --inp` writes the problem deck of a job's first load case on the same mesh
  (meshing is deterministic; crisp.py checks the nodes are the same): one deck per load case,
  each from a copy of the job holding that case alone;
- crisp compliance: the tets of the crisp design (non-design tets, and design tets whose
  node-density field at the centroid reaches the run's threshold, the one of result.stl),
  face-connected to a loaded node, solved by CalculiX (bench/result/crisp.py) per load case;
  the sum over the cases with their weights (the objective SIMP minimises; bracket and mount
  have two cases).

Settings: "before" is today's old default (no projection: `"heaviside": false`, which is the
old code path exactly: fixed OC move limit, same convergence test), "after" is the new
default (projection with beta continuation, adaptive OC move limits).

With --surface, only the result surface: per example, `topopt optimize` with the surface as it
was (`"surface_remesh": false, "surface_repair": false`) and as it is (defaults), both in one
run; triangles, smallest angle (free-form and Ω's faces), crossing triangle pairs right after
the smoothing and in the returned surface (exact check), volume, surface stage time.

usage: bench/result/run.py [--build build] [--work /tmp/topopt-bench-result] [--only cantilever,...]
                           [--settings before,after] [--surface [--size MM] [--max-iterations N]]
Prints Markdown for BENCHMARKS.md.
"""
import argparse, json, os, sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "..", "shared", "data", "examples")
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))
import benchlib  # noqa: E402
import crisp  # noqa: E402

EXAMPLES = {
    "cantilever": (1.5, {"supports": [{"type": "fixed", "faces": ["Face1"]}],
                         "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["NonDesign:Face12"],
                                                                   "vector": [0, 0, -1000]}]}]}),
    "rocker": (1.5, {"supports": [{"type": "fixed", "faces": ["Face10"]}],
                     "load_cases": [{"name": "rocker", "loads": [{"type": "force", "faces": ["Face9"], "vector": [0, -1000, 0]},
                                                                 {"type": "force", "faces": ["Face11"], "vector": [600, 0, 0]}]}]}),
    # bolt bores Face10-13 fixed; pin bore Face7: 5000 N along +x, and separately along -z
    "bracket": (2.5, {"supports": [{"type": "fixed", "faces": ["Face10", "Face11", "Face12", "Face13"]}],
                      "load_cases": [{"name": "x", "loads": [{"type": "force", "faces": ["Face7"], "vector": [5000, 0, 0]}]},
                                     {"name": "z", "loads": [{"type": "force", "faces": ["Face7"], "vector": [0, 0, -5000]}]}]}),
    # bolt bores Face28-31 fixed; the lug's bore Face8: 10 000 N in -z, and separately 5 000 N in +y
    "mount": (2.5, {"supports": [{"type": "fixed", "faces": ["Face28", "Face29", "Face30", "Face31"]}],
                    "load_cases": [{"name": "down", "loads": [{"type": "force", "faces": ["Face8"], "vector": [0, 0, -10000]}]},
                                   {"name": "side", "loads": [{"type": "force", "faces": ["Face8"], "vector": [0, 5000, 0]}]}]}),
}
SETTINGS = {"before": {"heaviside": False}, "after": {},
            # today's defaults with the non-design solids the design leaves apart not joined
            # (the job's "result" section; branch join7)
            "apart": {"result": {"join_non_design": False}}}
# --surface: the result surface as it was (Taubin smoothing only) and as it is now (remeshed
# before and after the smoothing, crossings repaired), on the same job with the new SIMP defaults
SURFACE_SETTINGS = {"surface before": {"surface_remesh": False, "surface_repair": False}, "surface after": {}}


THREADS = [2]  # OpenMP/OpenBLAS threads of every command (--threads; the first tables used 2)
PIN = []  # ["taskset", "-c", CPU] with --cpu


def run(cmd):
    """Runs a topopt command with THREADS threads (pinned with --cpu); returns (wall s, CPU s of
    the child, stdout)."""
    return benchlib.run_threads(PIN + cmd, THREADS[0])


def stl_shells(path):
    """Closed shells of the STL at path (triangles joined by shared corner points): (solid
    pieces, enclosed voids) = shells enclosing a positive / negative volume, and their volumes
    (mm³) in the same order, largest first."""
    import numpy as np
    tris = benchlib.read_stl(path)
    points, index = np.unique(tris.reshape(-1, 3), axis=0, return_inverse=True)
    corners = index.reshape(-1, 3)
    parent = list(range(len(points)))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a
    for a, b, c in corners:
        ra, rb, rc = find(a), find(b), find(c)
        parent[rb] = ra
        parent[find(rc)] = ra
    volume = {}
    for k, (a, b, c) in enumerate(tris):
        r = find(corners[k][0])
        volume[r] = volume.get(r, 0.0) + float(np.dot(a, np.cross(b, c))) / 6
    solids = sorted((v for v in volume.values() if v > 0), reverse=True)
    voids = sorted((v for v in volume.values() if v < 0))
    return solids, voids


def optimize(build, work, name, setting, options, size=None):
    """topopt optimize on the example with the "optimization" options (a "result" key among
    them is the job's "result" section); returns (job path, output folder, wall s, CPU s,
    history.json)."""
    size = size or EXAMPLES[name][0]
    options = dict(options)
    result = options.pop("result", None)
    out = os.path.join(work, (name + "_" + setting).replace(" ", "_"))
    job = {"part": os.path.join(DATA, name + ".step"), "nondesign": os.path.join(DATA, name + "_nondesign.step"),
           "mesh": {"size": size}, "material": {"E": 210000.0, "nu": 0.3},
           "optimization": dict({"volume_fraction": 0.3}, **options), "output": {"directory": out}}
    job.update(EXAMPLES[name][1])
    if result:
        job["result"] = result
    path = out + ".json"
    json.dump(job, open(path, "w"), indent=1)
    wall, cpu, _ = run([os.path.join(build, "topopt"), "optimize", path, "--quiet"])
    return path, out, wall, cpu, json.load(open(os.path.join(out, "history.json")))


def surface_row(h):
    """The result surface's figures from history.json."""
    s = h.get("surface", {})
    return {"triangles": s.get("triangles"), "min_angle_free": s.get("min_angle_free"),
            "min_angle_faces": s.get("min_angle_faces"), "min_angle_nondesign": s.get("min_angle_nondesign"),
            "self_intersections": s.get("self_intersections"),
            "crossings_smoothed": s.get("self_intersections_after_smoothing"), "surface_s": h["seconds"]["surface"],
            "volume": s.get("volume")}


def crisp_compliance(build, path, out, points, tets, keep, name):
    """CalculiX's compliance of the crisp design (the kept tets) summed over every load case of
    the job, each with its weight (the objective SIMP minimises): `topopt solve --inp` writes
    the deck of a job's first load case, so each case gets a copy of the job holding it alone
    (same mesh: crisp.py checks the nodes). Returns (weighted sum, [compliance per case], tets
    solved)."""
    job = json.load(open(path))
    per_case, total, solved = [], 0.0, 0
    for k, case in enumerate(job["load_cases"]):
        one_case = dict(job, load_cases=[case])
        case_job = os.path.join(out, "crisp_case%d.json" % (k + 1))
        json.dump(one_case, open(case_job, "w"), indent=1)
        deck = os.path.join(out, "problem_case%d.inp" % (k + 1))
        run([os.path.join(build, "topopt"), "solve", case_job, "--out-dir", os.path.join(out, "solve"), "--inp", deck])
        c, solved = crisp.ccx_compliance(deck, points, tets, keep, os.path.join(out, "ccx"), "%s_case%d" % (name, k + 1))
        per_case.append(c)
        total += case.get("weight", 1.0) * c
    return total, per_case, solved


def one(build, work, name, setting):
    path, out, wall, cpu, h = optimize(build, work, name, setting, SETTINGS[setting])
    points, tets, arrays = crisp.read_vtu(os.path.join(out, "density.vtu"))
    density, domain = arrays["density"], arrays["domain"]
    vol = abs(crisp.tet_volumes(points, tets))
    keep = crisp.crisp_tets(points, tets, domain, density, h["threshold"])
    c, per_case, solved = crisp_compliance(build, path, out, points, tets, keep, name)
    cad = cad_columns(out)
    solids, voids = stl_shells(os.path.join(out, "result.stl"))
    return {**cad, "stl_solids": solids, "stl_voids": voids, "warnings": h.get("design", {}).get("warnings", []),
            "bridges": h.get("design", {}).get("bridges", []), "tets": len(tets), "iterations": len(h["history"]), "status": h["status"], "simp_s": h["seconds"]["simp"],
            "wall_s": wall, "cpu_s": cpu, "grey": crisp.grey_share(density, domain, vol),
            "compliance_simp": h["history"][-1]["compliance"], "crisp": c, "crisp_cases": per_case, "crisp_tets": solved,
            "kept_tets": int(keep.sum()), **surface_row(h)}


def surface_table(build, work, names, size, max_iterations=None):
    """The surface before and after issue 19 B, per example, both in this run (OMP_NUM_THREADS=2
    for SIMP; the surface stage runs on one thread)."""
    rows = {}
    for name in names:
        for setting, options in SURFACE_SETTINGS.items():
            extra = {"max_iterations": max_iterations} if max_iterations else {}
            h = optimize(build, work, name, setting, dict(options, **extra), size)[4]
            rows[name, setting] = r = surface_row(h)
            print("%s %s: %s" % (name, setting, json.dumps(r)), file=sys.stderr, flush=True)
    print("## Result: the design surface (bench/result/run.py --surface)\n")
    print("| example | setting | triangles | smallest angle, free-form (°) | smallest angle, Ω's faces (°) | "
          "self-intersections after smoothing | self-intersections returned | volume (mm³) | surface time (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for (name, setting), r in rows.items():
        print("| %s | %s | %d | %.2f | %.2f | %d | %d | %.1f | %.2f |"
              % (name, setting, r["triangles"], r["min_angle_free"], r["min_angle_faces"], r["crossings_smoothed"],
                 r["self_intersections"], r["volume"], r["surface_s"]))
    return rows


def cad_columns(out):
    """The result back in CAD and verified, from the run's verification.json: STEP size (MB),
    faces (planar) and time, the as-built compliance (the result solid meshed by fill_volume,
    solved by our FEM), ours on the crisp design's tets, and the verification's time; None for
    a step that failed (its error is under "failed")."""
    v = json.load(open(os.path.join(out, "verification.json")))
    step, crisp_v = v.get("step", {}), v.get("crisp", {})
    return {"step_mb": step.get("bytes", 0) / 1e6 if step else None, "step_s": step.get("seconds"),
            "step_cpu_s": step.get("cpu_seconds"), "step_valid": step.get("valid"), "step_solids": step.get("solids"),
            "step_volume": step.get("volume"), "as_built_cpu_s": v.get("as_built", {}).get("cpu_seconds"),
            "unheld": v.get("unheld_volumes"),
            "step_faces": step.get("faces"), "step_planar": step.get("planar_faces"),
            "as_built": v.get("compliance_as_built"), "as_built_tets": v.get("tets"),
            "crisp_ours": crisp_v.get("compliance"),
            "verification_s": (v["as_built"]["seconds"] + crisp_v["seconds"]) if "as_built" in v else None,
            "failed": sorted(v.get("failed", {}))}


def cad_table(rows):
    """Prints the table of the result back in CAD and its verification (issue 19, part C)."""
    def f(x, fmt):
        return fmt % x if x is not None else "failed"
    print("\n## Result: back in CAD and verified (bench/result/run.py)\n")
    # as built / crisp: both from verification.json (our FEM, every load case with its weight),
    # as is CalculiX's crisp figure of the first table
    print("| example | setting | STEP (MB) | STEP valid, solids | STEP volume / STL | STEP faces (planar) | "
          "STEP time (s, CPU s) | as-built compliance (N·mm) | as-built tets | crisp, our FEM (N·mm) | "
          "as built / crisp | verification time (s, CPU s) | left out (mm³) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (name, setting), r in rows.items():
        ratio = r["as_built"] / r["crisp_ours"] if r["as_built"] is not None and r["crisp_ours"] else None
        vol = r["step_volume"] / r["volume"] if r.get("step_volume") and r.get("volume") else None
        print("| %s | %s | %s | %s | %s | %s | %s, %s | %s | %s | %s | %s | %s, %s | %s |"
              % (name, setting, f(r["step_mb"], "%.2f"),
                 "%s, %s" % (r["step_valid"], r["step_solids"]) if r["step_faces"] is not None else "failed",
                 f(vol, "%.5f"),
                 "%s (%s)" % (r["step_faces"], r["step_planar"]) if r["step_faces"] is not None else "failed",
                 f(r["step_s"], "%.1f"), f(r["step_cpu_s"], "%.1f"), f(r["as_built"], "%.2f"),
                 f(r["as_built_tets"], "%d"), f(r["crisp_ours"], "%.2f"), f(ratio, "%.3f"),
                 f(r["verification_s"], "%.1f"), f(r["as_built_cpu_s"], "%.1f"),
                 ", ".join("%.0f" % x for x in r["unheld"]) if r.get("unheld") else "–"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-result")
    ap.add_argument("--only", default=",".join(EXAMPLES))
    ap.add_argument("--settings", default=",".join(SETTINGS),
                    help="which of %s to run (default: both; 'after' alone is today's defaults)" % ", ".join(SETTINGS))
    ap.add_argument("--threads", type=int, default=2, help="OpenMP/OpenBLAS threads per command (default 2)")
    ap.add_argument("--cpu", default=None, help="pin every command to this CPU (taskset -c)")
    ap.add_argument("--surface", action="store_true", help="only the surface table (before/after issue 19 B)")
    ap.add_argument("--size", type=float, default=None, help="mesh size for --surface (default: each example's)")
    ap.add_argument("--max-iterations", type=int, default=None, help="SIMP's cap for --surface (default: the job default)")
    a = ap.parse_args()
    THREADS[0] = a.threads
    os.environ["OMP_NUM_THREADS"] = str(a.threads)  # CalculiX too (crisp.py)
    PIN[:] = ["taskset", "-c", a.cpu] if a.cpu else []
    os.makedirs(a.work, exist_ok=True)
    if a.surface:
        rows = surface_table(a.build, a.work, a.only.split(","), a.size, a.max_iterations)
        json.dump({"%s/%s" % k: v for k, v in rows.items()}, open(os.path.join(a.work, "surface_rows.json"), "w"), indent=1)
        return
    rows = {}
    for name in a.only.split(","):
        for setting in a.settings.split(","):
            rows[name, setting] = r = one(a.build, a.work, name, setting)
            print("%s %s: %s" % (name, setting, json.dumps(r)), file=sys.stderr, flush=True)
    json.dump({"%s/%s" % k: v for k, v in rows.items()}, open(os.path.join(a.work, "rows.json"), "w"), indent=1)
    print("## Result: crisp designs (bench/result/run.py)\n")
    print("| example | tets | setting | iterations | status | grey share | SIMP compliance (N·mm) | crisp compliance, "
          "CalculiX, all load cases (N·mm) | SIMP wall (s) | optimize CPU (s) | CPU after / before | triangles | "
          "smallest angle, free-form (°) | self-intersections | surface time (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (name, setting), r in rows.items():
        ratio = r["cpu_s"] / rows[name, "before"]["cpu_s"] if (name, "before") in rows else float("nan")
        cases = " (%s)" % " + ".join("%.2f" % c for c in r["crisp_cases"]) if len(r["crisp_cases"]) > 1 else ""
        print("| %s | %d | %s | %d | %s | %.1f %% | %.2f | %.2f%s | %.1f | %.1f | %.2f | %d | %.2f | %d | %.2f |"
              % (name, r["tets"], setting, r["iterations"], r["status"], 100 * r["grey"], r["compliance_simp"], r["crisp"], cases,
                 r["simp_s"], r["cpu_s"], ratio, r["triangles"], r["min_angle_free"], r["self_intersections"],
                 r["surface_s"]))
    cad_table(rows)
    summary_table(rows)


def summary_table(rows):
    """One row per run with issue 19's done-when figures side by side (BESO's cantilever: 322.45
    N·mm; the STL's shells counted by this script, independently of the product's report)."""
    print("\n## Result: the done-when figures (bench/result/run.py)\n")
    print("| example | setting | crisp, CalculiX (N·mm) | as built (N·mm) | as built / crisp (ours) | grey | "
          "smallest angle free / Ω faces / non-design (°) | self-intersections | STL solids (mm³) | STL voids | "
          "STEP MB, s, solids, valid | STEP / STL volume | optimize wall / CPU (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (name, setting), r in rows.items():
        ratio = r["as_built"] / r["crisp_ours"] if r["as_built"] is not None and r["crisp_ours"] else float("nan")
        vol = r["step_volume"] / r["volume"] if r.get("step_volume") and r.get("volume") else float("nan")
        step = ("%.2f, %.1f, %s, %s" % (r["step_mb"], r["step_s"], r["step_solids"], r["step_valid"])
                if r["step_mb"] is not None else "failed")
        print("| %s | %s | %.2f | %s | %.3f | %.1f %% | %.2f / %.2f / %.2f | %d | %d: %s | %d | %s | %.5f | %.0f / %.1f |"
              % (name, setting, r["crisp"], "%.2f" % r["as_built"] if r["as_built"] is not None else "failed", ratio,
                 100 * r["grey"], r["min_angle_free"], r["min_angle_faces"], r["min_angle_nondesign"],
                 r["self_intersections"], len(r["stl_solids"]), " + ".join("%.1f" % v for v in r["stl_solids"]),
                 len(r["stl_voids"]), step, vol, r["wall_s"], r["cpu_s"]))


if __name__ == "__main__":
    main()
