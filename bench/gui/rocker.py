"""The rocker study the GUI benches run (the workbench's own rocker test's supports and loads)."""
import os

import FreeCAD
import Part

from topopt.app import api

DATA = os.environ["TOPOPT_SHARED_DATA"]  # bench/gui/run.sh sets it


def rocker_study(iterations):
    """The rocker with its three rings as non-design solids, fixed at one bore and loaded at the
    other two (the workbench's own rocker test), the study's default mesh size."""
    doc = FreeCAD.newDocument("RockerCost")
    part = doc.addObject("Part::Feature", "Rocker")
    part.Shape = Part.read(os.path.join(DATA, "examples", "rocker.step"))
    keep = []
    for i, solid in enumerate(Part.read(os.path.join(DATA, "examples", "rocker_nondesign.step")).Solids):
        o = doc.addObject("Part::Feature", "Ring%d" % (i + 1))
        o.Shape = solid
        keep.append(o)
    doc.recompute()
    study = api.new_study(doc, part, keep, volume_fraction=0.3)
    if iterations:
        study.MaxIterations = iterations
    api.add_fixed(study, "Face10")
    api.add_force(study, ["Face9"], (0, -1000, 0))
    api.add_force(study, ["Face11"], (600, 0, 0))
    doc.recompute()
    return study


def run_bench(main):
    """Runs main(), then prints the load average and ends FreeCADCmd with os._exit (its
    interpreter would otherwise stay up after the script)."""
    import sys
    try:
        main()
        print("load average at end %.1f %.1f %.1f" % os.getloadavg())
        sys.stdout.flush()
    finally:
        os._exit(0)
