"""The hostile-input suite, module half: the rocker as FreeCAD exports it to BREP, damaged in
120 deterministic ways (fuzz_brep.py, the generator of the command-line half in
tests/cpp/hostile), each handed to _native.info inside FreeCADCmd. Every case must end within
30 s in a report or in a TopOptError whose code names a user error and whose message names
the part in user words (no OCCT or pybind11 names); FreeCAD must survive them all. The time
budget is 20 s, so that a hang shows as code "Timeout", which fails the test."""
import collections
import re
import time
import unittest

import Part

import topopt
from fuzz_brep import KINDS, damage_brep
from helpers import example

CASES_PER_KIND = 24
USER_ERRORS = {"Io", "InvalidShape", "Crashed"}  # Crashed: OCCT died in the child, named
INTERNALS = re.compile(r"::|Standard_|NCollection|TopoDS_|BRepCheck|Geom_|pybind11|internal error")


class DamagedBrepStrings(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.native = topopt.native()
        cls.rocker = Part.read(example("rocker.step")).exportBrepToString().encode("latin-1")

    def run_kind(self, kind):
        outcomes = collections.Counter()
        for seed in range(1, CASES_PER_KIND + 1):
            text = damage_brep(self.rocker, kind, seed).decode("latin-1")
            t0 = time.monotonic()
            try:
                report = self.native.info(text, "", -1.0, 20.0)
                outcome = "result"
                self.assertEqual(report["part"]["solids"], 1)
            except self.native.TopOptError as e:
                outcome = e.code
                message = str(e)
                self.assertIn(e.code, USER_ERRORS, "%s %d: %s" % (KINDS[kind], seed, message))
                self.assertIn("the part", message, "%s %d" % (KINDS[kind], seed))
                self.assertIsNone(INTERNALS.search(message), "%s %d: %s" % (KINDS[kind], seed, message))
            seconds = time.monotonic() - t0
            self.assertLess(seconds, 30.0, "%s %d" % (KINDS[kind], seed))
            outcomes[outcome] += 1
        print("%s: %s" % (KINDS[kind], dict(sorted(outcomes.items()))))

    def test_byte_flips(self):
        self.run_kind(0)

    def test_inserts(self):
        self.run_kind(1)

    def test_deletes(self):
        self.run_kind(2)

    def test_truncations(self):
        self.run_kind(3)

    def test_digit_changes(self):
        self.run_kind(4)

    def test_the_sound_part_still_reads(self):
        report = self.native.info(self.rocker.decode("latin-1"))
        self.assertEqual(report["part"]["faces"], 11)

    def test_named_crasher_is_named(self):
        # a damaged text that crashes OCCT's reader (tests/data/hostile): FreeCAD survives it
        import os
        path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "data", "hostile",
                            "line_missing_a_number.brep")
        with open(path) as f:
            text = f.read()
        with self.assertRaises(self.native.TopOptError) as ctx:
            self.native.info(text)
        self.assertEqual(ctx.exception.code, "Crashed")
        self.assertEqual(str(ctx.exception),
                         "the part (its BREP text) is damaged: OCCT crashed reading it (Segmentation fault, "
                         "signal 11); re-import or rebuild it (the document may have been damaged)")


if __name__ == "__main__":
    unittest.main()
