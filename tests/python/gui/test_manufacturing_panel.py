"""The study panel's manufacturing entries in a real FreeCAD window (under Xvfb): a split draw
direction picked from a face with its parting point picked from another, an overhang limit
with a picked build direction, angle and base face, the smallest and largest member size, and
Keep loaded faces. Each value set in the panel reaches the study and the job a run hands to
the worker (runner.prepare), and the panel shows them again when it is reopened. Screenshots
of the panel at FreeCAD's default combo view width go to TOPOPT_SCREENSHOTS."""
import json
import os
import unittest

import FreeCADGui
from PySide import QtGui

from gui_helpers import BoxPanelCase, grab_window, scroll_to, select, settle, texts_cut
from topopt.app import api, runner
from topopt.gui import panels

SHOTS = os.environ.get("TOPOPT_SCREENSHOTS", "/tmp/topopt-screenshots")


def shoot_panel(panel, name):
    """The main window with the panel scrolled to its manufacturing group (the combo view as
    FreeCAD opens it), and the whole panel unscrolled at the combo view's width."""
    os.makedirs(SHOTS, exist_ok=True)
    mw = FreeCADGui.getMainWindow()
    mw.resize(1280, 960)
    settle()
    scroll_to(panel, panel.controls.process.box)
    grab_window(os.path.join(SHOTS, name))
    form = panel.form
    form.resize(form.width(), form.sizeHint().height())
    form.grab().save(os.path.join(SHOTS, name.replace(".png", "_whole.png")))


def outside_their_parents(form):
    """The panel's visible widgets that stick out of the widget holding them (clipped), as
    (class, text, right edge, parent width); the form at the width the combo view gives it."""
    out = []
    for w in form.findChildren(QtGui.QWidget):
        parent = w.parentWidget()
        if not w.isVisible() or parent is None or isinstance(w, QtGui.QScrollBar):
            continue
        if w.geometry().right() > parent.rect().right() or w.geometry().left() < 0:
            text = w.text() if hasattr(w, "text") else getattr(w, "title", lambda: "")()
            out.append((type(w).__name__, text, w.geometry().right(), parent.rect().right()))
    return out


