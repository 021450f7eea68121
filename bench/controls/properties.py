#!/usr/bin/python3
"""Issue 22's done-when properties measured on the result surface the user gets (result.stl of a
bench/controls/run.py work folder), not on SIMP's densities: what tests/cpp/simp/controls_test.cpp
asserts on a structured beam, here on the examples.

- symmetry / pattern: the share of the surface's area whose image under the map (mirror about the
  plane; shift by the pitch, for the copies that have a next one) lies farther than one mesh size
  from the surface (the surface sampled every ~0.25 mm): 0 for a surface the map carries onto itself
  to the mesh size;
- draw direction: rays along the direction on a 0.5 mm grid over the part's box; the share that
  cross the surface more than twice, and the share a die could not release (going up along the
  direction: a void → solid change above the parting height — the upper die —, or solid → void below
  it — the lower die —; one-sided: the parting height is the part's lowest point, so any void under
  solid counts, the part's own bottom faces above its lowest point too: an upper bound); rays within a
  mesh size of a non-design solid that does not span the part along the direction left out (the
  given shape: the bracket's pin lug, whose bore lies across z);
- extrusion: rays along the direction; the share whose crossings are not none or the part's two
  faces across (every section equal: a line along the direction is all solid or all void);
- maximum member size: the widest ball of the crisp design (`_native.measure_members`, the product's
  crisp tets of density.vtu, reach of a mesh size).

usage: bench/controls/properties.py [--work /tmp/controls_bench] [--build build]
Prints one Markdown row per run folder it knows the control of (the labels of run.py).
"""
import argparse, json, os, sys

import numpy as np
from scipy.spatial import cKDTree

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
import benchlib  # noqa: E402


def surface_samples(tris, spacing):
    """Points on the triangles (#T x 3 x 3) about `spacing` apart, and the area each stands for."""
    pts, wts = [], []
    area = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1) / 2
    n = np.maximum(1, np.ceil(area / spacing ** 2)).astype(int)
    rng = np.random.default_rng(1)
    for k in np.unique(n):
        sel = np.flatnonzero(n == k)
        r = rng.random((len(sel), k, 2))
        flip = r.sum(axis=2) > 1
        r[flip] = 1 - r[flip]
        t = tris[sel]
        p = t[:, None, 0] + r[..., :1] * (t[:, None, 1] - t[:, None, 0]) + r[..., 1:] * (t[:, None, 2] - t[:, None, 0])
        pts.append(p.reshape(-1, 3))
        wts.append(np.repeat(area[sel] / k, k))
    return np.concatenate(pts), np.concatenate(wts)


def map_mismatch(tris, image, size, spacing=0.25):
    """Shares of the surface's area (of the points `image` maps, NaN where it does not) whose image
    lies farther than `size` and than half of it from the surface, and the farthest image (mm)."""
    p, w = surface_samples(tris, spacing)
    q = image(p)
    ok = ~np.isnan(q[:, 0])
    d, _ = cKDTree(p).query(q[ok])
    return float(w[ok][d > size].sum() / w[ok].sum()), float(w[ok][d > size / 2].sum() / w[ok].sum()), float(d.max())


def ray_crossings(tris, axis, step=0.5):
    """For rays along coordinate `axis` on a grid `step` apart (offset off the grid lines) over the
    surface's box: {(i, j): the sorted heights along the axis where ray (gu[i], gv[j]) crosses a
    triangle}, gu and gv (the grid's coordinates along the other two axes, in order)."""
    u, v = [a for a in range(3) if a != axis]
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    gu = np.arange(lo[u] + 0.5 * step * 0.913, hi[u], step)
    gv = np.arange(lo[v] + 0.5 * step * 0.877, hi[v], step)
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    # the triangles over each grid column, by their 2D box
    iu0 = np.searchsorted(gu, np.minimum(np.minimum(a[:, u], b[:, u]), c[:, u]))
    iu1 = np.searchsorted(gu, np.maximum(np.maximum(a[:, u], b[:, u]), c[:, u]))
    out = {}
    for i in range(len(gu)):
        sel = np.flatnonzero((iu0 <= i) & (iu1 > i))
        if not len(sel):
            continue
        for j, y in enumerate(gv):
            s = sel[(np.minimum(np.minimum(a[sel, v], b[sel, v]), c[sel, v]) <= y) &
                    (np.maximum(np.maximum(a[sel, v], b[sel, v]), c[sel, v]) >= y)]
            if not len(s):
                out[(i, j)] = np.empty(0)
                continue
            out[(i, j)] = _hits(a[s], b[s], c[s], u, v, axis, gu[i], y)
    return out, gu, gv


