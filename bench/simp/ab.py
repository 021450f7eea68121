#!/usr/bin/python3
"""Two topopt binaries against each other on issue 21's studies, alternated A/B/A/B in one run.

Each side runs single-threaded (OMP_NUM_THREADS=1, OPENBLAS_NUM_THREADS=1) pinned to one CPU
(--cpu, default 1), one command at a time, so both see the same machine. Studies:
  cantilever_off  the cantilever job from the STEP files (1 mm), output step and verification off
  cantilever_on   the same with step and verification on (the job's defaults)
  rocker          the rocker job from the STEP files (1.15 mm, ~100 k tets), job defaults
  rocker_off      the same with step and verification off
  solve           one `topopt solve` on the rocker meshed at 1.15 mm (by side A, the same MSH for
                  both sides) and one `ccx` of the same mesh and loads, interleaved
--iterations N caps every study at N SIMP iterations and --from-mesh reads each example's mesh
from an MSH file made once by binary A (the same tets for both sides; the two binaries' surface
and volume meshers may differ): a short, like-for-like measure of the optimisation alone when the
machine is too loaded for whole studies.
Every run appends one JSON line to --out (figures: CPU = user + sys of the child, wall, peak RSS,
tets, iterations, final compliance, grey share, SIMP seconds) and a Markdown summary is printed at
the end: per study, the CPU of each run and the median ratio B / A.

usage: bench/simp/ab.py --a /work/main/build/topopt --b build/topopt [--studies ...] [--rounds 2]
"""
import argparse, json, os, re, statistics, sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402
import targets  # noqa: E402


def pinned(cmd, cpu):
    """(command, environment): cmd on CPU `cpu` with OpenMP and OpenBLAS at one thread."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    return ["nice", "-n", "5", "taskset", "-c", str(cpu)] + list(cmd), env


def study(binary, work, tag, name, mesh, extra, cpu):
    """One `topopt optimize` of example `name`; mesh: {"size": s} (from its STEP files) or
    {"file": msh}; extra: job keys (output, optimization). Returns the measured figures."""
    out_dir = os.path.join(work, tag)
    extra = dict(extra, output=dict(extra.get("output", {}), directory=out_dir))
    path = targets.write_job(work, tag, name, mesh, extra)
    stats = os.path.join(work, tag + "_stats.json")
    cmd, env = pinned([binary, "optimize", path, "--quiet", "--stats", stats], cpu)
    out, t, wall, peak = benchlib.run(["timeout", "1500"] + cmd, env, check=False)
    try:
        grey, h = targets.grey_share(out_dir)
    except (OSError, ValueError):
        return {"failed": out[-2000:], "cpu": t, "wall": wall}
    tets = re.search(r"(\d+) tets", out)
    st = json.load(open(stats))
    peak = (st["per_rank"][0] if "per_rank" in st else st).get("peak_mb", peak)  # this run's, not the children's
    return {"cpu": t, "wall": wall, "peak": peak, "tets": int(tets.group(1)) if tets else None,
            "its": len(h["history"]), "c": h["history"][-1]["compliance"], "grey": grey,
            "status": h.get("status"), "simp": h["seconds"].get("simp"), "surface": h["seconds"].get("surface")}


def shared_mesh(binary, work, name, size):
    """The MSH file of example `name` at `size`, meshed by `binary` on first use."""
    msh = os.path.join(work, "%s_%g.msh" % (name, size))
    return msh if os.path.exists(msh) else targets.mesh_file(binary, work, name, size)[0]


def solve(binary, work, job, cpu):
    """One `topopt solve` of `job`, pinned; returns CPU, wall, peak RSS and the compliance."""
    cmd, env = pinned([binary, "solve", job], cpu)
    out, t, wall, peak = benchlib.run(cmd, env)
    return {"cpu": t, "wall": wall, "peak": peak, "c": float(re.search(r"compliance ([0-9.eE+-]+)", out).group(1))}


def summary(rows):
    """Prints, per study, each run's CPU and figures and the median CPU ratio B / A."""
    for name in dict.fromkeys(r["study"] for r in rows):
        rs = [r for r in rows if r["study"] == name]
        print("\n%s:\n\n| run | side | load (1 min) | tets | iterations | compliance | grey | CPU (s) | wall (s) | "
              "peak RSS (MB) |" % name)
        print("|---|---|---|---|---|---|---|---|---|---|")
        for r in rs:
            print("| %d | %s | %.1f | %s | %s | %s | %s | %.2f | %.1f | %.0f |" % (
                r["round"], r["side"], r["load"], r.get("tets", ""), r.get("its", ""),
                "%.3f" % r["c"] if "c" in r else r.get("failed", "")[:60], "%.4f" % r["grey"] if r.get("grey") is not None
                else "", r["cpu"], r["wall"], r.get("peak", 0)))
        a = [r["cpu"] for r in rs if r["side"] == "A"]
        b = [r["cpu"] for r in rs if r["side"] == "B"]
        if a and b:
            print("\nmedian CPU A %.2f s, B %.2f s: B / A = %.3f" % (statistics.median(a), statistics.median(b),
                                                                      statistics.median(b) / statistics.median(a)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--a", required=True, help="binary A (the base)")
    ap.add_argument("--b", required=True, help="binary B (the change)")
    ap.add_argument("--work", default="/tmp/topopt-bench-ab")
    ap.add_argument("--out", default="/tmp/topopt-bench-ab/runs.jsonl")
    ap.add_argument("--cpu", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--studies", default="cantilever_off,cantilever_on,solve,rocker")
    ap.add_argument("--iterations", type=int, default=0, help="cap on SIMP iterations (0: the job's)")
    ap.add_argument("--from-mesh", action="store_true", help="studies read a mesh file made by binary A")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    rows = []

    def record(row):
        row["load"] = os.getloadavg()[0]
        rows.append(row)
        with open(a.out, "a") as f:
            f.write(json.dumps(row) + "\n")
        print(json.dumps(row), flush=True)

    off = {"step": False, "verification": False, "vtu": True}
    for name in a.studies.split(","):
        if name == "solve":
            msh, _ = targets.mesh_file(a.a, a.work, "rocker", 1.15)
            job = targets.write_job(a.work, "solve", "rocker", {"file": msh},
                                    {"output": {"directory": os.path.join(a.work, "solve"), "vtu": False}})
            inp = os.path.join(a.work, "rocker_solve.inp")
            benchlib.run([a.a, "solve", job, "--inp", inp])
        for rnd in range(1, a.rounds + 1):
            for side, binary in (("A", a.a), ("B", a.b)):
                base = {"study": name, "round": rnd, "side": side}
                if name == "solve":
                    record(dict(base, **solve(binary, a.work, job, a.cpu)))
                    cmd, env = pinned(["ccx", "-i", os.path.splitext(inp)[0]], a.cpu)
                    _, t, wall, peak = benchlib.run(cmd, env, cwd=a.work)
                    record({"study": "ccx", "round": rnd, "side": side, "cpu": t, "wall": wall, "peak": peak})
                    continue
                ex, size = ("rocker", 1.15) if name.startswith("rocker") else ("cantilever", 1.0)
                extra = {"output": off if name.endswith("_off") else {}}
                if a.iterations:
                    extra["optimization"] = {"max_iterations": a.iterations}
                mesh = {"file": shared_mesh(a.a, a.work, ex, size)} if a.from_mesh else {"size": size}
                tag = "%s_%s%d" % (name, side, rnd)
                record(dict(base, **study(binary, a.work, tag, ex, mesh, extra, a.cpu)))
    summary(rows)


if __name__ == "__main__":
    main()
