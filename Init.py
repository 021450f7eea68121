# TopOpt workbench, application part: runs in FreeCAD and FreeCADCmd alike.
# FreeCAD runs this file with exec() (no __file__; the workbench folder is the variable Dir)
# after putting that folder first on sys.path. The folder holds the package `topopt` when
# the workbench is installed (the staged build, the .deb); in a clone of the repository
# (Mod/TopOpt, as the Addon Manager makes it) the package sits in Mod/topopt, so that folder
# goes on sys.path too. The package finds everything else from its own __file__.
# (Names defined here are not visible inside functions under exec(): the function imports
# what it uses.)
import FreeCAD


def _put_topopt_on_path(folder):
    """Puts the folder that holds the package `topopt` (`folder` or `folder`/Mod) first on
    sys.path; without `folder`, looks for it among the sys.path entries that hold InitGui.py."""
    import os
    import sys

    import FreeCAD
    candidates = [folder] if isinstance(folder, str) else []
    candidates += [p for p in sys.path if os.path.isfile(os.path.join(p, "InitGui.py"))]
    for candidate in candidates:
        for parent in (candidate, os.path.join(candidate, "Mod")):
            if os.path.isfile(os.path.join(parent, "topopt", "__init__.py")):
                if parent not in sys.path:
                    sys.path.insert(0, parent)
                return parent
    FreeCAD.Console.PrintError("TopOpt: the package 'topopt' is neither beside Init.py nor in its Mod folder\n")
    return None


try:
    _topopt_folder = Dir  # noqa: F821 - set by FreeCAD's RunInitPy
except NameError:
    _topopt_folder = None
_put_topopt_on_path(_topopt_folder)
FreeCAD.addImportType("TopOpt job (*.topopt.json)", "topopt.app.jobio")
