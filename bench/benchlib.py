"""What the bench scripts share: running a tool as a child process and measuring it.

Import it from a bench script with
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    import benchlib
"""
import os, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.environ.get("TOPOPT_SHARED_DATA", os.path.join(ROOT, "..", "shared", "data"))


def run(cmd, env=None, check=True, cwd=None):
    """Runs cmd (in cwd when given: ccx writes spooles.out and other files into its working
    folder); returns (stdout + stderr, CPU seconds (user + sys), wall seconds, peak RSS in MB),
    all of this child alone (wait4's usage of it and of what it waited for), so that a tool run
    after a larger one reports its own peak. Exits with the command's output when it fails and
    check is true."""
    with tempfile.TemporaryFile("w+") as log:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, text=True, env=env, cwd=cwd)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        log.seek(0)
        output = log.read()
    if p.returncode and check:
        sys.exit(" ".join(cmd) + "\n" + output)
    return output, usage.ru_utime + usage.ru_stime, wall, usage.ru_maxrss / 1024.0


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


def read_stl(path):
    """Triangles (n, 3, 3) of a binary or ASCII STL, as a numpy array."""
    import struct
    import numpy as np
    data = open(path, "rb").read()
    if data[:5] == b"solid" and b"facet" in data[:300]:
        v = [list(map(float, l.split()[1:4])) for l in data.decode().splitlines() if l.strip().startswith("vertex")]
        return np.array(v, dtype=float).reshape(-1, 3, 3)
    n = struct.unpack("<I", data[80:84])[0]
    a = np.frombuffer(data[84:84 + 50 * n], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    return a["v"].astype(float)


def picture(stl, png, title, elev=25, azim=-60):
    """A shaded picture of the surface in stl (equal axes), written to png, seen from elevation
    elev and azimuth azim (degrees; the defaults give the isometric view)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    tris = read_stl(stl)
    if len(tris) == 0:
        return
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1)[:, None], 1e-30)
    light = np.array([0.4, -0.5, 0.75])
    shade = 0.35 + 0.65 * np.clip(n @ (light / np.linalg.norm(light)), 0, 1)
    fig = plt.figure(figsize=(8, 6))
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(Poly3DCollection(tris, facecolors=np.outer(shade, [0.55, 0.65, 0.85]), edgecolor="none"))
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    c, r = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set_xlim(c[0] - r, c[0] + r), ax.set_ylim(c[1] - r, c[1] + r), ax.set_zlim(c[2] - r, c[2] + r)
    ax.view_init(elev=elev, azim=azim)
    ax.set_title(title, fontsize=9)
    ax.set_axis_off()
    fig.savefig(png, dpi=110, bbox_inches="tight")
    plt.close(fig)
