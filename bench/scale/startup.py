#!/usr/bin/python3
"""Start-up cost of `topopt`: CPU time (user + system) of `topopt info` on a small part, for two
builds of the command-line tool in the same run (issue 21 (a): the serial tool must not load
PETSc and MPI).

Each binary runs `info --part PART` N times, pinned to one core (taskset -c 0), the two builds
alternating so that the machine's load falls on both alike; the CPU time of each run is read from
the child's rusage (os.wait4). Prints the median and the mean per run, the ratio, the number of
shared libraries each loads (ldd) and the load average.

usage: bench/scale/startup.py BEFORE AFTER [--runs 20] [--part examples/cantilever.step]
"""
import argparse, os, statistics, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.environ.get("TOPOPT_SHARED_DATA", os.path.join(ROOT, "..", "shared", "data"))


def cpu_of_one_run(cmd):
    """CPU seconds (user + system) of one run of cmd, and its exit code."""
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(p.pid, 0)
    return usage.ru_utime + usage.ru_stime, os.waitstatus_to_exitcode(status)


def libraries(binary):
    out = subprocess.run(["ldd", binary], capture_output=True, text=True).stdout
    return sum(1 for line in out.splitlines() if "=>" in line or line.strip().startswith("/"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--part", default=os.path.join(DATA, "examples", "cantilever.step"))
    a = ap.parse_args()
    times = {a.before: [], a.after: []}
    load = os.getloadavg()[0]
    for _ in range(a.runs):
        for binary in (a.before, a.after):
            cpu, code = cpu_of_one_run(["taskset", "-c", "0", binary, "info", "--part", a.part])
            if code:
                sys.exit("%s info --part %s failed (exit %d)" % (binary, a.part, code))
            times[binary].append(cpu)
    print("`topopt info --part %s`, %d runs each, alternating, pinned to core 0; load average %.1f at the "
          "start, %.1f at the end\n" % (os.path.basename(a.part), a.runs, load, os.getloadavg()[0]))
    print("| build | shared libraries | CPU per run, median (s) | mean (s) | min (s) |")
    print("|---|---|---|---|---|")
    for name, binary in (("before", a.before), ("after", a.after)):
        t = times[binary]
        print("| %s (%s) | %d | %.3f | %.3f | %.3f |" % (name, binary, libraries(binary), statistics.median(t),
                                                        statistics.mean(t), min(t)))
    print("\nratio before / after (median): %.2f; saved per start: %.3f s CPU" % (
        statistics.median(times[a.before]) / statistics.median(times[a.after]),
        statistics.median(times[a.before]) - statistics.median(times[a.after])))


if __name__ == "__main__":
    main()
