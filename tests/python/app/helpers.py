"""Shared by the FreeCADCmd tests: where the reference data is."""
import os

SHARED = os.environ.get("TOPOPT_SHARED_DATA", "")


def example(name):
    return os.path.join(SHARED, "examples", name)