def _hits(a, b, c, u, v, axis, x, y):
    """Heights along `axis` where the line (u = x, v = y) crosses the triangles a, b, c (#S x 3)."""
    def edge(p, q):
        return (q[:, u] - p[:, u]) * (y - p[:, v]) - (q[:, v] - p[:, v]) * (x - p[:, u])
    e0, e1, e2 = edge(a, b), edge(b, c), edge(c, a)
    inside = ((e0 >= 0) & (e1 >= 0) & (e2 >= 0)) | ((e0 <= 0) & (e1 <= 0) & (e2 <= 0))
    s = e0 + e1 + e2
    inside &= s != 0
    w = np.stack([e1, e2, e0], axis=1)[inside] / s[inside, None]  # barycentric weights of a, b, c
    h = w[:, 0] * a[inside, axis] + w[:, 1] * b[inside, axis] + w[:, 2] * c[inside, axis]
    return np.sort(h)


def draw_shares(hits, lo, parting, tol, skip=lambda key: False):
    """(share of rays crossing more than twice, share not released) for rays along +axis; lo: the
    part's lowest height, parting: the parting height (lo for one-sided); rays whose grid key
    `skip` names left out."""
    many = cut = n = 0
    for key, h in hits.items():
        if skip(key):
            continue
        n += 1
        many += len(h) > 2
        for k, z in enumerate(h):  # even k: void -> solid going up; odd: solid -> void
            if abs(z - parting) <= tol or (parting == lo and abs(z - lo) <= tol):
                continue
            if (k % 2 == 0) == (z > parting):
                cut += 1
                break
    return many / max(n, 1), cut / max(n, 1)


def extrusion_share(hits, lo, hi, tol, skip=lambda key: False):
    """Share of rays whose crossings are neither none nor the part's two faces lo and hi (rays
    whose grid key `skip` names left out)."""
    bad = n = 0
    for key, h in hits.items():
        if skip(key):
            continue
        n += 1
        bad += not (len(h) == 0 or (len(h) == 2 and abs(h[0] - lo) <= tol and abs(h[1] - hi) <= tol))
    return bad / max(n, 1)


def design_and_solids(out):
    """The design domain's box (lo, hi: 3-vectors) and each non-design solid's box, of the run's
    density.vtu."""
    sys.path.insert(0, os.path.join(ROOT, "bench", "result"))
    import crisp  # noqa: E402
    points, tets, arrays = crisp.read_vtu(os.path.join(out, "density.vtu"))
    domain = arrays["domain"].astype(np.int64)
    boxes = []
    for k in np.unique(domain):
        q = points[tets[domain == k]].reshape(-1, 3)
        boxes.append((q.min(0), q.max(0)))
    return boxes[0], boxes[1:]


def off_solids(gu, gv, axis, solids, lo, hi, margin):
    """skip(key) for ray_crossings' keys: the ray passes within `margin` of a non-design solid's box
    that does not span the part along `axis` (lo, hi): its section is the solid's, not the design's."""
    u, v = [a for a in range(3) if a != axis]
    short = [(b0, b1) for b0, b1 in solids if b0[axis] > lo + 1e-6 or b1[axis] < hi - 1e-6]

    def skip(key):
        x, y = gu[key[0]], gv[key[1]]
        return any(b0[u] - margin <= x <= b1[u] + margin and b0[v] - margin <= y <= b1[v] + margin for b0, b1 in short)
    return skip


def half_width_shift(axis, lo, hi, solids, margin):
    """image(q) for map_mismatch: q moved half the part's width along `axis` (wrapped into lo…hi), NaN
    where q or its image lies within `margin` of a non-design solid's box that does not span the part
    along `axis` (its surface is the solid's, not the extruded design's)."""
    short = [(b0, b1) for b0, b1 in solids if b0[axis] > lo[axis] + 1e-6 or b1[axis] < hi[axis] - 1e-6]
    width = hi[axis] - lo[axis]

    def near_short(q):
        out = np.zeros(len(q), bool)
        for b0, b1 in short:
            out |= np.all((q >= b0 - margin) & (q <= b1 + margin), axis=1)
        return out

    def image(q):
        r = q.copy()
        r[:, axis] = lo[axis] + np.mod(q[:, axis] - lo[axis] + width / 2, width)
        r[near_short(q) | near_short(r)] = np.nan
        return r
    return image


