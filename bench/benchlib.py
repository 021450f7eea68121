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


# The shared examples' suggested load cases (../shared/data/README.md) with a bench mesh size (mm).
EXAMPLE_PROBLEMS = {
    # 60 x 20 x 10 mm, x = 0 fixed, 1000 N in -z on the load pad (y in [7, 13])
    "cantilever": (2.0, {"supports": [{"type": "fixed", "faces": ["Face1"]}],
                         "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["NonDesign:Face12"],
                                                                   "vector": [0, 0, -1000]}]}]}),
    # bolt bores Face10-13 fixed; pin bore Face7: 5000 N along +x, and separately along -z
    "bracket": (3.0, {"supports": [{"type": "fixed", "faces": ["Face10", "Face11", "Face12", "Face13"]}],
                      "load_cases": [{"name": "x", "loads": [{"type": "force", "faces": ["Face7"],
                                                              "vector": [5000, 0, 0]}]},
                                     {"name": "z", "loads": [{"type": "force", "faces": ["Face7"],
                                                              "vector": [0, 0, -5000]}]}]}),
}


def run_threads(cmd, threads, check=True):
    """run() with OpenMP and OpenBLAS held to `threads`; returns (wall s, CPU s, stdout + stderr)."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), OPENBLAS_NUM_THREADS=str(threads))
    out, cpu, wall, _ = run(cmd, env, check)
    return wall, cpu, out
