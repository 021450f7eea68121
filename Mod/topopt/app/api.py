"""Plain scripting API for FreeCADCmd and the Python console.

Shapes go to the native core as BREP strings (Shape.exportBrepToString()), so the core links
only OCCT, the same OCCT FreeCAD loads.
"""
import Part

from .. import native


class TopOptError(RuntimeError):
    """Raised for any problem the user can fix; .code names the kind of problem."""


def _brep(shape):
    if shape is None:
        return ""
    if isinstance(shape, (list, tuple)):
        shape = Part.makeCompound(list(shape)) if shape else None
        if shape is None:
            return ""
    if not isinstance(shape, Part.Shape):
        raise TopOptError("expected a Part shape, got %s" % type(shape).__name__)
    return shape.exportBrepToString()


def info(part, nondesign=None, tolerance=-1.0):
    """Check the part and the non-design solids and classify one against the other.

    part: a Part.Shape holding one solid (Ω). nondesign: a solid, a compound of solids or a
    list of solids (Ω̄, in order), or None. Returns a dict (see `topopt info --json`):
    counts, volumes, where each non-design face lies on the part, contacts.
    Raises TopOptError with a message saying what to fix.
    """
    try:
        return native().info(_brep(part), _brep(nondesign), tolerance)
    except native().TopOptError as e:
        err = TopOptError(str(e))
        err.code = getattr(e, "code", "Internal")
        raise err from None
