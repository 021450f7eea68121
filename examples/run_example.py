"""The bundled example, run headless in FreeCADCmd by scripts/run-example.

Environment: TOPOPT_EXAMPLE_DIR (this folder), TOPOPT_OUT (where results go).
Exits with a non-zero status on any failure (FreeCADCmd itself would not).
"""
import json
import os
import sys
import traceback

import Part

from topopt.app import api


def main():
    here = os.environ["TOPOPT_EXAMPLE_DIR"]
    out = os.environ["TOPOPT_OUT"]
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(here, "lever.topopt.json")) as f:
        job = json.load(f)
    part = Part.read(os.path.join(here, job["part"]))
    nondesign = Part.read(os.path.join(here, job["nondesign"]))
    report = api.info(part, nondesign)
    path = os.path.join(out, "lever_inputs.json")
    with open(path, "w") as f:
        json.dump(report, f, indent=2)
    print("part: %d faces, volume %.1f mm3" % (report["part"]["faces"], report["part"]["volume"]))
    for s in report["nondesign"]["solids"]:
        on = ["%s on %s" % (f["name"], f["on_entity"]) for f in s["faces"] if f["on"] == "face"]
        print("non-design solid %d: volume %.1f mm3; %s" % (s["index"], s["volume"], ", ".join(on)))
    print("input report: %s" % path)


try:
    main()
    code = 0
except Exception:
    traceback.print_exc()
    code = 1
sys.stdout.flush()
os._exit(code)
