#!/usr/bin/python3
"""Property sweep of issue 19's "no self-intersection, for every result": random small studies
on a box and a plate, each through `topopt optimize` (meshing, a few SIMP iterations, the result
extraction and the product's exact result check), with random symmetry plane, extrusion,
keep_loaded_faces, threshold (the volume's or a fixed one), smoothing and remeshing. Few
iterations leave grey regions of equal density, the case where the threshold can fall on many
nodes at once (the box study of issue 19 with the OC warm start).

A study passes when `topopt optimize` reports a closed surface with 0 self-intersections. The
shapes are made once with FreeCAD (freecadcmd) in --work. Prints one line per study and a
summary; exits 1 if any study failed.

usage: bench/result/cross_sweep.py [--topopt build/topopt] [--studies 20] [--seed 1] [--work DIR]
"""
import argparse, json, os, random, re, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# name: (dx, dy, dz) of a box at the origin (Part.makeBox: Face1 x=0, Face2 x=dx, Face3 y=0,
# Face4 y=dy, Face5 z=0, Face6 z=dz)
SHAPES = {"box": (60, 10, 10), "plate": (48, 30, 4), "block": (30, 20, 16)}

MAKE = """import Part
for name, size in %r.items():
    Part.makeBox(*size).exportStep(%r + "/" + name + ".step")
"""


def make_shapes(work):
    """The STEP files of SHAPES in work (made with freecadcmd when missing)."""
    if all(os.path.exists(os.path.join(work, n + ".step")) for n in SHAPES):
        return
    script = os.path.join(work, "make_shapes.py")
    with open(script, "w") as f:
        f.write(MAKE % (SHAPES, work))
    subprocess.run(["freecadcmd", script], check=True, capture_output=True, timeout=300)
    missing = [n for n in SHAPES if not os.path.exists(os.path.join(work, n + ".step"))]
    if missing:
        sys.exit("freecadcmd did not write " + ", ".join(missing))


def random_study(rng, work, k):
    """(job dict, description) of study k: a random shape, mesh size, controls and settings."""
    name = rng.choice(sorted(SHAPES))
    dx, dy, dz = SHAPES[name]
    size = rng.choice([2.5, 3.0, 4.0])
    opt = {"volume_fraction": rng.choice([0.3, 0.4, 0.5]), "max_iterations": rng.randint(3, 12),
           "update": "oc", "keep_loaded_faces": rng.random() < 0.7,
           "smoothing_iterations": rng.choice([0, 20]), "surface_remesh": rng.random() < 0.7}
    if rng.random() < 0.4:
        opt["threshold"] = round(rng.uniform(0.3, 0.6), 3)
    controls = {}
    plane = rng.choice(["none", "y", "z"])
    if plane == "y":
        controls["symmetry_planes"] = [{"point": [0, dy / 2, dz / 2], "normal": [0, 1, 0]}]
    elif plane == "z":
        controls["symmetry_planes"] = [{"point": [0, dy / 2, dz / 2], "normal": [0, 0, 1]}]
    extrusion = rng.choice(["none", "y", "z"]) if plane != "z" else rng.choice(["none", "y"])
    if extrusion != "none":
        controls["extrusion"] = [0, 1, 0] if extrusion == "y" else [0, 0, 1]
    if controls:
        opt["controls"] = controls
    job = {"part": os.path.join(work, name + ".step"), "mesh": {"size": size},
           "material": {"E": 210000.0, "nu": 0.3, "density": 7.85e-09},
           "supports": [{"type": "fixed", "faces": ["Face1"]}],
           "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["Face2"], "vector": [0, 0, -100]}]}],
           "optimization": opt, "output": {"step": False, "verification": False,
                                           "directory": os.path.join(work, "out%02d" % k)}}
    text = "%s %g mm, vf %g, %d its, symmetry %s, extrusion %s, keep_loaded_faces %s, threshold %s, smoothing %d, " \
           "remesh %s" % (name, size, opt["volume_fraction"], opt["max_iterations"], plane, extrusion,
                          opt["keep_loaded_faces"], opt.get("threshold", "auto"), opt["smoothing_iterations"],
                          opt["surface_remesh"])
    return job, text


def run_study(topopt, work, k, job):
    """(ok, figure text, seconds) of one `topopt optimize` of job."""
    path = os.path.join(work, "job%02d.json" % k)
    with open(path, "w") as f:
        json.dump(job, f, indent=1)
    t0 = time.time()
    p = subprocess.run([topopt, "optimize", path, "--quiet"], capture_output=True, text=True, timeout=900,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    seconds = time.time() - t0
    m = re.search(r"surface: threshold ([0-9.eE+-]+), (\d+) triangles, (closed|NOT closed), (\d+) self-intersections",
                  p.stdout)
    if p.returncode != 0 or not m:
        err = (p.stderr.strip().splitlines() or ["exit %d" % p.returncode])[-1]
        return False, "FAILED: " + err[:300], seconds
    ok = m.group(3) == "closed" and m.group(4) == "0"
    return ok, "threshold %s, %s triangles, %s, %s self-intersections" % m.groups(), seconds


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--topopt", default=os.path.join(ROOT, "build", "topopt"))
    ap.add_argument("--studies", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--work", default="/tmp/topopt-cross-sweep")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    make_shapes(a.work)
    rng = random.Random(a.seed)
    failed = 0
    for k in range(a.studies):
        job, text = random_study(rng, a.work, k)
        ok, figures, seconds = run_study(a.topopt, a.work, k, job)
        failed += not ok
        print("%2d %s | %s: %s (%.1f s)" % (k, "ok  " if ok else "FAIL", text, figures, seconds), flush=True)
    print("%d of %d studies crossing-free (load %.1f)" % (a.studies - failed, a.studies, os.getloadavg()[0]))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
