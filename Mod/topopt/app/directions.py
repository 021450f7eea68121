"""Force directions: always chosen by the user, stored the way FreeCAD FEM applies and draws them.

FEM's force constraint takes its direction from a reference (its Direction: a straight edge
or a planar face); its DirectionVector — what FEM draws as arrows and what its solvers
apply — is that edge's direction or that face's normal, flipped by Reversed. Without a
reference FEM falls back on a direction nobody chose (the loaded face's normal, +X on a
bore), so TopOpt refuses such a force and says how to give one. A direction typed as a
vector (x, y, z) — in TopOpt's force panel or api.add_force — becomes a small hidden line
(Part::Line) along that vector which the force references: FEM then draws and applies
exactly that vector, in FreeCAD and in any FEM solver, and the document keeps it.
"""
import math

import FreeCAD

from . import units
from .errors import TopOptError

#: the value of the TopOptRole property that marks a direction line as TopOpt's
ROLE = "force direction"


def _fail(message, code="InvalidParameter"):
    raise TopOptError(message, code)


def unit_vector(vector, name="the direction"):
    """`vector` (3 numbers or a FreeCAD Vector) scaled to length 1; TopOptError if it is zero
    or not three finite numbers."""
    xyz = units.vector(vector, name)
    length = math.sqrt(sum(c * c for c in xyz))
    if length == 0:
        _fail("%s is zero: give a direction (x, y, z), e.g. (0, -1, 0) for -Y" % name)
    return [c / length for c in xyz]


def helper_line(force):
    """The direction line TopOpt made for `force`, or None (no reference, or the user's own)."""
    direction = getattr(force, "Direction", None)
    if not direction:
        return None
    obj = direction[0] if isinstance(direction, tuple) else direction
    return obj if getattr(obj, "TopOptRole", "") == ROLE else None


def _anchor_and_length(force):
    """Where to put a direction line (the centre of the loaded faces) and how long (a tenth of
    their size, at least 1 mm), so that it sits by the load when someone shows it."""
    boxes = []
    for obj, subs in getattr(force, "References", []):
        for sub in subs if isinstance(subs, (list, tuple)) else [subs]:
            try:
                boxes.append(obj.Shape.getElement(sub).BoundBox)
            except Exception:  # a face that no longer exists: place the line at the origin
                pass
    if not boxes:
        return FreeCAD.Vector(), 10.0
    box = boxes[0]
    for b in boxes[1:]:
        box.add(b)
    return box.Center, max(1.0, 0.1 * box.DiagonalLength)


def set_vector_direction(force, vector):
    """Gives FEM force `force` the direction `vector` (x, y, z; any length but not zero):
    creates or moves its direction line and points Direction at it, Reversed off. Returns
    the line. FEM's DirectionVector then equals the unit vector."""
    d = unit_vector(vector, "the force direction of '%s'" % force.Label)
    doc = force.Document
    line = helper_line(force)
    if line is None:
        line = doc.addObject("Part::Line", force.Name + "_Direction")
        line.addProperty("App::PropertyString", "TopOptRole", "TopOpt", "What TopOpt made this object for")
        line.TopOptRole = ROLE
        line.setEditorMode("TopOptRole", 2)
    line.Label = "%s direction" % force.Label
    anchor, length = _anchor_and_length(force)
    end = anchor + FreeCAD.Vector(*d) * length
    line.X1, line.Y1, line.Z1 = anchor.x, anchor.y, anchor.z
    line.X2, line.Y2, line.Z2 = end.x, end.y, end.z
    line.recompute()
    force.Direction = (line, ["Edge1"])
    force.Reversed = False
    if line.ViewObject is not None:
        line.ViewObject.Visibility = False
    if "TopOptDirection" in force.PropertiesList:  # older documents: now the line holds it
        force.removeProperty("TopOptDirection")
    return line


def _reference_geometry(force):
    """The edge or face `force`'s Direction refers to, or None."""
    direction = getattr(force, "Direction", None)
    if not direction:
        return None
    obj, subs = direction if isinstance(direction, tuple) else (direction, [])
    subs = [subs] if isinstance(subs, str) else list(subs)
    if not subs or getattr(obj, "Shape", None) is None:
        return None
    try:
        return obj.Shape.getElement(subs[0])
    except Exception:  # the referenced element is gone
        return None


def _usable_reference(element):
    """True for a straight edge or a planar face: the references FEM takes a direction from."""
    if element is None:
        return False
    if element.ShapeType == "Edge":
        return type(element.Curve).__name__ in ("Line", "LineSegment")
    if element.ShapeType == "Face":
        return type(element.Surface).__name__ == "Plane"
    return False


def direction_of(force):
    """The unit direction [x, y, z] in which FEM force `force` acts, as FEM draws and applies
    it (DirectionVector, from its reference and Reversed). Forces of older TopOpt documents
    that stored their direction in TopOptDirection use that. Raises TopOptError naming the
    force when it has no direction the user chose."""
    label = "'%s'" % force.Label
    if getattr(force, "Direction", None):
        if not _usable_reference(_reference_geometry(force)):
            _fail("%s takes its direction from something that is neither a straight edge nor a planar face: "
                  "open it with TopOpt's Force command and give a direction (x, y, z), or pick a straight "
                  "edge or a planar face" % label)
        return unit_vector(force.DirectionVector, "%s: DirectionVector" % label)
    if "TopOptDirection" in force.PropertiesList:
        return unit_vector(force.TopOptDirection, "%s: TopOptDirection" % label)
    _fail("%s has no direction: select it, press TopOpt's Force and give a direction (x, y, z), or pick a "
          "straight edge or a planar face for it (FEM would otherwise push along a default nobody chose)"
          % label)


def set_reference_direction(force, obj, sub, reversed_=False):
    """Gives `force` the direction of a straight edge or the normal of a planar face (`sub`
    of `obj`, e.g. "Edge3"), as FEM's own reference; removes TopOpt's direction line if it
    had one. Raises TopOptError when the element is neither."""
    element = None
    try:
        element = obj.Shape.getElement(sub)
    except Exception:
        pass
    if not _usable_reference(element):
        _fail("%s of %s is neither a straight edge nor a planar face: pick one of those, or type the "
              "direction (x, y, z)" % (sub, obj.Label))
    old = helper_line(force)
    force.Direction = (obj, [sub])
    force.Reversed = bool(reversed_)
    if old is not None:
        force.Document.removeObject(old.Name)
    if "TopOptDirection" in force.PropertiesList:
        force.removeProperty("TopOptDirection")


def migrate_scripted_forces(study):
    """Forces of older documents that kept their direction in TopOptDirection (FEM drew its
    default arrows for them) get a direction line, so that FEM draws what TopOpt applies."""
    for c in study.Constraints:
        if getattr(c, "TypeId", "") == "Fem::ConstraintForce" and "TopOptDirection" in c.PropertiesList \
                and not getattr(c, "Direction", None):
            try:
                set_vector_direction(c, c.TopOptDirection)
            except TopOptError as e:  # a zero vector: the run will say so
                FreeCAD.Console.PrintWarning("TopOpt: %s\n" % e)
