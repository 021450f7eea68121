#!/usr/bin/python3
"""The direct solver against multigrid CG inside SIMP, at several mesh sizes: where they cross.

The cantilever example (its suggested load case) is meshed at each size; `topopt optimize`
then runs the same fixed number of SIMP iterations on that mesh with "solver": "direct" and
"iterative", one after the other in this script, single-core (pinned to CPU 0, OpenMP and
OpenBLAS at one thread). Each row gives the free unknowns, CPU time (user + sys) of each run
and their ratio, and the final compliances' agreement. fem::kDirectDofLimit, the "auto"
choice, is set from the crossover this finds.

usage: bench/simp/solvers.py [--build build] [--sizes 3,2,1.5,1.2,1] [--iterations 30]
Prints Markdown for BENCHMARKS.md.
"""
import argparse, json, os, re, sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import benchlib  # noqa: E402


def job_for(msh, solver, iterations, out):
    """The cantilever's suggested load case on the mesh file msh, with a fixed iteration count."""
    return {"mesh": {"file": msh}, "material": {"E": 210000, "nu": 0.3},
            "supports": [{"type": "fixed", "faces": ["Face1"]}],
            "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["NonDesign:Face12"],
                                                       "vector": [0, 0, -1000]}]}],
            "optimization": {"volume_fraction": 0.3, "solver": solver, "max_iterations": iterations,
                             "tol_change": 1e-9, "tol_objective": 1e-12},
            "output": {"directory": out}}


def one_size(topopt, work, size, iterations):
    """Meshes the cantilever at `size` and runs both solvers; returns the table row's values."""
    ex = os.path.join(benchlib.DATA, "examples")
    msh = os.path.join(work, "cantilever_%g.msh" % size)
    out, _, _, _ = benchlib.run([topopt, "mesh", "--part", os.path.join(ex, "cantilever.step"), "--non-design",
                                 os.path.join(ex, "cantilever_nondesign.step"), "--size", str(size), "--out", msh])
    tets = int(re.search(r"(\d+) tets", out).group(1))
    row = {}
    for solver in ("direct", "iterative"):
        d = os.path.join(work, "%s_%g" % (solver, size))
        path = d + ".json"
        json.dump(job_for(msh, solver, iterations, d), open(path, "w"))
        cmd, env = benchlib.single_core([topopt, "optimize", path, "--verbose"])
        log, cpu, _, _ = benchlib.run(cmd, env)
        h = json.load(open(os.path.join(d, "history.json")))
        dofs = re.search(r"(\d+) unknowns", log)
        row[solver] = (cpu, h["history"][-1]["compliance"], int(dofs.group(1)) if dofs else None)
    return tets, row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(benchlib.ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-solvers")
    ap.add_argument("--sizes", default="3,2,1.5,1.2,1")
    ap.add_argument("--iterations", type=int, default=30)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    topopt = os.path.join(a.build, "topopt")
    print("## Solver crossover in SIMP (bench/simp/solvers.py)\n")
    print("Cantilever, %d SIMP iterations (fixed), OC, volume fraction 0.3, default tolerance; single-core: "
          "pinned to CPU 0, OpenMP and OpenBLAS at 1 thread; CPU = user + sys of the whole run (the mesh "
          "is read from a file).\n" % a.iterations)
    print("| mesh size (mm) | tets | unknowns | direct CPU (s) | multigrid CPU (s) | direct / multigrid | "
          "compliance direct / multigrid |")
    print("|---|---|---|---|---|---|---|")
    for size in [float(x) for x in a.sizes.split(",")]:
        tets, row = one_size(topopt, a.work, size, a.iterations)
        d, m = row["direct"], row["iterative"]
        print("| %g | %d | %s | %.1f | %.1f | %.2f | %.6f |" % (size, tets, d[2] or m[2] or "?", d[0], m[0],
                                                               d[0] / m[0], d[1] / m[1]), flush=True)


if __name__ == "__main__":
    main()
