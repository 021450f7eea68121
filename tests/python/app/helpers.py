"""Shared by the FreeCADCmd tests: where the reference data is."""
import os

SHARED = os.environ.get("TOPOPT_SHARED_DATA", "")


def example(name):
    return os.path.join(SHARED, "examples", name)


def bundled(name):
    """A file of the project's bundled examples (examples/)."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "examples", name)
