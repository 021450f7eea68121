# TopOpt workbench, application part: runs in FreeCAD and FreeCADCmd alike.
# FreeCAD puts this folder on sys.path, so the package `topopt` (the folder beside this file)
# and its compiled module `topopt._native` import directly.
import FreeCAD

FreeCAD.addImportType("TopOpt job (*.topopt.json)", "topopt.app.jobio")
