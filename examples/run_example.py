"""The bundled example, run headless in FreeCADCmd by scripts/run-example: a study on the lever
built from script (as a user's macro would), run end to end (mesh → SIMP → result surface),
saved as a FreeCAD document, exported as STL.

Environment: TOPOPT_EXAMPLE_DIR (this folder), TOPOPT_OUT (where results go).
Exits with a non-zero status on any failure (FreeCADCmd itself would not).
"""
import json
import os
import sys
import traceback

import FreeCAD
import Part

from topopt.app import api, quiet


def main():
    here = os.environ["TOPOPT_EXAMPLE_DIR"]
    out = os.environ["TOPOPT_OUT"]
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(here, "lever.topopt.json")) as f:
        job = json.load(f)
    doc = FreeCAD.newDocument("LeverExample")
    part = doc.addObject("Part::Feature", "Lever")
    part.Shape = Part.read(os.path.join(here, job["part"]))
    keep = []
    for i, solid in enumerate(Part.read(os.path.join(here, job["nondesign"])).Solids):
        o = doc.addObject("Part::Feature", "Keep%d" % (i + 1))
        o.Shape = solid
        keep.append(o)
    quiet.recompute(doc)
    opt = job["optimization"]
    study = api.new_study(doc, part, keep, volume_fraction=opt["volume_fraction"],
                          mesh_size=job["mesh"]["size"])
    study.MaxIterations = opt["max_iterations"]
    study.FilterRadius = opt["filter_radius"]
    api.add_fixed(study, job["supports"][0]["faces"])
    load = job["load_cases"][0]["loads"][0]
    api.add_force(study, load["faces"], tuple(load["vector"]))
    quiet.recompute(doc)

    result = api.run(study)  # one line per stage, then the run summary
    stl = api.export_stl(study, os.path.join(out, "lever_result.stl"))
    fcstd = api.save(doc, os.path.join(out, "lever_study.FCStd"))
    with open(os.path.join(out, "lever_history.json"), "w") as f:
        json.dump({"compliance": list(study.ComplianceHistory), "volume": list(study.VolumeHistory),
                   "status": study.Status}, f, indent=1)
    print("result shape: %d triangles, %s, volume %.0f mm³" % (
        result.Mesh.CountFacets, "closed" if result.Mesh.isSolid() else "NOT closed", result.Mesh.Volume))
    print("document: %s\nSTL: %s" % (fcstd, stl))
    if not result.Mesh.isSolid():
        raise RuntimeError("the result shape is not closed")


try:
    main()
    code = 0
except Exception:
    traceback.print_exc()
    code = 1
sys.stdout.flush()
os._exit(code)
