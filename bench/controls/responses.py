#!/usr/bin/python3
"""Objectives and constraints (issue 22, part B) on the cantilever and the bracket.

For each example (suggested load cases of ../shared/data/README.md, steel) this script runs, in
one go on one mesh size, with OMP_NUM_THREADS as given (default 1):
- "compliance": the default, compliance at volume fraction 0.3 with OC (the reference);
- "mass | compliance": the lightest design whose compliance stays within 1.25 × the reference's;
- "mass | stress": the lightest design whose largest von Mises stress stays within twice the
  full part's (the crisp stress of a one-iteration run of the same job at volume 0.999);
- "compliance @ stress volume": the stiffest design of the volume "mass | stress" ended with,
  under a stress limit of 1e8 MPa that never binds, so that it runs with the same update
  settings (MMA, move 0.05, β up to 16) and its crisp design's largest stress is recorded: the
  design the stress limit must beat (a rounded re-entrant corner carries less stress);
- "frequency": the highest first eigenfrequency at volume fraction 0.3.
Each row: final volume fraction, compliance, largest relaxed and crisp stress (with a stress
limit), first eigenfrequency (first → last iteration), iterations, SIMP wall time and its ratio
to the reference's, CPU time of the whole command; a picture of each result.stl (matplotlib,
isometric) is written next to the outputs.

usage: bench/controls/responses.py [--build build] [--work /tmp/topopt-bench-responses]
                                   [--only cantilever,bracket] [--iterations 250] [--size 3]
Prints Markdown for BENCHMARKS.md.
"""
import argparse, json, os, sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import benchlib  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "..", "shared", "data", "examples")

EXAMPLES = benchlib.EXAMPLE_PROBLEMS


def run(cmd, threads):
    """Runs a command; returns (wall s, CPU s of the child)."""
    wall, cpu, _ = benchlib.run_threads(cmd, threads)
    return wall, cpu


def optimize(a, name, tag, optimization):
    """One `topopt optimize` of example `name` with the given optimisation section."""
    size, problem = EXAMPLES[name]
    size = a.size or size
    out = os.path.join(a.work, name + "_" + tag)
    job = {"part": os.path.join(DATA, name + ".step"), "nondesign": os.path.join(DATA, name + "_nondesign.step"),
           "mesh": {"size": size}, "material": {"E": 210000.0, "nu": 0.3}, "optimization": optimization,
           "output": {"directory": out}}
    job.update(problem)
    path = out + ".json"
    json.dump(job, open(path, "w"), indent=1)
    wall, cpu = run([os.path.join(a.build, "topopt"), "optimize", path, "--quiet"], a.threads)
    h = json.load(open(os.path.join(out, "history.json")))
    return h, wall, cpu, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-responses")
    ap.add_argument("--only", default="cantilever,bracket")
    ap.add_argument("--iterations", type=int, default=250)
    ap.add_argument("--size", type=float, default=0, help="mesh size (mm); 0: the example's")
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    print("## Objectives and constraints (bench/controls/responses.py)\n")
    print("Steel, MMA for every row but the reference (OC), Heaviside projection on, at most %d iterations, "
          "OMP_NUM_THREADS=%d. Volume: share of the design domain; stress: the largest relaxed element von Mises "
          "stress ρ̄^0.5 σ (MPa) of SIMP's last iteration / the largest of its crisp design (ρ̄ ≥ 0.5 solid, the "
          "rest void, analysed anew); frequency: the first eigenfrequency (Hz), first → last iteration.\n"
          % (a.iterations, a.threads))
    print("| example | run | limit | volume | compliance (N·mm) | stress relaxed / crisp (MPa) | frequency (Hz) | "
          "iterations | SIMP (s) | × reference | CPU (s) | picture |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    base = {"max_iterations": a.iterations}
    for name in a.only.split(","):
        runs = example_runs(a, name, base)
        t_ref = runs[0][2]["seconds"]["simp"]
        for tag, limit, h, wall, cpu, out in runs:
            last = h["history"][-1]
            png = out + ".png"
            benchlib.picture(os.path.join(out, "result.stl"), png, "%s: %s" % (name, tag))
            freq = "%.1f → %.1f" % (h["history"][0]["frequency"], last["frequency"]) if last.get("frequency") else "–"
            stress = ("%.1f / %.1f" % (last["stress_relaxed"], last["stress_crisp"])
                      if last.get("stress_relaxed") else "–")
            print("| %s | %s | %s | %.3f | %.4g | %s | %s | %d | %.1f | %.2f | %.1f | %s |"
                  % (name, tag, limit, last["volume"], last["compliance"], stress, freq, len(h["history"]),
                     h["seconds"]["simp"], h["seconds"]["simp"] / t_ref, cpu, png))


def example_runs(a, name, base):
    """The runs of one example: (tag, limit, history, wall s, CPU s, output directory) each."""
    ref, wall, cpu, out = optimize(a, name, "compliance", dict(base, volume_fraction=0.3))
    runs = [("compliance", "vf 0.3", ref, wall, cpu, out)]
    c_ref = ref["history"][-1]["compliance"]
    probe, _, _, _ = optimize(a, name, "probe", {"objective": "mass", "stress_limit": 1.0, "volume_fraction": 0.999,
                                                 "max_iterations": 1, "heaviside": False})
    s_full = probe["history"][0]["stress_crisp"]
    for tag, limit, opt in (
            ("mass_compliance", "c ≤ %.4g" % (1.25 * c_ref),
             dict(base, objective="mass", compliance_limit=1.25 * c_ref, volume_fraction=0.5)),
            ("mass_stress", "σ ≤ %.4g (2 × full part)" % (2 * s_full),
             dict(base, objective="mass", stress_limit=2 * s_full, volume_fraction=0.6))):
        h, wall, cpu, out = optimize(a, name, tag, opt)
        runs.append((tag, limit, h, wall, cpu, out))
    v_stress = runs[-1][2]["history"][-1]["volume"]
    for tag, limit, opt in (
            ("compliance_at_stress_volume", "vf %.3f, σ ≤ 1e8 (inactive)" % v_stress,
             dict(base, update="mma", stress_limit=1e8, volume_fraction=v_stress)),
            ("frequency", "vf 0.3", dict(base, objective="frequency", volume_fraction=0.3))):
        h, wall, cpu, out = optimize(a, name, tag, opt)
        runs.append((tag, limit, h, wall, cpu, out))
    return runs


if __name__ == "__main__":
    main()
