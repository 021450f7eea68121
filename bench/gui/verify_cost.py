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

from rocker import rocker_study, run_bench  # bench/gui/run.sh puts bench/gui on the path
from topopt.app import api


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


run_bench(main)
