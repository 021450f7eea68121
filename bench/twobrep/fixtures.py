#!/usr/bin/python3
"""The partial-contact fixtures of issue 20 written as STEP pairs, so that bench/twobrep/run.py
can mesh them through `topopt mesh` like the shared examples.

The same six parts as tests/cpp/brep/partial_contact_fixtures.cpp (the C++ tests build them
from OCCT primitives in memory); here FreeCAD's Part module (OCCT underneath) builds them, with
no code of topopt. Each fixture is <name>.step (the part Ω, one solid) and
<name>_nondesign.step (the non-design solids Ω̄, a compound). Sizes in mm.

usage: /usr/bin/python3 bench/twobrep/fixtures.py [OUTDIR]   (default /tmp/twobrep_fixtures; FreeCAD's
       library is found in /usr/lib/freecad*/lib when python3 does not import it already)
"""
import math
import os
import sys

try:
    import FreeCAD  # noqa: F401
except ImportError:
    sys.path += ["/usr/lib/freecad-python3/lib", "/usr/lib/freecad/lib"]
    import FreeCAD  # noqa: F401
import Part
from FreeCAD import Vector as V

NAMES = ("bosses_one_side", "lug_cut_by_outer_face", "boss_on_cylinder_wall", "pad_spanning_two_faces",
         "pads_touching_unequal", "boss_on_bspline_wall")


def box(x0, y0, z0, x1, y1, z1):
    return Part.makeBox(x1 - x0, y1 - y0, z1 - z0, V(x0, y0, z0))


def cylinder(x, y, z, r, h, axis=V(0, 0, 1)):
    return Part.makeCylinder(r, h, V(x, y, z), axis)


def solid_of(shape):
    """The first solid of a boolean's result (each boolean here makes exactly one)."""
    if not shape.Solids:
        raise RuntimeError("fixture boolean made no solid")
    return shape.Solids[0]


def fuse(a, b, unify=True):
    s = a.fuse(b)
    return solid_of(s.removeSplitter() if unify else s)


def cut(a, b):
    return solid_of(a.cut(b))


def bosses_one_side():
    """A plate 60 x 40 x 8, two bosses (r 6, bore r 3) 6 mm out of its top, flush below."""
    part, bosses = box(0, 0, 0, 60, 40, 8), []
    for x in (15.0, 45.0):
        part = fuse(part, cylinder(x, 20, 0, 6, 14))
        bosses.append(cut(cylinder(x, 20, 0, 6, 14), cylinder(x, 20, 0, 3, 14)))
    for x in (15.0, 45.0):
        part = cut(part, cylinder(x, 20, 0, 3, 14))
    return part, bosses


def lug_cut_by_outer_face():
    """A plate 60 x 40 x 8 with a lug ring (r 10, bore r 5) centred on its edge x = 60."""
    part = cut(fuse(box(0, 0, 0, 60, 40, 8), cylinder(60, 20, 0, 10, 8)), cylinder(60, 20, 0, 5, 8))
    return part, [cut(cylinder(60, 20, 0, 10, 8), cylinder(60, 20, 0, 5, 8))]


def boss_on_cylinder_wall():
    """A cylinder r 20 h 30 with a boss r 5 along x out of its wall; Ω̄ = the boss from x = 12."""
    part = fuse(cylinder(0, 0, 0, 20, 30), cylinder(0, 0, 15, 5, 30, V(1, 0, 0)))
    return part, [cylinder(12, 0, 15, 5, 18, V(1, 0, 0))]


def pad_spanning_two_faces():
    """Two boxes fused (not unified): the top is two faces; a pad under it spans both."""
    part = fuse(box(0, 0, 0, 20, 30, 20), box(20, 0, 0, 40, 30, 20), unify=False)
    return part, [box(15, 10, 15, 25, 20, 20)]


def pads_touching_unequal():
    """A box 40 x 30 x 20, two pads on its bottom touching at x = 20 on unequal faces."""
    return box(0, 0, 0, 40, 30, 20), [box(10, 10, 0, 20, 15, 5), box(20, 5, 0, 30, 25, 8)]


def boss_on_bspline_wall():
    """A block 60 x 40 under the arch z = 10 + 4 sin(pi x / 60), all faces B-splines, with a
    boss r 5 at (30, 20) from z = 0 to 20 leaving it through the arch."""
    arch = Part.BSplineCurve()
    arch.interpolate([V(5.0 * i, 0, 10 + 4 * math.sin(math.pi * i / 12)) for i in range(13)])
    a, b = arch.StartPoint, arch.EndPoint
    wire = Part.Wire([Part.LineSegment(V(0, 0, 0), V(60, 0, 0)).toShape(), Part.LineSegment(V(60, 0, 0), b).toShape(),
                      arch.toShape(), Part.LineSegment(a, V(0, 0, 0)).toShape()])
    block = Part.Face(wire).extrude(V(0, 40, 0)).toNurbs()
    return fuse(solid_of(block), cylinder(30, 20, 0, 5, 20), unify=False), [cylinder(30, 20, 0, 5, 20)]


def write_all(outdir):
    """Writes every fixture's pair into outdir; returns {name: (part path, non-design path)}."""
    os.makedirs(outdir, exist_ok=True)
    out = {}
    for name in NAMES:
        part, nondesign = globals()[name]()
        if not part.isValid():
            raise RuntimeError("fixture %s: the part is not a valid solid" % name)
        paths = (os.path.join(outdir, name + ".step"), os.path.join(outdir, name + "_nondesign.step"))
        part.exportStep(paths[0])
        Part.makeCompound(nondesign).exportStep(paths[1])
        out[name] = paths
        print("%s: part %.3f mm3, %d faces; non-design %.3f mm3 in %d solids" % (
            name, part.Volume, len(part.Faces), sum(s.Volume for s in nondesign), len(nondesign)))
    return out


if __name__ == "__main__":
    write_all(sys.argv[1] if len(sys.argv) > 1 else "/tmp/twobrep_fixtures")
