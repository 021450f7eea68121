"""What the verification (Verify, on by default) adds to a run of the rocker through the
workbench's worker process, as the GUI runs it: the same study run twice in one script, Verify
off then on (result.step written both times), each run's wall time and its worker's CPU time
(user + system of the waited-for child processes), one thread (OMP_NUM_THREADS=1).

Run in FreeCADCmd with the built workbench installed (bench/gui/run.sh does it):
    bench/gui/run.sh [iterations]
Prints one line per run and the ratio; also the verification's own seconds from its report.
"""
import json
import os
import sys
import time

import FreeCAD
import Part

from topopt.app import api

DATA = os.environ["TOPOPT_SHARED_DATA"]  # bench/gui/run.sh sets it


def rocker_study(iterations):
    """The rocker with its three rings as non-design solids, fixed at one bore and loaded at the
    other two (the workbench's own rocker test), the study's default mesh size."""
    doc = FreeCAD.newDocument("RockerCost")
    part = doc.addObject("Part::Feature", "Rocker")
    part.Shape = Part.read(os.path.join(DATA, "examples", "rocker.step"))
    keep = []
    for i, solid in enumerate(Part.read(os.path.join(DATA, "examples", "rocker_nondesign.step")).Solids):
        o = doc.addObject("Part::Feature", "Ring%d" % (i + 1))
        o.Shape = solid
        keep.append(o)
    doc.recompute()
    study = api.new_study(doc, part, keep, volume_fraction=0.3)
    if iterations:
        study.MaxIterations = iterations
    api.add_fixed(study, "Face10")
    api.add_force(study, ["Face9"], (0, -1000, 0))
    api.add_force(study, ["Face11"], (600, 0, 0))
    doc.recompute()
    return study


def timed_run(study, verify):
    study.Verify = verify
    study.WriteStep = True
    t0, c0 = time.monotonic(), os.times()
    api.run(study, verbose=False)
    t1, c1 = time.monotonic(), os.times()
    cpu = (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)
    report = json.loads(study.VerificationReport) if verify and study.VerificationReport else {}
    return t1 - t0, cpu, report


def main():
    iterations = int(sys.argv[-1]) if sys.argv[-1].isdigit() else 0
    os.environ["OMP_NUM_THREADS"] = "1"
    study = rocker_study(iterations)
    load = os.getloadavg()
    off_wall, off_cpu, _ = timed_run(study, False)
    on_wall, on_cpu, report = timed_run(study, True)
    print("rocker, MaxIterations %d, 1 thread, load average at start %.1f %.1f %.1f" % ((study.MaxIterations,) + load))
    print("Verify off: wall %.1f s, worker CPU %.1f s" % (off_wall, off_cpu))
    print("Verify on:  wall %.1f s, worker CPU %.1f s" % (on_wall, on_cpu))
    print("on / off: wall %.2f, CPU %.2f" % (on_wall / off_wall, on_cpu / off_cpu))
    print("verification report: %s" % json.dumps({k: report.get(k) for k in ("seconds", "cpu_seconds", "as_built",
                                                                             "tets") if k in report})[:600])
    print("load average at end %.1f %.1f %.1f" % os.getloadavg())
    sys.stdout.flush()


try:
    main()
finally:
    os._exit(0)
