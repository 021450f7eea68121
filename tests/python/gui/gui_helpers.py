"""Shared by the GUI tests: the window made ready, events processed, elements selected, a
box study with its panel open."""
import unittest

import FreeCAD
import FreeCADGui
from PySide import QtGui


def settle(n=20):
    """Processes pending Qt events n times (layouts, repaints, queued signals)."""
    for _ in range(n):
        QtGui.QApplication.processEvents()


def select(obj, *subs):
    """Makes FreeCAD's selection the sub-elements `subs` ("Face3", ...) of `obj`."""
    FreeCADGui.Selection.clearSelection()
    for sub in subs:
        FreeCADGui.Selection.addSelection(obj, sub)


def open_workbench():
    """The main window shown with TopOpt's workbench active; errors go to the report view only
    (no message boxes that would wait for a click)."""
    FreeCAD.ConfigSet("TopOptNoDialogs", "1")
    FreeCADGui.getMainWindow().show()
    FreeCADGui.activateWorkbench("TopOptWorkbench")
    settle()


class BoxPanelCase(unittest.TestCase):
    """Each test gets app.helpers.box_study's box (document DOCUMENT) with the study's panel
    open (self.doc, self.study, self.panel); the panel is cancelled and the document closed
    after it."""

    DOCUMENT = "PanelBox"

    @classmethod
    def setUpClass(cls):
        open_workbench()

    def setUp(self):
        from app.helpers import box_study
        from topopt.gui import panels
        self.doc, self.study = box_study(self.DOCUMENT)
        FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
        self.panel = panels.open_study_panel(self.study)
        settle()

    def tearDown(self):
        if self.panel.is_open():
            self.panel.reject()
        FreeCAD.closeDocument(self.doc.Name)


def scroll_to(panel, widget):
    """Scrolls the combo view's task panel holding `panel` (a study panel) so that `widget`
    shows, as a user would before a screenshot."""
    area = panel.form.parent()
    while area is not None and not isinstance(area, QtGui.QScrollArea):
        area = area.parent()
    if area is not None:
        area.ensureWidgetVisible(widget)
    settle()
