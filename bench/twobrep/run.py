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
"""
import argparse, json, os, platform, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "..", "shared", "data", "examples")
DEFAULT_CASES = "rocker:0,rocker:1.4,rocker:1,cantilever:0,cantilever:0.8,bracket:0,bracket:2"


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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--cases", default=DEFAULT_CASES)
    args = ap.parse_args()
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
