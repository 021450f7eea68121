#!/usr/bin/python3
"""Scaling of `topopt optimize` (and `solve`) past one process: serial against `mpirun -np 2`.

The cantilever example (its suggested load case: fixed at Face1, 1000 N down on the non-design
pad's Face12) is meshed once per size with `topopt mesh`; then, on that mesh file, in this one
script and one after the other:
  serial   `taskset -c 0 topopt optimize` (one core: the serial code's threads share it)
  2 ranks  `mpirun -np 2 topopt optimize` (PETSc, one thread per rank)
both with the Helmholtz filter (radius 1.5 mm), OC, volume fraction 0.3, a fixed number of SIMP
iterations (convergence tests off), without the result's STEP and verification (at 2.4 M tets the
STEP export alone ran for minutes in OCCT; bench/result measures it). Each row: wall time of SIMP (history.json), CPU time (user +
system) of each process, peak memory per rank (--stats: getrusage of each process) and the final compliance of
both (they must agree to about 1e-3). `--solve` adds one static solve each way on the largest mesh.

usage: bench/scale/run.py [--build build] [--sizes 0.86,0.5] [--iterations 10] [--solve] [--amg gamg]
A mesh file of an earlier run in --work is used again.
Prints Markdown for BENCHMARKS.md. As root, OpenMPI needs OMPI_ALLOW_RUN_AS_ROOT=1 and
OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1: the script sets them for its own mpirun only.
"""
import argparse, json, os, re, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.environ.get("TOPOPT_SHARED_DATA", os.path.join(ROOT, "..", "shared", "data"))
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def run(cmd, env=None):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode:
        sys.exit(" ".join(cmd) + "\n" + p.stdout[-3000:] + p.stderr[-3000:])
    return p.stdout + p.stderr, time.perf_counter() - t0


def job_file(work, msh, name, iterations):
    job = {"mesh": {"file": msh}, "material": {"E": 210000, "nu": 0.3},
           "supports": [{"type": "fixed", "faces": ["Face1"]}],
           "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["NonDesign:Face12"],
                                                      "vector": [0, 0, -1000]}]}],
           "optimization": {"volume_fraction": 0.3, "filter": "helmholtz", "filter_radius": 1.5,
                            "solver": "iterative", "max_iterations": iterations, "tol_change": 1e-9,
                            "tol_objective": 1e-12},
           # the result's STEP and verification follow the result surface, not the solver: bench/result
           "output": {"directory": os.path.join(work, name), "step": False, "verification": False}}
    path = os.path.join(work, name + ".json")
    json.dump(job, open(path, "w"))
    return path


def one_run(topopt, work, msh, name, iterations, ranks, command="optimize", extra=()):
    """One run of `topopt COMMAND` on the mesh file, serial (ranks 1, pinned to core 0) or under
    mpirun; extra: more arguments. Returns wall, SIMP (or solve) seconds, per-rank peaks and
    CPU, the final compliance, SIMP iterations and the last FE solve's CG iterations (0 serial)."""
    path = job_file(work, msh, name, iterations)
    stats = os.path.join(work, name + "_stats.json")
    cmd = [topopt, command, path, "--stats", stats] + (["--quiet"] if command == "optimize" else []) + list(extra)
    if ranks == 1:
        log, wall = run(["taskset", "-c", "0"] + cmd)
    else:
        log, wall = run(["mpirun", "--oversubscribe", "-np", str(ranks)] + cmd, env=MPI_ENV)
    s = json.load(open(stats))
    peaks = [r["peak_mb"] for r in s["per_rank"]]
    cpus = [r["cpu_seconds"] for r in s["per_rank"]]
    cg = s["per_rank"][0].get("solver_iterations", 0)
    tets = sum(r["tets"] for r in s["per_rank"])
    if command == "optimize":
        h = json.load(open(os.path.join(work, name, "history.json")))
        return {"wall": wall, "simp": h["seconds"]["simp"], "peaks": peaks, "cpus": cpus,
                "c": h["history"][-1]["compliance"], "its": len(h["history"]), "cg": cg, "tets": tets}
    m = re.search(r"compliance ([0-9.eE+-]+)", log)
    return {"wall": wall, "simp": s["per_rank"][0]["seconds_run"], "peaks": peaks, "cpus": cpus,
            "c": float(m.group(1)), "its": 0, "cg": cg, "tets": tets}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-scale")
    ap.add_argument("--sizes", default="0.86,0.5")
    ap.add_argument("--iterations", type=int, default=10)
    ap.add_argument("--solve", action="store_true")
    ap.add_argument("--amg", default="gamg", help="the multigrid of the 2-rank runs (topopt --amg)")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    topopt = os.path.join(a.build, "topopt")
    ex = os.path.join(DATA, "examples")
    load = os.getloadavg()
    print("## Past one machine: serial against 2 MPI ranks (bench/scale/run.py)\n")
    print("Cantilever, Helmholtz filter r = 1.5 mm, OC, %d SIMP iterations; serial pinned to one core "
          "(taskset), 2 ranks one thread each; load average at the start %.1f (the machine is shared).\n"
          % (a.iterations, load[0]))
    print("| size (mm) | tets | SIMP iterations serial / 2 ranks | serial SIMP wall (s) | serial CPU (s) "
          "| 2 ranks SIMP wall (s) | 2 ranks CPU per rank (s) | wall ratio serial / 2 ranks | serial peak (MB) "
          "| 2 ranks peak per rank (MB) | CG iterations, last solve (2 ranks) | compliance 2 ranks / serial "
          "| load average after |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    last = None
    for size in [float(x) for x in a.sizes.split(",")]:
        msh = os.path.join(a.work, "cantilever_%g.msh" % size)
        if not os.path.exists(msh):  # a mesh of an earlier run is used again
            run([topopt, "mesh", "--part", os.path.join(ex, "cantilever.step"), "--non-design",
                 os.path.join(ex, "cantilever_nondesign.step"), "--size", str(size), "--out", msh])
        s = one_run(topopt, a.work, msh, "serial_%g" % size, a.iterations, 1)
        p = one_run(topopt, a.work, msh, "ranks2_%g" % size, a.iterations, 2, extra=["--amg", a.amg])
        tets = s["tets"]
        print("| %g | %d | %d / %d | %.1f | %.1f | %.1f | %s | %.2f | %.0f | %s | %d | %.6f | %.1f |" % (
            size, tets, s["its"], p["its"], s["simp"], s["cpus"][0], p["simp"],
            " / ".join("%.1f" % x for x in p["cpus"]), s["simp"] / p["simp"], s["peaks"][0],
            " / ".join("%.0f" % x for x in p["peaks"]), p["cg"], p["c"] / s["c"], os.getloadavg()[0]), flush=True)
        last = (size, tets, msh)
    if a.solve and last:
        size, tets, msh = last
        s = one_run(topopt, a.work, msh, "solve1_%g" % size, 1, 1, "solve")
        p = one_run(topopt, a.work, msh, "solve2_%g" % size, 1, 2, "solve", ["--amg", a.amg])
        print("\nOne static solve, %d tets: serial %.1f s wall, %.1f s CPU (peak %.0f MB); 2 ranks %.1f s wall, CPU "
              "per rank %s s (peaks %s MB); compliance ratio %.6f." % (
                  tets, s["simp"], s["cpus"][0], s["peaks"][0], p["simp"], " / ".join("%.1f" % x for x in p["cpus"]),
                  " / ".join("%.0f" % x for x in p["peaks"]), p["c"] / s["c"]))


if __name__ == "__main__":
    main()