def largest_ball(build, out, size):
    """The widest inscribed ball (mm) of the run's crisp design (the product's crisp tets)."""
    sys.path.insert(0, os.path.join(build, "workbench", "TopOpt", "topopt"))
    sys.path.insert(0, os.path.join(ROOT, "bench", "result"))
    import _native  # noqa: E402
    import crisp  # noqa: E402
    points, tets, domain, solid = crisp.run_crisp_design(out)
    return _native.measure_members(points, tets, domain, solid, size)["largest_ball"]


def _mismatch_rows(what, m):
    """The rows of one map's mismatch m = (share > a mesh size, share > half of it, farthest)."""
    return [(what + ": area whose image is > 1 mesh size off", m[0]),
            (what + ": area whose image is > ½ mesh size off", m[1]), (what + ": farthest image (mm)", m[2])]


def measure(folder, job, build):
    """The property of the run in `folder` (its job `job`): (what, figure) pairs."""
    tris = benchlib.read_stl(os.path.join(folder, "result.stl"))
    c = job["optimization"].get("controls", {})
    size = job["mesh"]["size"]
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    rows = []
    design, solids = design_and_solids(folder)
    for plane in c.get("symmetry_planes", []):
        p0, n = np.array(plane["point"], float), np.array(plane["normal"], float)
        n /= np.linalg.norm(n)
        rows += _mismatch_rows("mirror", map_mismatch(tris, lambda q: q - 2 * ((q - p0) @ n)[:, None] * n[None], size))
    for pat in c.get("patterns", []):
        d = np.array(pat["direction"], float)
        d /= np.linalg.norm(d)
        start = min(design[0] @ d, design[1] @ d)  # the design domain's start (an axis direction here)
        last = start + (pat["count"] - 1) * pat["pitch"]

        def shift(q, d=d, start=start, last=last, pitch=pat["pitch"]):
            s = q @ d
            r = q + pitch * d[None]
            r[(s < start) | (s >= last)] = np.nan
            return r
        rows += _mismatch_rows("pattern", map_mismatch(tris, shift, size))
    if "extrusion" in c:
        axis = int(np.argmax(np.abs(c["extrusion"])))
        hits, gu, gv = ray_crossings(tris, axis)
        skip = off_solids(gu, gv, axis, solids, lo[axis], hi[axis], size)
        rows.append(("rays along the extrusion (off the short non-design solids by a mesh size) not all-or-nothing",
                     extrusion_share(hits, lo[axis], hi[axis], 0.05, skip)))
        rows += _mismatch_rows("translate by half the width along the extrusion (off the short non-design solids by a "
                               "mesh size)", map_mismatch(tris, half_width_shift(axis, lo, hi, solids, size), size))
    if "draw_direction" in c:
        dd = c["draw_direction"]
        axis = int(np.argmax(np.abs(dd["direction"])))
        hits, gu, gv = ray_crossings(tris, axis)
        parting = dd["parting_point"][axis] if "parting_point" in dd else lo[axis]
        skip = off_solids(gu, gv, axis, solids, lo[axis], hi[axis], size)
        many, cut = draw_shares(hits, lo[axis], parting, 0.05, skip)
        rows.append(("rays (off the short non-design solids by a mesh size) crossing > 2 times", many))
        rows.append(("rays (off the short non-design solids by a mesh size) not released", cut))
    if "max_member_size" in c:
        rows.append(("widest ball (mm)", largest_ball(build, folder, size)))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--work", default="/tmp/controls_bench")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--free-too", action="store_true", help="measure each control's property on the free run too")
    a = ap.parse_args()
    print("| run | property | figure |\n|---|---|---|")
    jobs = sorted(f for f in os.listdir(a.work) if f.endswith(".json"))
    for name in jobs:
        folder = os.path.join(a.work, name[:-5])
        if not os.path.exists(os.path.join(folder, "result.stl")):
            continue
        job = json.load(open(os.path.join(a.work, name)))
        for what, figure in measure(folder, job, a.build):
            print("| %s | %s | %.4g |" % (name[:-5], what, figure))
        free = os.path.join(a.work, name.split("_")[0] + "_free")
        if a.free_too and job["optimization"].get("controls") and os.path.isdir(free):
            for what, figure in measure(free, job, a.build):
                print("| %s (free run, same measure) | %s | %.4g |" % (name[:-5], what, figure))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
