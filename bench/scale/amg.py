#!/usr/bin/python3
"""GAMG against hypre's BoomerAMG as the preconditioner of the distributed CG (issue 21 (d)).

The cantilever example (its suggested load case) is meshed once per size with `topopt mesh`; on
each mesh, in this one script, `mpirun -np 2 topopt solve --amg gamg` and `--amg boomeramg`
run one after the other (one thread per rank; the same job, relative residual 1e-10). Each row:
CG iterations (of the solve; not reported for optimize), wall time of the solve (set-up of the
multigrid included) or of SIMP, CPU time per rank,
peak memory per rank, and the compliance of both (they must agree). With --optimize N, also N
SIMP iterations of `topopt optimize` each way (the solver is set up again at every iteration).

usage: bench/scale/amg.py [--build build] [--sizes 3,2,1.5] [--optimize 5]
Prints Markdown for BENCHMARKS.md.
"""
import argparse, importlib, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
scale = importlib.import_module("run")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(scale.ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-amg")
    ap.add_argument("--sizes", default="3,2,1.5")
    ap.add_argument("--optimize", type=int, default=0, help="also this many SIMP iterations each way (0: none)")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    topopt = os.path.join(a.build, "topopt")
    ex = os.path.join(scale.DATA, "examples")
    print("## GAMG against BoomerAMG (bench/scale/amg.py)\n")
    print("Cantilever, `mpirun -np 2 topopt solve --amg ...`, one thread per rank, relative residual 1e-10; "
          "load average at the start %.1f (2 cores, shared).\n" % os.getloadavg()[0])
    print("| size (mm) | tets | command | AMG | CG iterations | wall (s) | CPU per rank (s) | peak per rank (MB) "
          "| compliance |")
    print("|---|---|---|---|---|---|---|---|---|")
    for size in [float(x) for x in a.sizes.split(",")]:
        msh = os.path.join(a.work, "cantilever_%g.msh" % size)
        if not os.path.exists(msh):
            scale.run([topopt, "mesh", "--part", os.path.join(ex, "cantilever.step"), "--non-design",
                       os.path.join(ex, "cantilever_nondesign.step"), "--size", str(size), "--out", msh])
        runs = [("solve", 1)] + ([("optimize", a.optimize)] if a.optimize else [])
        for command, iterations in runs:
            for amg in ("gamg", "boomeramg"):
                r = scale.one_run(topopt, a.work, msh, "%s_%s_%g" % (command, amg, size), iterations, 2, command,
                                  ["--amg", amg])
                print("| %g | %s | %s | %s | %s | %.2f | %s | %s | %.6g |" % (
                    size, r["tets"], command + ("" if command == "solve" else " ×%d" % iterations), amg,
                    r["cg"] if command == "solve" else "—", r["simp"],
                    " / ".join("%.2f" % x for x in r["cpus"]), " / ".join("%.0f" % x for x in r["peaks"]), r["c"]),
                      flush=True)


if __name__ == "__main__":
    main()
