"""Values with units, read the same way whatever FreeCAD stores them as.

FreeCAD 0.20 keeps FEM's force in a plain float (N), its pressure in a float (MPa), its
displacement in floats (mm) and self weight as multiples of g; FreeCAD 1.x keeps them as
quantities (App::PropertyForce, PropertyPressure, …; self weight as an acceleration and a
direction). The study's own material values are quantities (App::PropertyPressure, and
App::PropertyDensity where FreeCAD has it, else a quantity written as text). Everything here
turns such a value into a float in the unit the core works in (mm, N, MPa, t/mm³, mm/s²)
and says which property is wrong when it cannot.
"""
import math

import FreeCAD

from .errors import TopOptError

#: standard gravity in mm/s² (FreeCAD 0.20's self weight is given in multiples of it)
STANDARD_GRAVITY = 9806.65


def _fail(message):
    raise TopOptError(message, "InvalidParameter")


def _unit_of(text):
    return FreeCAD.Units.Quantity(text).Unit


def value_in(value, unit, name, plain_unit=None):
    """`value` (a float, a FreeCAD Quantity, or a quantity written as text like
    "7850 kg/m^3") as a finite float in `unit` (a unit FreeCAD parses: "N", "MPa", "mm",
    "t/mm^3", "mm/s^2"). A plain number is taken as given in `plain_unit` (default: `unit`),
    the unit FreeCAD 0.20 uses for that property. `name` names the property in the message
    of the TopOptError raised for a wrong unit or a value that is not a finite number."""
    if isinstance(value, str):
        try:
            value = FreeCAD.Units.Quantity(value)
        except Exception:
            _fail("%s is '%s', which is not a value FreeCAD understands: write a number with its unit, "
                  "like '%s'" % (name, value, _example(unit)))
    if isinstance(value, FreeCAD.Units.Quantity):
        if value.Unit != _unit_of(unit) and value.Unit != FreeCAD.Units.Unit():
            _fail("%s is %s, which is not in a unit of the same kind as %s: write it like '%s'"
                  % (name, value.UserString, unit, _example(unit)))
        x = value.getValueAs(unit) if value.Unit != FreeCAD.Units.Unit() else value.Value
        x = float(x)
    else:
        try:
            x = float(value)
        except (TypeError, ValueError):
            _fail("%s must be a number with its unit (%s), not %r" % (name, unit, value))
        if plain_unit and plain_unit != unit:
            x = float(FreeCAD.Units.Quantity(x, _unit_of(plain_unit)).getValueAs(unit))
    if not math.isfinite(x):
        _fail("%s is %r: give a finite number" % (name, x))
    return x


def _example(unit):
    return {"N": "1000 N", "MPa": "210000 MPa", "mm": "2 mm", "t/mm^3": "7850 kg/m^3",
            "mm/s^2": "9806.65 mm/s^2"}.get(unit, "1 " + unit)


def prop(obj, name, unit, plain_unit=None):
    """Property `name` of `obj` in `unit` (see value_in); the message names obj's label."""
    return value_in(getattr(obj, name), unit, "'%s': %s" % (obj.Label, name), plain_unit)


def set_prop(obj, name, value, unit):
    """Sets property `name` of `obj` to `value` given in `unit`: as a plain float where FreeCAD
    keeps the property as a float in that unit (0.20's FEM constraints), as a quantity
    otherwise (1.x: a float there would be read in FreeCAD's internal unit)."""
    if obj.getTypeIdOfProperty(name) == "App::PropertyFloat":
        setattr(obj, name, float(value))
    else:
        setattr(obj, name, FreeCAD.Units.Quantity("%.17g %s" % (value, unit)))


def vector(v, name):
    """A FreeCAD Vector (or 3 numbers) as [x, y, z] floats, every one finite."""
    try:
        xyz = [float(v.x), float(v.y), float(v.z)] if hasattr(v, "x") else [float(c) for c in v]
    except (TypeError, ValueError):
        xyz = []
    if len(xyz) != 3 or not all(math.isfinite(c) for c in xyz):
        _fail("%s must be a vector of three finite numbers (x, y, z), not %r" % (name, v))
    return xyz


def gravity(c):
    """The acceleration (mm/s², [x, y, z]) of FEM's self weight constraint `c`: FreeCAD 0.20's
    Gravity_x/y/z (multiples of g), or 1.x's GravityAcceleration along GravityDirection."""
    label = "'%s'" % c.Label
    if "GravityAcceleration" in c.PropertiesList:
        g = value_in(c.GravityAcceleration, "mm/s^2", label + ": GravityAcceleration")
        d = vector(c.GravityDirection, label + ": GravityDirection")
        length = math.sqrt(sum(x * x for x in d))
        if length == 0:
            _fail("%s: GravityDirection is zero: give the direction gravity points in" % label)
        return [g * x / length for x in d]
    from . import checks
    return [checks.number(getattr(c, "Gravity_" + a), "%s: Gravity_%s" % (label, a)) * STANDARD_GRAVITY
            for a in "xyz"]


def add_quantity(obj, name, group, doc, kind, unit):
    """Adds property `name` (group `group`, tooltip `doc`) holding a quantity of `unit`'s kind
    (`unit`: a unit FreeCAD parses, e.g. "mJ"), 0 to start with: FreeCAD's own property type
    `kind` ("App::PropertyWork") where this FreeCAD has it, else an App::PropertyQuantity given
    `unit`'s kind (keep_unit). Nothing is done when `obj` has the property already."""
    if name in obj.PropertiesList:
        return
    try:
        obj.addProperty(kind, name, group, doc)
    except Exception:  # FreeCAD 0.20 has no such type: a quantity given its unit
        obj.addProperty("App::PropertyQuantity", name, group, doc)
        keep_unit(obj, name, unit)


def keep_unit(obj, name, unit):
    """Gives the App::PropertyQuantity `name` of `obj` the kind of `unit` ("mJ"), keeping its
    value. FreeCAD 0.20 offers no Python call for a quantity property's unit: it refuses any
    value with a unit ("Not matching Unit!") until an expression has set one, and it saves the
    value only (a reopened document's quantity is a bare number in FreeCAD's internal units,
    mm, kg, s). So the unit comes from an expression evaluated once and removed. Properties of
    another type, or already in `unit`'s kind, are left alone."""
    if obj.getTypeIdOfProperty(name) != "App::PropertyQuantity":
        return
    value = getattr(obj, name)
    kind = _unit_of(unit)
    if value.Unit == kind:
        return
    in_unit = FreeCAD.Units.Quantity(float(value.Value), kind).getValueAs(unit)  # the bare number is internal
    obj.setExpression(name, "%.17g %s" % (float(in_unit), unit))
    obj.recompute()
    obj.setExpression(name, None)


def to_text(value, unit, precision=6):
    """A float in `unit` written as FreeCAD's quantity text ("7850 kg/m^3")."""
    return "%.*g %s" % (precision, value, unit)
