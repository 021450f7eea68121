"""TopOpt: topology optimisation for FreeCAD.

`topopt.app` is the headless API (FreeCADCmd or FreeCAD), `topopt.gui` the workbench's
commands and panels (imported only with the GUI). The compiled core is `topopt._native`.
"""
import os

__version__ = "0.1.0"


def package_dir():
    return os.path.dirname(os.path.abspath(__file__))


def resources_dir():
    """The workbench's Resources folder (icons, ui), beside this package when installed."""
    return os.path.join(os.path.dirname(package_dir()), "Resources")


def native():
    """The compiled core, with a message that says what to do when it is missing."""
    try:
        from . import _native
    except ImportError as e:
        raise ImportError(
            "TopOpt's compiled module is missing or does not match this FreeCAD's Python "
            "(%s). Build and install it with scripts/run-example or scripts/install-workbench." % e)
    return _native
