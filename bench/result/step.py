#!/usr/bin/python3
"""STEP benchmark (issue 19): the result's STEP before and after the compact export, per
example, both from the same run and the same binary in one run of this script.

For each example with a finished `topopt optimize` run (bench/result/run.py's jobs in its
--work folder: EXAMPLE_SETTING.json next to the output folder EXAMPLE_SETTING, SETTING given by
--run, default "after"), `topopt result JOB.json
--threshold T` at the run's threshold (history.json), one thread:
- facets: `--coarsen 0 --pcurves --facets`, the first export (every triangle a planar face,
  coplanar faces merged, the edges' 2D curves written);
- before: `--facets`, the compact export with the input's curved faces as facets (free-form
  region coarsened within 5 % of its median edge, no 2D curves);
- after: the defaults (as before, and the input's cylinders, cones, spheres and tori — bores,
  bosses — as faces on those surfaces).
Each STEP is read back by OCCT in FreeCAD (`Part.read`, BRepCheck through isValid): solids,
faces, validity and volume against the STL's. Sizes, faces, the export's CPU and wall seconds
(the child that builds and writes the solid) and the machine's load are printed as Markdown.

usage: bench/result/step.py [--build build] [--work /tmp/topopt-bench-result] [--run after]
                            [--only rocker,...] [--settings before,after] [--no-reread]
--no-reread skips FreeCAD's re-read (minutes per file on a loaded machine): the export's own
BRepCheck in the child is what "valid" then says.
"""
import argparse, json, os, re, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
import benchlib  # noqa: E402

SETTINGS = {"facets": ["--coarsen", "0", "--pcurves", "--facets"], "before": ["--facets"], "after": []}
CHECK = """
import json, os, Part
s = Part.read(os.environ["STEP_FILE"])
json.dump({"solids": len(s.Solids), "faces": len(s.Faces), "valid": s.isValid(), "volume": s.Volume},
          open(os.environ["STEP_REPORT"], "w"))
"""


def export(build, job, threshold, setting, path):
    """topopt result on one thread; returns the figures it printed and its wall seconds."""
    cmd = [os.path.join(build, "topopt"), "result", job, "--threshold", repr(threshold), "--step", path,
           "--quiet"] + SETTINGS[setting]
    wall, cpu, out = benchlib.run_threads(cmd, 1, check=False)
    surface = re.search(r"surface: threshold \S+, \d+ triangles, volume ([\d.e+-]+) mm\^3", out)
    m = re.search(r"step: (\d+) faces \((\d+) planar, (\d+) on the input's curved faces, (\d+) of those left as "
                  r"facets\) from (\d+) triangles, ([\d.e+-]+) MB, volume ([\d.e+-]+) "
                  r"mm\^3 \(([\d.e+-]+) s, ([\d.e+-]+) s CPU\)", out)
    if not m or not surface:  # refused: the error's last line
        return {"error": out.strip().splitlines()[-1] if out.strip() else "no output", "command_s": wall}
    faces, planar, analytic, refused, triangles, mb, volume, seconds, step_cpu = m.groups()
    return {"faces": int(faces), "planar": int(planar), "analytic": int(analytic), "refused": int(refused),
            "triangles": int(triangles), "mb": float(mb), "volume": float(volume),
            "step_s": float(seconds), "step_cpu_s": float(step_cpu), "command_cpu_s": cpu, "command_s": wall,
            "stl_volume": float(surface.group(1))}


def read_back(path):
    """What OCCT (FreeCAD's Part.read) finds in the STEP file."""
    with tempfile.TemporaryDirectory() as tmp:
        script, report = os.path.join(tmp, "check.py"), os.path.join(tmp, "report.json")
        open(script, "w").write(CHECK)
        subprocess.run(["freecadcmd", script], env=dict(os.environ, STEP_FILE=path, STEP_REPORT=report),
                       capture_output=True, text=True)
        return json.load(open(report)) if os.path.exists(report) else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(benchlib.ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-bench-result")
    ap.add_argument("--run", default="after", help="the setting of run.py whose runs to export (default: after)")
    ap.add_argument("--only", default="cantilever,rocker,bracket,mount")
    ap.add_argument("--settings", default="before,after")
    ap.add_argument("--no-reread", action="store_true")
    a = ap.parse_args()
    print("load average at the start: %.1f %.1f %.1f" % os.getloadavg())
    print("| example | STEP | size (MB) | faces (from triangles) | planar (merged and facets) / on curved input faces | curved pieces left as facets | "
          "valid, solids (re-read) | volume STEP / STL | export CPU s | export wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in a.only.split(","):
        job = os.path.join(a.work, "%s_%s.json" % (name, a.run))
        if not os.path.exists(job):
            print("| %s | no run: %s is missing (run bench/result/run.py --settings %s first) |||||||||"
                  % (name, job, a.run))
            continue
        run_dir = json.load(open(job))["output"]["directory"]
        threshold = json.load(open(os.path.join(run_dir, "history.json")))["threshold"]
        for setting in a.settings.split(","):
            path = os.path.join(run_dir, "bench_%s.step" % setting)
            r = export(a.build, job, threshold, setting, path)
            if "error" in r:
                print("| %s | %s | failed: %s |||||||| " % (name, setting, r["error"]))
                continue
            back = {} if a.no_reread else (read_back(path) or {})
            print("| %s | %s | %.2f | %d (%d) | %d / %d | %d | %s, %s | %s | %.1f | %.1f |"
                  % (name, setting, r["mb"], r["faces"], r["triangles"], r["planar"], r["analytic"], r["refused"], back.get("valid", "True (export's check)"),
                     back.get("solids", "-"),
                     "%.5f" % (back.get("volume", r["volume"]) / r["stl_volume"]), r["step_cpu_s"],
                     r["step_s"]))
            sys.stdout.flush()
    print("load average at the end: %.1f %.1f %.1f" % os.getloadavg())


if __name__ == "__main__":
    main()
