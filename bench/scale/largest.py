#!/usr/bin/python3
"""The largest cantilever one machine holds: serial `topopt mesh`, `optimize` and `solve` at growing sizes.

Issue 21 asks for the largest case that fits in the machine's memory (24 GB here): at least 10 M
tets for a solve and 5 M for optimize. For each step of the plan the cantilever example is meshed
once (`topopt mesh`, kept in --work for later runs) and then solved or optimised on that mesh file
with the job of bench/scale/run.py (Helmholtz filter r = 1.5 mm, OC, CG + our multigrid, a fixed
number of SIMP iterations), without the result's STEP and verification (their cost grows with the
result surface, not with the solver: measure them with bench/result). Every run is one process pinned to CPU 0 with one thread; each row
gives its CPU time (user + sys), wall time and peak resident memory (wait4 of that child alone),
so the mesher's peak and the solver's are told apart. A run the kernel kills for memory is
reported as such rather than stopping the script.

usage: bench/scale/largest.py [--build build] [--plan optimize:0.396,solve:0.184] [--iterations 3]
Prints Markdown for BENCHMARKS.md.
"""
import argparse, json, os, re, sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)
import benchlib  # noqa: E402
from run import job_file  # noqa: E402  (bench/scale/run.py's job: the same case as the 2-rank runs)


def measured(cmd):
    """(output, CPU s, wall s, peak MB) of cmd on one core and one thread; a failed run is told by
    what it did not write (the output says why)."""
    cmd, env = benchlib.single_core(cmd)
    return benchlib.run(cmd, env, check=False)


def mesh(topopt, work, size):
    """The cantilever's mesh file at size (mm), made once; its row figures (None when it existed)."""
    ex = os.path.join(benchlib.DATA, "examples")
    msh = os.path.join(work, "cantilever_%g.msh" % size)
    if os.path.exists(msh):
        return msh, None
    cmd = [topopt, "mesh", "--part", os.path.join(ex, "cantilever.step"), "--non-design",
           os.path.join(ex, "cantilever_nondesign.step"), "--size", str(size), "--out", msh]
    out, cpu, wall, peak = measured(cmd)
    return msh, (cpu, wall, peak, os.path.exists(msh), out[-300:])


def study(topopt, work, msh, command, size, iterations):
    """One serial run of `topopt COMMAND` on msh: (tets, CPU s, wall s, peak MB, compliance, note)."""
    name = "%s_%g" % (command, size)
    path = job_file(work, msh, name, iterations)
    stats = os.path.join(work, name + "_stats.json")
    cmd = [topopt, command, path, "--stats", stats] + (["--quiet"] if command == "optimize" else [])
    out, cpu, wall, peak = measured(cmd)
    if not os.path.exists(stats):
        return 0, cpu, wall, peak, None, "failed: " + out.strip()[-200:].replace("\n", " ")
    tets = sum(r["tets"] for r in json.load(open(stats))["per_rank"])
    if command == "optimize":
        h = json.load(open(os.path.join(work, name, "history.json")))
        return tets, cpu, wall, peak, h["history"][-1]["compliance"], "%d iterations" % len(h["history"])
    m = re.search(r"compliance ([0-9.eE+-]+)", out)
    return tets, cpu, wall, peak, float(m.group(1)) if m else None, ""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(benchlib.ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-scale")
    ap.add_argument("--plan", default="optimize:0.396,optimize:0.292,optimize:0.232,solve:0.184")
    ap.add_argument("--iterations", type=int, default=3)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    topopt = os.path.join(a.build, "topopt")
    print("Serial, one thread, pinned to CPU 0; load average at the start %.1f.\n" % os.getloadavg()[0])
    print("| command | size (mm) | tets | mesh CPU / wall (s) | mesh peak (MB) | run CPU / wall (s) "
          "| run peak (MB) | MB per million tets | compliance (N·mm) | note | load after |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for step in a.plan.split(","):
        command, size = step.split(":")
        size = float(size)
        msh, m = mesh(topopt, a.work, size)
        mesh_cols = ("%.1f / %.1f" % (m[0], m[1]), "%.0f" % m[2]) if m else ("(earlier run)", "–")
        if m and not m[3]:
            print("| %s | %g | – | %s | %s | – | – | – | – | mesh failed: %s | %.1f |" % (
                command, size, *mesh_cols, m[4].replace("\n", " "), os.getloadavg()[0]), flush=True)
            continue
        tets, cpu, wall, peak, c, note = study(topopt, a.work, msh, command, size, a.iterations)
        per_m = "%.0f" % (peak / (tets / 1e6)) if tets else "–"
        print("| %s | %g | %d | %s | %s | %.1f / %.1f | %.0f | %s | %s | %s | %.1f |" % (
            command, size, tets, *mesh_cols, cpu, wall, peak, per_m, "%.3f" % c if c else "–", note,
            os.getloadavg()[0]), flush=True)


if __name__ == "__main__":
    main()
