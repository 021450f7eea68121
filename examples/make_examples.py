"""Builds TopOpt's bundled example with FreeCAD's Part module.

Run: freecadcmd -c "exec(open('examples/make_examples.py').read())"
Writes lever.step (the part Ω) and lever_nondesign.step (the non-design solids Ω̄, a
compound in this order: 1 fixed hub, 2 load eye, 3 mounting pad).
Units are millimetres.
"""
import os

import FreeCAD
import Part
from FreeCAD import Vector

HERE = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else "examples"


def lever():
    t = 10.0
    hub, eye = Vector(0, 0, 0), Vector(110, 0, 0)
    body = Part.makeCylinder(18, t, hub).fuse(Part.makeCylinder(13, t, eye))
    web = Part.makeBox(110, 30, t, Vector(0, -15, 0))
    part = body.fuse(web).removeSplitter()
    for centre, r in ((hub, 8.0), (eye, 6.0)):
        part = part.cut(Part.makeCylinder(r, t, centre))
    part = part.removeSplitter()
    ring_hub = Part.makeCylinder(13, t, hub).cut(Part.makeCylinder(8, t, hub))
    ring_eye = Part.makeCylinder(10, t, eye).cut(Part.makeCylinder(6, t, eye))
    pad = Part.makeBox(16, 6, t, Vector(47, 9, 0))  # on the web's upper side face y = 15
    return part, [ring_hub, ring_eye, pad]


def main():
    part, nondesign = lever()
    part.exportStep(os.path.join(HERE, "lever.step"))
    Part.makeCompound(nondesign).exportStep(os.path.join(HERE, "lever_nondesign.step"))
    print("lever: %d faces, volume %.1f mm3; non-design volume %.1f mm3"
          % (len(part.Faces), part.Volume, sum(s.Volume for s in nondesign)))


main()
