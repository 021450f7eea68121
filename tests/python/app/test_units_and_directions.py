"""Values with units (FreeCAD 0.20's floats and 1.x's quantities read alike), explicit force
directions (what FEM draws is what the job applies; no silent default), the result threshold
never feeding a run, and documents of older versions loading as current studies."""
import os
import tempfile
import unittest

import FreeCAD
import ObjectsFem
import Part
from helpers import box_study

from topopt.app import api, directions, units
from topopt.app.errors import TopOptError
from topopt.app.job import constraint_to_job, study_to_job
from topopt.app.study import owned_objects


def fake_object(doc, props, proxy_type=None):
    """A FeaturePython with the given (type, name, value) properties, standing in for FreeCAD
    1.x's FEM objects whose values are quantities."""
    obj = doc.addObject("App::FeaturePython", "Fake")
    for kind, name, value in props:
        obj.addProperty(kind, name, "Test", "")
        setattr(obj, name, value)
    if proxy_type:
        class Proxy:
            Type = proxy_type
        obj.Proxy = Proxy()
    return obj


class Units(unittest.TestCase):
    def setUp(self):
        self.doc = FreeCAD.newDocument("Units")

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_floats_quantities_and_text(self):
        self.assertEqual(units.value_in(1000.0, "N", "Force"), 1000.0)
        self.assertAlmostEqual(units.value_in(FreeCAD.Units.Quantity("2 kN"), "N", "Force"), 2000.0)
        self.assertAlmostEqual(units.value_in("7850 kg/m^3", "t/mm^3", "Density"), 7.85e-9)
        self.assertAlmostEqual(units.value_in("210 GPa", "MPa", "E"), 210000.0)
        self.assertAlmostEqual(units.value_in(7.85e-9, "t/mm^3", "Density"), 7.85e-9)  # older documents' floats

    def test_wrong_units_and_values_are_named(self):
        with self.assertRaises(TopOptError) as e:
            units.value_in("5 mm", "N", "'Force': Force")
        self.assertIn("'Force': Force is 5", str(e.exception))
        self.assertIn("write it like '1000 N'", str(e.exception))
        with self.assertRaises(TopOptError) as e:
            units.value_in("heavy", "t/mm^3", "Density")
        self.assertIn("Density is 'heavy'", str(e.exception))
        with self.assertRaises(TopOptError) as e:
            units.value_in(float("nan"), "N", "Force")
        self.assertIn("give a finite number", str(e.exception))

    def test_quantity_properties_as_freecad_1_stores_them(self):
        obj = fake_object(self.doc, [("App::PropertyForce", "Force", "1.5 kN"), ("App::PropertyPressure",
                                      "Pressure", "2 MPa"), ("App::PropertyDistance", "xDisplacement", "0 mm")])
        self.assertAlmostEqual(units.prop(obj, "Force", "N"), 1500.0)
        self.assertAlmostEqual(units.prop(obj, "Pressure", "MPa"), 2.0)
        self.assertEqual(units.prop(obj, "xDisplacement", "mm"), 0.0)
        units.set_prop(obj, "Force", 250.0, "N")  # a quantity, not 250 in FreeCAD's internal mN
        self.assertAlmostEqual(units.prop(obj, "Force", "N"), 250.0)
        fem = ObjectsFem.makeConstraintForce(self.doc, "F")
        units.set_prop(fem, "Force", 250.0, "N")  # FreeCAD 0.20: a float in N
        self.assertEqual(fem.Force, 250.0)

    def test_self_weight_old_and_new(self):
        old = ObjectsFem.makeConstraintSelfWeight(self.doc)
        old.Gravity_x, old.Gravity_y, old.Gravity_z = 0.0, 0.0, -1.0
        self.assertEqual(units.gravity(old), [0.0, 0.0, -9806.65])
        new = fake_object(self.doc, [("App::PropertyAcceleration", "GravityAcceleration", "9806.65 mm/s^2"),
                                     ("App::PropertyVector", "GravityDirection", FreeCAD.Vector(0, 0, -2))],
                          "Fem::ConstraintSelfWeight")
        self.assertEqual([round(x, 6) for x in units.gravity(new)], [0.0, 0.0, -9806.65])
        doc, study = box_study("SelfWeight")
        try:
            kind, item = constraint_to_job(study, new)
        finally:
            FreeCAD.closeDocument(doc.Name)
        self.assertEqual((kind, item["type"]), ("load", "gravity"))


