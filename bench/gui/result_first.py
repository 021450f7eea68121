"""Time to the result with Verify on, before and after "result first, verification after":
the rocker study (bench/gui/verify_cost.py's) run twice in one script through the worker as
the GUI panel runs it (runner.prepare → execute → apply): first with the verification inside
the run (the result reaches the document when the worker ends), then result first (the result
reaches the document when the worker says it is written; the verification follows in the
same worker). For each: seconds to the result in the document, seconds to the end
(verification done), the worker's CPU time; one thread (OMP_NUM_THREADS=1).

    TOPOPT_BENCH=result_first bench/gui/run.sh [iterations]
"""
import os
import sys
import time

from rocker import rocker_study, run_bench  # bench/gui/run.sh puts bench/gui on the path
from topopt.app import runner


def timed(study, first):
    """(seconds to the result in the document, seconds to the end, worker CPU seconds)."""
    prepared = runner.prepare(study)
    t0, c0 = time.monotonic(), os.times()
    shown = []

    def on_result(result):
        with runner.transaction(study.Document, "TopOpt run"):
            runner.apply(study, result)
        shown.append(time.monotonic() - t0)

    result = runner.execute(prepared, on_result=on_result if first else None)
    if first:
        with runner.transaction(study.Document, "TopOpt verification"):
            runner.apply_verification(study, result)
    else:
        with runner.transaction(study.Document, "TopOpt run"):
            runner.apply(study, result)
        shown.append(time.monotonic() - t0)
    t1, c1 = time.monotonic(), os.times()
    cpu = (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)
    return shown[0], t1 - t0, cpu, study.ComplianceAsBuilt


def main():
    iterations = int(sys.argv[-1]) if sys.argv[-1].isdigit() else 0
    os.environ["OMP_NUM_THREADS"] = "1"
    study = rocker_study(iterations)
    study.Verify, study.WriteStep = True, True
    load = os.getloadavg()
    inside = timed(study, False)
    after = timed(study, True)
    print("rocker, MaxIterations %d, 1 thread, load average at start %.1f %.1f %.1f" % ((study.MaxIterations,) + load))
    for name, (shown, end, cpu, c) in (("verification inside", inside), ("result first", after)):
        print("%-20s result shown after %.1f s, verification done after %.1f s, worker CPU %.1f s, "
              "as-built compliance %.6g N·mm" % (name, shown, end, cpu, c))
    print("time to result, result first / inside: %.2f; to the end: %.2f" % (after[0] / inside[0], after[1] / inside[1]))


run_bench(main)
