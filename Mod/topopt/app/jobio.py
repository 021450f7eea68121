"""Opening TopOpt job files (*.topopt.json) from FreeCAD's File > Open."""
import builtins
import json


def open(filename):  # noqa: A001 - FreeCAD calls the import hook `open`
    with builtins.open(filename) as f:
        job = json.load(f)
    import FreeCAD
    FreeCAD.Console.PrintMessage("TopOpt job %s: %s\n" % (filename, ", ".join(sorted(job))))


insert = open