class ForceDirections(unittest.TestCase):
    def setUp(self):
        self.doc, self.study = box_study("Directions")

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def force(self):
        return [c for c in self.study.Constraints if c.TypeId == "Fem::ConstraintForce"][0]

    def test_scripted_force_is_drawn_as_applied(self):
        f = api.add_force(self.study, "Face2", (0, -300, 400))
        self.doc.recompute()
        self.assertAlmostEqual(f.DirectionVector.y, -0.6)  # what FEM draws and applies
        self.assertAlmostEqual(f.DirectionVector.z, 0.8)
        line = directions.helper_line(f)
        self.assertIsNotNone(line)
        self.assertEqual(line.TopOptRole, directions.ROLE)
        loads = study_to_job(self.study)["load_cases"][0]["loads"]
        self.assertEqual([round(x, 9) for x in loads[1]["vector"]], [0.0, -300.0, 400.0])
        f.Force = 1000.0  # FEM recomputes its direction from the reference: the direction stays
        self.doc.recompute()
        self.assertAlmostEqual(f.DirectionVector.y, -0.6)
        self.assertIn(line, owned_objects(self.study))  # shown under the study, after its force

    def test_a_force_without_a_chosen_direction_is_refused(self):
        f = ObjectsFem.makeConstraintForce(self.doc, "Bare")
        f.References = [(self.study.Part, "Face2")]
        f.Force = 10.0
        self.study.Constraints = list(self.study.Constraints) + [f]
        self.doc.recompute()
        self.assertAlmostEqual(f.DirectionVector.Length, 1.0)  # FEM's own default, which nobody chose
        with self.assertRaises(TopOptError) as e:
            study_to_job(self.study)
        self.assertIn("'Bare' has no direction", str(e.exception))
        self.assertIn("give a direction (x, y, z)", str(e.exception))

    def test_direction_from_a_picked_face_and_reversed(self):
        f = self.force()
        part = self.study.Part
        directions.set_reference_direction(f, part, "Face6", reversed_=False)  # the box's top, z = 10
        self.doc.recompute()
        self.assertIsNone(directions.helper_line(f))
        self.assertFalse([o for o in self.doc.Objects if getattr(o, "TopOptRole", "") == directions.ROLE])
        up = directions.direction_of(f)
        directions.set_reference_direction(f, part, "Face6", reversed_=True)
        self.doc.recompute()
        self.assertEqual([round(-x, 9) for x in up], [round(x, 9) for x in directions.direction_of(f)])
        self.assertAlmostEqual(abs(up[2]), 1.0)

    def test_curved_reference_is_refused(self):
        cyl = self.doc.addObject("Part::Feature", "Cyl")
        cyl.Shape = Part.makeCylinder(2, 5)
        self.doc.recompute()
        with self.assertRaises(TopOptError) as e:
            directions.set_reference_direction(self.force(), cyl, "Face1")
        self.assertIn("neither a straight edge nor a planar face", str(e.exception))

    def test_threshold_never_feeds_a_run(self):
        before = study_to_job(self.study)
        self.study.Threshold = 0.25
        self.assertEqual(study_to_job(self.study), before)
        self.assertNotIn("threshold", before["optimization"])


class ConstraintValues(unittest.TestCase):
    """FEM's constraints as FreeCAD 0.20 stores them (floats in N, MPa, mm) and as 1.x does
    (quantities), read by the job into the same supports and loads."""

    def setUp(self):
        self.doc, self.study = box_study("ConstraintValues")
        self.part = self.study.Part

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def quantity_constraint(self, props):
        """A FreeCAD 1.x-like constraint: quantity properties on Face2 of the part."""
        obj = fake_object(self.doc, props)
        obj.addProperty("App::PropertyLinkSubList", "References", "Test", "")
        obj.References = [(self.part, "Face2")]
        return obj

    def test_force_pressure_and_components_read_alike(self):
        from topopt.app import job as jobmod
        force = ObjectsFem.makeConstraintForce(self.doc, "F")
        force.References = [(self.part, "Face2")]
        force.Force = 1500.0  # FreeCAD 0.20: N as a float
        directions.set_vector_direction(force, (0, 0, -1))
        self.doc.recompute()
        new_force = self.quantity_constraint([("App::PropertyForce", "Force", "1.5 kN"),
                                              ("App::PropertyVector", "TopOptDirection", FreeCAD.Vector(0, 0, -1))])
        old_item, new_item = jobmod._force(self.study, force, "F"), jobmod._force(self.study, new_force, "F")
        self.assertEqual((old_item["type"], old_item["faces"]), (new_item["type"], new_item["faces"]))
        for a, b, expected in zip(old_item["vector"], new_item["vector"], (0.0, 0.0, -1500.0)):
            self.assertAlmostEqual(a, expected, places=9)
            self.assertAlmostEqual(b, expected, places=9)
        pressure = ObjectsFem.makeConstraintPressure(self.doc, "P")
        pressure.References = [(self.part, "Face2")]
        pressure.Pressure, pressure.Reversed = 2.0, True  # MPa as a float, pulling
        new_pressure = self.quantity_constraint([("App::PropertyPressure", "Pressure", "2000 kPa"),
                                                 ("App::PropertyBool", "Reversed", True)])
        self.assertEqual(jobmod._pressure(self.study, pressure, "P"), jobmod._pressure(self.study, new_pressure, "P"))
        self.assertEqual(jobmod._pressure(self.study, new_pressure, "P")["value"], -2.0)
        fixed = ObjectsFem.makeConstraintDisplacement(self.doc, "D")
        fixed.References = [(self.part, "Face2")]
        fixed.xFix, fixed.xFree, fixed.yFree, fixed.zFree = True, False, True, True
        props = [("App::PropertyBool", a + kind, a == "x" if kind == "Fix" else a != "x")
                 for a in "xyz" for kind in ("Fix", "Free")]
        new_fixed = self.quantity_constraint(props + [("App::PropertyDistance", a + "Displacement", "0 mm")
                                                      for a in "xyz"])
        self.assertEqual(jobmod._components(self.study, fixed, "D"), jobmod._components(self.study, new_fixed, "D"))
        self.assertEqual(jobmod._components(self.study, new_fixed, "D")["fix"], ["x"])
        new_fixed.yFree = False
        new_fixed.yDisplacement = FreeCAD.Units.Quantity("0.5 mm")  # a prescribed move: refused, named
        with self.assertRaises(TopOptError) as e:
            jobmod._components(self.study, new_fixed, "'D'")
        self.assertIn("'D' prescribes a non-zero displacement", str(e.exception))


