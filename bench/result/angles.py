#!/usr/bin/python3
"""Smallest triangle angles of the result surface (issue 19: none below 10°), per example and
per class (free-form, Ω's kept faces, non-design solids' faces), with the exact
self-intersection count and the surface stage's time, for one or more builds of `topopt` in
one run of this script (so that the figures compare on one machine at one load).

The examples and settings are those of tests/cpp/result/surface_examples_test.cpp: the coarse
meshes (rocker and cantilever 3 mm, bracket and mount 5 mm), 40 SIMP iterations, and two
settings: the threshold that keeps the volume fraction with 20 smoothing pairs ("default"),
and threshold 0.4 with 60 smoothing pairs ("t0.4"). Every run is `topopt optimize` on one
thread (OMP_NUM_THREADS=1), without the STEP and the verification.

usage: bench/result/angles.py BUILD_OR_BINARY [...] [--only rocker,...] [--work DIR]
Prints a Markdown table; each row also goes to stderr as it is measured.
"""
import argparse, json, os, resource, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "..", "shared", "data", "examples")

FIXED_BORES = ["Face28", "Face29", "Face30", "Face31"]
EXAMPLES = {
    "rocker": (3.0, {"supports": [{"type": "fixed", "faces": ["Face10"]}],
                     "load_cases": [{"name": "rocker", "loads": [
                         {"type": "force", "faces": ["Face9"], "vector": [0, -1000, 0]},
                         {"type": "force", "faces": ["Face11"], "vector": [600, 0, 0]}]}]}),
    "cantilever": (3.0, {"supports": [{"type": "fixed", "faces": ["Face1"]}],
                         "load_cases": [{"name": "tip", "loads": [
                             {"type": "force", "faces": ["NonDesign:Face12"], "vector": [0, 0, -1000]}]}]}),
    "bracket": (5.0, {"supports": [{"type": "fixed", "faces": ["Face10", "Face11", "Face12", "Face13"]}],
                      "load_cases": [{"name": "x", "loads": [{"type": "force", "faces": ["Face7"], "vector": [5000, 0, 0]}]},
                                     {"name": "z", "loads": [{"type": "force", "faces": ["Face7"], "vector": [0, 0, -5000]}]}]}),
    "mount": (5.0, {"supports": [{"type": "fixed", "faces": FIXED_BORES}],
                    "load_cases": [{"name": "down", "loads": [{"type": "force", "faces": ["Face8"], "vector": [0, 0, -10000]}]},
                                   {"name": "side", "loads": [{"type": "force", "faces": ["Face8"], "vector": [0, 5000, 0]}]}]}),
}
SETTINGS = {"default": {}, "t0.4": {"threshold": 0.4, "smoothing_iterations": 60}}


def binary(path):
    """The topopt executable of a build folder, or the path itself if it is the executable."""
    return path if os.path.isfile(path) else os.path.join(path, "topopt")


def optimize(exe, work, tag, name, setting):
    """Runs `topopt optimize` on one example and setting; returns (CPU s of the child, history)."""
    size, problem = EXAMPLES[name]
    out = os.path.join(work, "%s_%s_%s" % (tag, name, setting))
    job = {"part": os.path.join(DATA, name + ".step"), "nondesign": os.path.join(DATA, name + "_nondesign.step"),
           "mesh": {"size": size},
           "optimization": dict({"volume_fraction": 0.3, "max_iterations": 40}, **SETTINGS[setting]),
           "output": {"directory": out, "step": False, "verification": False}}
    job.update(problem)
    path = out + ".json"
    json.dump(job, open(path, "w"), indent=1)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([exe, "optimize", path, "--quiet"], check=True, env=dict(os.environ, OMP_NUM_THREADS="1"),
                   stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, json.load(open(os.path.join(out, "history.json")))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("builds", nargs="+", help="build folders or topopt executables, compared in this order")
    ap.add_argument("--only", default=",".join(EXAMPLES))
    ap.add_argument("--work", default="/tmp/topopt-bench-angles")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    rows = []
    for name in a.only.split(","):
        for setting in SETTINGS:
            for k, build in enumerate(a.builds):
                cpu, h = optimize(binary(build), a.work, "b%d" % k, name, setting)
                s = h.get("surface", {})
                row = (name, setting, build, s.get("triangles"), s.get("min_angle_free"), s.get("min_angle_faces"),
                       s.get("min_angle_nondesign"), s.get("self_intersections"), h["seconds"]["surface"], cpu)
                rows.append(row)
                print(json.dumps(row), file=sys.stderr, flush=True)
    print("load average at the end: %.2f %.2f %.2f\n" % os.getloadavg())
    print("| example | setting | build | triangles | smallest angle free-form (°) | Ω's faces (°) | "
          "non-design (°) | self-intersections | surface time (s) | optimize CPU (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %s | %s | %d | %.2f | %.2f | %.2f | %d | %.2f | %.1f |" % r)


if __name__ == "__main__":
    main()
