"""What the bench scripts share: running a tool as a child process and measuring it.

Import it from a bench script with
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    import benchlib
"""
import os, resource, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.environ.get("TOPOPT_SHARED_DATA", os.path.join(ROOT, "..", "shared", "data"))


def run(cmd, env=None, check=True):
    """Runs cmd; returns (stdout + stderr, CPU seconds (user + sys of the child), wall seconds,
    largest child's peak RSS in MB so far). Exits with the command's output when it fails and
    check is true."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode and check:
        sys.exit(" ".join(cmd) + "\n" + p.stdout + p.stderr)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return p.stdout + p.stderr, cpu, wall, after.ru_maxrss / 1024.0


def single_core(cmd):
    """cmd pinned to CPU 0 (taskset) with OpenMP and OpenBLAS held to one thread: a
    single-core run. Returns (command, environment) for run()."""
    env = dict(os.environ)
    env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    return ["taskset", "-c", "0"] + list(cmd), env