class StudyUnits(unittest.TestCase):
    def setUp(self):
        self.doc, self.study = box_study("StudyUnits")

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_material_with_units(self):
        self.assertEqual(self.study.getTypeIdOfProperty("YoungsModulus"), "App::PropertyPressure")
        self.assertIn(self.study.getTypeIdOfProperty("Density"), ("App::PropertyDensity", "App::PropertyQuantity"))
        self.assertEqual(self.study.Density.UserString, "7850.00 kg/m^3")  # a density, not a bare number
        self.study.YoungsModulus = "70 GPa"
        self.study.Density = "2700 kg/m^3"
        m = study_to_job(self.study)["material"]
        self.assertAlmostEqual(m["E"], 70000.0)
        self.assertAlmostEqual(m["density"], 2.7e-9)
        self.study.Density = "2.7 g/cm^3"  # any unit of density
        self.assertAlmostEqual(study_to_job(self.study)["material"]["density"], 2.7e-9)

    def test_a_density_in_the_wrong_unit_is_refused_or_named(self):
        with self.assertRaises(Exception):  # FreeCAD itself refuses it: the property holds a density
            self.study.Density = "5 mm"
        self.assertAlmostEqual(units.prop(self.study, "Density", "kg/m^3"), 7850.0)
        # an older version's text in a wrong unit stays text when the study loads, and a run names it
        self.study.removeProperty("Density")
        self.study.addProperty("App::PropertyString", "Density", "Material", "")
        self.study.Density = "5 mm"
        self.study.Proxy.ensure_properties(self.study)
        with self.assertRaises(TopOptError) as e:
            study_to_job(self.study)
        self.assertIn("Density is 5", str(e.exception))
        self.assertIn("not in a unit of the same kind as t/mm^3: write it like '7850 kg/m^3'", str(e.exception))


class OlderDocuments(unittest.TestCase):
    def test_floats_and_scripted_directions_become_current(self):
        doc, study = box_study("Older")
        force = [c for c in study.Constraints if c.TypeId == "Fem::ConstraintForce"][0]
        # as an older TopOpt saved it: unitless floats, the direction in TopOptDirection only
        doc.removeObject(directions.helper_line(force).Name)
        force.Direction = None
        force.addProperty("App::PropertyVector", "TopOptDirection", "TopOpt", "")
        force.TopOptDirection = FreeCAD.Vector(0, 0, -1)
        for name, value in (("YoungsModulus", 200000.0), ("Density", 7.85e-9), ("ComplianceAsBuilt", 12.5)):
            study.removeProperty(name)
            study.addProperty("App::PropertyFloat", name, "Material", "")
            setattr(study, name, value)
        path = os.path.join(tempfile.mkdtemp(), "older.FCStd")
        force_name = force.Name
        api.save(doc, path)
        FreeCAD.closeDocument(doc.Name)
        doc = FreeCAD.openDocument(path)
        try:
            study = doc.getObject("TopOptStudy")
            force = doc.getObject(force_name)
            self.assertEqual(study.getTypeIdOfProperty("YoungsModulus"), "App::PropertyPressure")
            self.assertAlmostEqual(study.YoungsModulus.getValueAs("MPa"), 200000.0)
            job = study_to_job(study)
            self.assertAlmostEqual(job["material"]["density"], 7.85e-9)
            self.assertEqual(study.Density.UserString, "7850.00 kg/m^3")  # the float became a density
            self.assertEqual(study.ComplianceAsBuilt.Unit, FreeCAD.Units.Quantity("1 mJ").Unit)  # N·mm, a work
            self.assertAlmostEqual(units.prop(study, "ComplianceAsBuilt", "N*mm"), 12.5)
            self.assertIsNotNone(directions.helper_line(force))  # FEM now draws what is applied
            doc.recompute()
            self.assertAlmostEqual(force.DirectionVector.z, -1.0)
            self.assertNotIn("TopOptDirection", force.PropertiesList)
            self.assertEqual(job["load_cases"][0]["loads"][0]["vector"], [0.0, 0.0, -100.0])
        finally:
            FreeCAD.closeDocument(doc.Name)


if __name__ == "__main__":
    unittest.main()
