"""Run by scripts/run-example inside FreeCAD's GUI (under Xvfb): opens the example's saved
study and writes a picture of its result shape. Environment: TOPOPT_OUT."""
import os
import sys
import traceback

import FreeCAD
import FreeCADGui

code = 1
try:
    out = os.environ["TOPOPT_OUT"]
    doc = FreeCAD.openDocument(os.path.join(out, "lever_study.FCStd"))
    FreeCADGui.activateWorkbench("TopOptWorkbench")
    for o in doc.Objects:
        if o.ViewObject is not None:
            o.ViewObject.Visibility = o.Name.endswith("_Result") or o.Name.startswith("Keep")
    view = FreeCADGui.ActiveDocument.ActiveView
    view.viewIsometric()
    view.fitAll()
    path = os.path.join(out, "lever_result.png")
    view.saveImage(path, 1200, 900, "White")
    print("picture: %s" % path)
    code = 0
except Exception:
    traceback.print_exc()
sys.stdout.flush()
os._exit(code)
