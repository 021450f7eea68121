#!/usr/bin/python3
"""The explicit density filter against the Helmholtz (PDE) filter, on one mesh at several radii.

The cantilever example (its suggested load case) is meshed once; `topopt optimize` then runs a
fixed number of SIMP iterations on that mesh with "filter": "gaussian" and "helmholtz" at each
radius, alternating, one after the other in this script. Each row gives CPU time (user + sys of
the run), peak memory, the explicit filter's neighbours per element (from the log), the
Helmholtz filter's CG iterations, and the final compliance. The crossover in neighbours per
element is what simp::kHelmholtzAboveNeighbours is set from.

usage: bench/simp/filters.py [--build build] [--size 1.0] [--iterations 15] [--radii 1.5,2.5,3.5,5]
Prints Markdown for BENCHMARKS.md.
"""
import argparse, json, os, re, sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from benchlib import DATA, ROOT, run  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-filters")
    ap.add_argument("--size", type=float, default=1.0)
    ap.add_argument("--iterations", type=int, default=15)
    ap.add_argument("--radii", default="1.5,2.5,3.5,5")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    ex = os.path.join(DATA, "examples")
    msh = os.path.join(a.work, "cantilever.msh")
    topopt = os.path.join(a.build, "topopt")
    out, _, _, _ = run([topopt, "mesh", "--part", os.path.join(ex, "cantilever.step"), "--non-design",
                        os.path.join(ex, "cantilever_nondesign.step"), "--size", str(a.size), "--out", msh])
    tets = re.search(r"(\d+) tets", out)
    print("## Density filters (bench/simp/filters.py)\n")
    print("Cantilever, mesh size %g mm (%s tets), %d SIMP iterations, OC, volume fraction 0.3; CPU = user + sys "
          "of the whole run (its own meshing excluded: the mesh is read from a file); threads: %s.\n"
          % (a.size, tets.group(1) if tets else "?", a.iterations, os.environ.get("OMP_NUM_THREADS", "all")))
    print("| radius (mm) | neighbours / element | explicit CPU (s) | explicit peak (MB) | Helmholtz CPU (s) | "
          "Helmholtz peak (MB) | ratio explicit / Helmholtz | compliance explicit / Helmholtz |")
    print("|---|---|---|---|---|---|---|---|")
    for r in [float(x) for x in a.radii.split(",")]:
        row = {}
        for kind in ("gaussian", "helmholtz"):
            job = {"mesh": {"file": msh}, "material": {"E": 210000, "nu": 0.3},
                   "supports": [{"type": "fixed", "faces": ["Face1"]}],
                   "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["NonDesign:Face12"],
                                                              "vector": [0, 0, -1000]}]}],
                   "optimization": {"volume_fraction": 0.3, "filter": kind, "filter_radius": r,
                                    "max_iterations": a.iterations, "tol_change": 1e-9, "tol_objective": 1e-12},
                   "output": {"directory": os.path.join(a.work, "%s_%g" % (kind, r))}}
            path = os.path.join(a.work, "%s_%g.json" % (kind, r))
            json.dump(job, open(path, "w"))
            # peak memory per run: a child process of its own so that ru_maxrss is this run's
            log, cpu, wall, _ = run(["/usr/bin/time", "-f", "MAXRSS %M", topopt, "optimize", path, "--verbose"])
            peak = int(re.search(r"MAXRSS (\d+)", log).group(1)) / 1024.0
            h = json.load(open(os.path.join(a.work, "%s_%g" % (kind, r), "history.json")))
            m = re.search(r"([0-9.]+) neighbours per element", log)
            row[kind] = (cpu, peak, h["history"][-1]["compliance"], float(m.group(1)) if m else None)
        g, p = row["gaussian"], row["helmholtz"]
        print("| %g | %.0f | %.1f | %.0f | %.1f | %.0f | %.2f | %.3f |" % (r, g[3], g[0], g[1], p[0], p[1], g[0] / p[0],
                                                                      g[2] / p[2]))


if __name__ == "__main__":
    main()
