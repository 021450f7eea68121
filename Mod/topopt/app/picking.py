"""Planes, axes and directions for the geometry controls and limits, taken from what the user
picks, as FEM users do: a symmetry plane from a planar face or a datum plane, a cyclic axis
from a cylindrical (or conical) face or an edge (straight: along it; circular: its axis), a
direction from a planar face (its normal) or a straight edge. Each returns plain lists in
model axes (mm) and raises TopOptError naming what was picked and what would do instead."""
from .errors import TopOptError


def _element(obj, sub):
    """The picked sub-element (a face, edge or vertex) of `obj`, or its whole shape when `sub`
    is empty (a datum plane or line picked in the tree), in global coordinates."""
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull():
        raise TopOptError("%s has no shape: pick a face or an edge" % obj.Label, "InvalidParameter")
    if not sub:
        if len(shape.Faces) == 1:
            return shape.Faces[0], "%s" % obj.Label
        if len(shape.Edges) == 1:
            return shape.Edges[0], "%s" % obj.Label
        raise TopOptError("%s is not a datum plane or line: pick one of its faces or edges" % obj.Label,
                          "InvalidParameter")
    try:
        return shape.getElement(sub), "%s of %s" % (sub, obj.Label)
    except Exception:  # FreeCAD raises its own exception types for a name it does not know
        raise TopOptError("%s has no %s: pick again" % (obj.Label, sub), "InvalidParameter") from None


def _vec(v):
    return [float(v.x), float(v.y), float(v.z)]


def plane_of(obj, sub=""):
    """(point, normal) of a picked planar face or datum plane."""
    element, what = _element(obj, sub)
    surface = getattr(element, "Surface", None)
    if element.ShapeType != "Face" or type(surface).__name__ != "Plane":
        raise TopOptError("%s is not planar: pick a planar face or a datum plane for a symmetry plane" % what,
                          "InvalidParameter")
    u0, u1, v0, v1 = element.ParameterRange
    normal = element.normalAt((u0 + u1) / 2, (v0 + v1) / 2)
    return _vec(element.CenterOfMass), _vec(normal)


def axis_of(obj, sub=""):
    """(point, axis) of a picked cylindrical or conical face, a circular edge (its axis) or a
    straight edge (along it, a unit vector)."""
    element, what = _element(obj, sub)
    if element.ShapeType == "Face":
        surface = element.Surface
        if type(surface).__name__ in ("Cylinder", "Cone"):
            return _vec(surface.Center), _vec(surface.Axis)
    elif element.ShapeType == "Edge":
        curve = element.Curve
        kind = type(curve).__name__
        if kind in ("Circle", "ArcOfCircle"):
            return _vec(curve.Center), _vec(curve.Axis)
        if kind in ("Line", "LineSegment"):
            a, b = element.Vertexes[0].Point, element.Vertexes[-1].Point
            return _vec(a), _vec((b - a).normalize())
    raise TopOptError("%s has no axis: pick a cylindrical face, a circular edge or a straight edge" % what,
                      "InvalidParameter")


def direction_of(obj, sub=""):
    """A direction from a picked planar face (its outward normal), a datum plane (its normal)
    or a straight edge (from its first vertex to its last)."""
    element, what = _element(obj, sub)
    if element.ShapeType == "Face" and type(element.Surface).__name__ == "Plane":
        return plane_of(obj, sub)[1]
    if element.ShapeType == "Edge" and type(element.Curve).__name__ in ("Line", "LineSegment"):
        return axis_of(obj, sub)[1]
    raise TopOptError("%s gives no direction: pick a planar face (its normal) or a straight edge" % what,
                      "InvalidParameter")


def point_of(obj, sub=""):
    """A point from a picked vertex (its position), or the centre of a picked face or edge (its
    centre of mass): e.g. a parting plane's point."""
    element, what = _element(obj, sub)
    if element.ShapeType == "Vertex":
        return _vec(element.Point)
    if element.ShapeType in ("Face", "Edge"):
        return _vec(element.CenterOfMass)
    raise TopOptError("%s gives no point: pick a vertex, an edge or a face" % what, "InvalidParameter")


def part_face(part, obj, sub):
    """The job's name ("Face5") of a picked face of `part` (the study's part), for a base
    plate; any other pick is refused naming what was picked."""
    if obj != part or not sub.startswith("Face"):
        raise TopOptError("%s of %s is not a face of the part %s: pick the part's face that stands on the "
                          "base plate" % (sub or "the whole", obj.Label, part.Label), "FaceNotFound")
    return sub
