#!/usr/bin/python3
"""The explicit density filter against the Helmholtz (PDE) filter, on one mesh at several radii.

The cantilever example (its suggested load case) is meshed once; `topopt optimize` then runs a
fixed number of SIMP iterations on that mesh with "filter": "gaussian" and "helmholtz" at each
radius, alternating, one after the other in this script. Each row gives CPU time (user + sys of
the run), peak memory, the explicit filter's neighbours per element (from the log), the
Helmholtz filter's CG iterations, and the final compliance. The crossover in neighbours per
element is what simp::kHelmholtzAboveNeighbours is set from.

With --helmholtz-solvers the two runs per radius are instead the Helmholtz filter with CG
preconditioned by Jacobi and by our multigrid ("helmholtz_solver"), and the table gives the
filter's length in mean edges: simp::helmholtz_multigrid_above() is set from this crossover.

usage: bench/simp/filters.py [--build build] [--size 1.0] [--iterations 15] [--radii 1.5,2.5,3.5,5]
                             [--helmholtz-solvers]
Prints Markdown for BENCHMARKS.md.
"""
import argparse, json, os, re, sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from benchlib import DATA, ROOT, run  # noqa: E402


def one_run(topopt, work, msh, name, r, options, iterations):
    """optimize on the mesh file with the filter options; returns (CPU s, peak MB, compliance, log)."""
    out = os.path.join(work, "%s_%g" % (name, r))
    job = {"mesh": {"file": msh}, "material": {"E": 210000, "nu": 0.3},
           "supports": [{"type": "fixed", "faces": ["Face1"]}],
           "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["NonDesign:Face12"],
                                                      "vector": [0, 0, -1000]}]}],
           "optimization": dict({"volume_fraction": 0.3, "filter_radius": r, "max_iterations": iterations,
                                 "tol_change": 1e-9, "tol_objective": 1e-12}, **options),
           "output": {"directory": out}}
    path = out + ".json"
    json.dump(job, open(path, "w"))
    # peak memory per run: a child process of its own so that ru_maxrss is this run's
    log, cpu, _, _ = run(["/usr/bin/time", "-f", "MAXRSS %M", topopt, "optimize", path, "--verbose"])
    peak = int(re.search(r"MAXRSS (\d+)", log).group(1)) / 1024.0
    h = json.load(open(os.path.join(out, "history.json")))
    return cpu, peak, h["history"][-1]["compliance"], log


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-filters")
    ap.add_argument("--size", type=float, default=1.0)
    ap.add_argument("--iterations", type=int, default=15)
    ap.add_argument("--radii", default="1.5,2.5,3.5,5")
    ap.add_argument("--helmholtz-solvers", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    ex = os.path.join(DATA, "examples")
    msh = os.path.join(a.work, "cantilever_%g.msh" % a.size)
    topopt = os.path.join(a.build, "topopt")
    out, _, _, _ = run([topopt, "mesh", "--part", os.path.join(ex, "cantilever.step"), "--non-design",
                        os.path.join(ex, "cantilever_nondesign.step"), "--size", str(a.size), "--out", msh])
    tets = re.search(r"(\d+) tets", out)
    if a.helmholtz_solvers:
        variants = (("jacobi", {"filter": "helmholtz", "helmholtz_solver": "jacobi"}),
                    ("multigrid", {"filter": "helmholtz", "helmholtz_solver": "multigrid"}))
        title = "Helmholtz filter: Jacobi against multigrid"
        extra = "length / mean edge"
    else:
        variants = (("gaussian", {"filter": "gaussian"}), ("helmholtz", {"filter": "helmholtz"}))
        title = "Density filters"
        extra = "neighbours / element"
    (n0, o0), (n1, o1) = variants
    print("## %s (bench/simp/filters.py)\n" % title)
    print("Cantilever, mesh size %g mm (%s tets), %d SIMP iterations, OC, volume fraction 0.3; CPU = user + sys "
          "of the whole run (its own meshing excluded: the mesh is read from a file); threads: %s.\n"
          % (a.size, tets.group(1) if tets else "?", a.iterations, os.environ.get("OMP_NUM_THREADS", "all")))
    print("| radius (mm) | %s | %s CPU (s) | %s peak (MB) | %s CPU (s) | %s peak (MB) | CPU %s / %s | "
          "compliance %s / %s |" % (extra, n0, n0, n1, n1, n0, n1, n0, n1))
    print("|---|---|---|---|---|---|---|---|")
    for r in [float(x) for x in a.radii.split(",")]:
        g = one_run(topopt, a.work, msh, n0, r, o0, a.iterations)
        p = one_run(topopt, a.work, msh, n1, r, o1, a.iterations)
        m = re.search(r"\(([0-9.e+-]+) mean edges\)" if a.helmholtz_solvers else r"([0-9.]+) neighbours per element",
                      g[3])
        print("| %g | %s | %.1f | %.0f | %.1f | %.0f | %.2f | %.3f |" % (
            r, "%.2f" % float(m.group(1)) if m else "?", g[0], g[1], p[0], p[1], g[0] / p[0], g[2] / p[2]), flush=True)


if __name__ == "__main__":
    main()
