#!/usr/bin/python3
"""Mesh digests of the shared parts through the product path, to show that a restructuring
left the meshes as they were.

Every part of ../shared/data (the examples with their non-design solids, NIST 1-6 and 11,
linkrods) goes through `topopt mesh --mesher native` at its default size (and at the
factors given); the script records tets, nodes, quality and an MD5 of the written MSH file
(node coordinates and connectivity, so any change in a node or a tet shows). With --compare
it prints, per row, 'identical', or the relative change in tets and the quality figures.

usage: bench/identity/run.py [--build build] [--out digest.json] [--compare old.json]
                             [--parts rocker,NIST_1] [--factors 1.0]
"""
import argparse, hashlib, json, os, subprocess, sys, tempfile, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.normpath(os.path.join(ROOT, "..", "shared", "data"))


def parts():
    """(name, part file, non-design file or None) for every single-solid part of the data."""
    out = []
    for name in ("rocker", "cantilever", "bracket"):
        ex = os.path.join(DATA, "examples")
        out.append((name, os.path.join(ex, name + ".step"), os.path.join(ex, name + "_nondesign.step")))
    for n in (1, 2, 3, 4, 5, 6, 11):
        out.append(("NIST_%d" % n, os.path.join(DATA, "nist", "NIST_MBE_PMI_%d.stp" % n), None))
    out.append(("linkrods", os.path.join(DATA, "occt", "linkrods.step"), None))
    return out


def digest(build, name, part, nd, factor, tmp):
    """Meshes one part; returns its row (tets, nodes, md5, quality, seconds) or its error."""
    msh, stats = os.path.join(tmp, name + ".msh"), os.path.join(tmp, name + ".json")
    cmd = [os.path.join(build, "topopt"), "mesh", "--part", part, "--mesher", "native", "--out", msh, "--stats", stats]
    if nd:
        cmd += ["--non-design", nd]
    if factor != 1.0:
        info = json.loads(subprocess.run([os.path.join(build, "topopt"), "info", "--part", part, "--json"],
                                         capture_output=True, text=True, check=True).stdout)
        lo, hi = info["part"]["bbox"]["min"], info["part"]["bbox"]["max"]
        diagonal = sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5
        cmd += ["--size", repr(factor * diagonal / 50)]  # the product's default is diagonal / 50
    t = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t
    if p.returncode != 0:
        return {"error": p.stderr.strip()[-300:], "seconds": dt}
    s = json.load(open(stats))
    with open(msh, "rb") as f:
        md5 = hashlib.md5(f.read()).hexdigest()
    q = s["quality"]
    return {"tets": s["tets"], "nodes": s["nodes"], "md5": md5, "seconds": round(dt, 2),
            "radius_ratio_min": q["radius_ratio"]["min"], "radius_ratio_mean": q["radius_ratio"]["mean"],
            "dihedral_min": q["dihedral_deg"]["min"], "conformity": s["conformity"].get("ok")}


def compare(row, old):
    if "error" in row or "error" in old:
        return "error now: %s / before: %s" % (row.get("error", "-"), old.get("error", "-"))
    if row["md5"] == old["md5"]:
        return "identical"
    dt = (row["tets"] - old["tets"]) / old["tets"] * 100
    return "tets %+.2f %%, radius ratio min %s -> %s, mean %s -> %s" % (
        dt, old["radius_ratio_min"], row["radius_ratio_min"], old["radius_ratio_mean"], row["radius_ratio_mean"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default="digest.json")
    ap.add_argument("--compare")
    ap.add_argument("--parts", default="")
    ap.add_argument("--factors", default="1.0")
    a = ap.parse_args()
    wanted = [p for p in a.parts.split(",") if p]
    old = json.load(open(a.compare)) if a.compare else {}
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, part, nd in parts():
            if wanted and name not in wanted:
                continue
            for f in (float(x) for x in a.factors.split(",")):
                key = "%s@%g" % (name, f)
                rows[key] = digest(a.build, name, part, nd, f, tmp)
                line = "%-16s %s" % (key, json.dumps(rows[key]))
                if key in old:
                    line += "\n    " + compare(rows[key], old[key])
                print(line, flush=True)
    json.dump(rows, open(a.out, "w"), indent=1)


if __name__ == "__main__":
    sys.exit(main())
