#!/usr/bin/python3
"""Pictures of the result surfaces (issue 19): `topopt optimize` on each example (the load cases
of run.py, volume fraction 0.3, the coarse mesh sizes of the SurfaceExamples test unless --size),
then result.stl from four sides: isometric, the opposite isometric from below, the top, the front.

usage: bench/result/pictures.py [--build build] [--work /tmp/topopt-pictures] [--only rocker,...]
                                [--size MM]
Writes <work>/<example>_<view>.png and prints the paths with the surface's triangle count.
"""
import argparse, os, sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))
import benchlib  # noqa: E402
import run  # noqa: E402

SIZES = {"rocker": 3.0, "cantilever": 3.0, "bracket": 5.0, "mount": 5.0}
VIEWS = {"iso": (25, -60), "below": (-30, 120), "top": (89, -90), "front": (0, -90)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(run.ROOT, "build"))
    ap.add_argument("--work", default="/tmp/topopt-pictures")
    ap.add_argument("--only", default=",".join(SIZES))
    ap.add_argument("--size", type=float, default=None)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    for name in a.only.split(","):
        _, out, wall, _, _ = run.optimize(a.build, a.work, name, "default", {}, a.size or SIZES[name])
        stl = os.path.join(out, "result.stl")
        print(f"{name}: {len(benchlib.read_stl(stl))} triangles, optimize {wall:.0f} s wall")
        for view, (elev, azim) in VIEWS.items():
            png = os.path.join(a.work, f"{name}_{view}.png")
            benchlib.picture(stl, png, f"{name} result ({view})", elev, azim)
            print("  " + png)


if __name__ == "__main__":
    main()