class ManufacturingPanel(BoxPanelCase):
    DOCUMENT = "PanelProcess"

    def set_every_entry(self):
        p, part = self.panel.controls.process, self.study.Part
        select(part, "Face5")  # z = 0, outward normal -z: drawn downwards
        p.pick_draw()
        select(part, "Face1")  # x = 0: its centre (0, 5, 5) is the parting plane's point
        p.pick_parting_point()
        select(part, "Face6")  # z = 10: built along +z
        p.pick_build()
        p.overhang_angle.setValue(50.0)
        select(part, "Face5")  # the bottom stands on the plate
        p.pick_base_face()
        p.min_member.setValue(8.0)
        p.max_member.setValue(12.0)
        keep = [b for b in self.panel.bindings if b.prop == "KeepLoadedFaces"][0]
        self.assertTrue(keep.widget.isChecked())  # on by default
        keep.widget.setChecked(False)
        join = [b for b in self.panel.bindings if b.prop == "JoinNonDesign"][0]
        self.assertTrue(join.widget.isChecked())  # on by default
        join.widget.setChecked(False)
        settle()

    def test_each_entry_reaches_the_job_and_shows_again_on_reopen(self):
        self.set_every_entry()
        self.assertFalse(self.study.KeepLoadedFaces)  # the panel edits the property at once
        combo = FreeCADGui.getMainWindow().findChild(QtGui.QDockWidget, "Combo View")
        if combo is not None:  # the panel fits FreeCAD's default combo view, nothing clipped
            widths = {b.title(): b.minimumSizeHint().width() for b in self.panel.form.findChildren(QtGui.QGroupBox)}
            self.assertLessEqual(self.panel.form.minimumSizeHint().width(), combo.width(), widths)
        shoot_panel(self.panel, "panel_manufacturing.png")
        self.assertEqual(outside_their_parents(self.panel.form), [])
        self.assertEqual(texts_cut(self.panel.form), [])  # every value, item and label shows whole
        self.assertTrue(self.panel.accept())
        c = json.loads(self.study.GeometryControls)
        self.assertEqual(c["draw_direction"], {"direction": [0.0, 0.0, -1.0], "parting_point": [0.0, 5.0, 5.0]})
        self.assertEqual(c["overhang"], {"direction": [0.0, 0.0, 1.0], "angle": 50.0, "base_face": "Face5"})
        self.assertEqual((c["min_member_size"], c["max_member_size"]), (8.0, 12.0))
        self.assertEqual(self.study.Update, "mma")  # the largest member size needs MMA
        opt = runner.prepare(self.study).job["optimization"]  # what a run hands to the worker
        self.assertEqual(opt["controls"], c)
        self.assertIs(opt["keep_loaded_faces"], False)
        self.assertFalse(self.study.JoinNonDesign)
        self.assertIs(runner.prepare(self.study).job["result"]["join_non_design"], False)
        self.assertEqual(opt["update"], "mma")
        reopened = panels.open_study_panel(self.study)
        self.panel = reopened
        p = reopened.controls.process
        self.assertTrue(p.draw_on.isChecked())
        self.assertEqual(p.draw_kind.currentText(), "split")
        self.assertEqual(p.draw_dir.value(), [0.0, 0.0, -1.0])
        self.assertEqual(p.parting_point.value(), [0.0, 5.0, 5.0])
        self.assertTrue(p.overhang_on.isChecked())
        self.assertEqual((p.build_dir.value(), p.overhang_angle.value()), ([0.0, 0.0, 1.0], 50.0))
        self.assertEqual(p.base_face.text(), "Face5")
        self.assertEqual((p.min_member.value(), p.max_member.value()), (8.0, 12.0))
        keep = [b for b in reopened.bindings if b.prop == "KeepLoadedFaces"][0]
        self.assertFalse(keep.widget.isChecked())
        join = [b for b in reopened.bindings if b.prop == "JoinNonDesign"][0]
        self.assertFalse(join.widget.isChecked())
        self.assertTrue(reopened.accept())  # unchanged values are written back unchanged
        self.assertEqual(json.loads(self.study.GeometryControls), c)

    def test_one_sided_draw_and_no_base_face(self):
        p = self.panel.controls.process
        select(self.study.Part, "Edge1")  # a straight edge along z
        p.pick_draw()
        select(self.study.Part, "Face6")
        p.pick_build()
        self.assertTrue(p.draw_on.isChecked() and p.overhang_on.isChecked())
        self.assertEqual(p.draw_kind.currentText(), "one-sided")
        self.assertFalse(p.parting_point.isEnabled())  # only a split has a parting plane
        self.assertTrue(self.panel.accept())
        c = json.loads(self.study.GeometryControls)
        self.assertEqual(set(c["draw_direction"]), {"direction"})
        self.assertEqual([abs(x) for x in c["draw_direction"]["direction"]], [0.0, 0.0, 1.0])
        self.assertEqual(c["overhang"], {"direction": [0.0, 0.0, 1.0], "angle": 45.0})
        self.assertNotIn("min_member_size", c)
        self.assertIs(api.job_of(self.study)["optimization"]["keep_loaded_faces"], True)
        self.assertIs(api.job_of(self.study)["result"]["join_non_design"], True)

    def test_a_base_face_off_the_part_or_an_edge_is_refused(self):
        p = self.panel.controls.process
        other = self.doc.addObject("Part::Box", "Other")
        self.doc.recompute()
        for obj, sub in ((other, "Face5"), (self.study.Part, "Edge1")):
            select(obj, sub)
            with self.assertRaises(Exception) as caught:
                p.pick_base_face()
            self.assertIn("pick the part's face that stands on the base plate", str(caught.exception))
        self.assertFalse(p.overhang_on.isChecked())
        self.assertEqual(p.base_face.text(), "none: the part's lowest point")

    def test_a_refused_member_size_keeps_the_panel_open_and_the_study_unchanged(self):
        p = self.panel.controls.process
        p.min_member.setValue(10.0)
        p.max_member.setValue(6.0)  # the widest ball below the thinnest member: refused
        self.assertFalse(self.panel.accept())
        self.assertTrue(self.panel.is_open())
        self.assertEqual(self.study.GeometryControls, "")
        self.assertEqual(self.study.Update, "oc")


if __name__ == "__main__":
    unittest.main()
