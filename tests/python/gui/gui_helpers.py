"""Shared by the GUI tests: the window made ready, events processed, elements selected, a
box study with its panel open, screenshots of the whole window with its 3D view."""
import os
import shutil
import tempfile
import unittest

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui


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
    maxDiff = None  # a list of cut texts shows whole

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


def viewer_rect():
    """The active 3D view's drawing area in main window coordinates (a QRect), or None when no
    3D view shows."""
    gui_doc = FreeCADGui.ActiveDocument
    view = gui_doc.ActiveView if gui_doc is not None else None
    viewport = view.graphicsView().viewport() if hasattr(view, "graphicsView") else None
    if viewport is None or not viewport.isVisible() or viewport.width() <= 0 or viewport.height() <= 0:
        return None
    return QtCore.QRect(viewport.mapTo(FreeCADGui.getMainWindow(), QtCore.QPoint(0, 0)), viewport.size())


def grab_window(path):
    """Saves the main window at `path` (PNG) as a user sees it: the widgets, and the active 3D
    view painted in at the viewer's place (viewer_rect). A widget grab leaves the OpenGL area
    empty under Xvfb (and the viewer's grabFramebuffer returns its background only), so the
    view is rendered offscreen by View.saveImage at the viewer's own size, with its own
    background. Returns the QImage saved."""
    settle()
    image = FreeCADGui.getMainWindow().grab().toImage()
    rect = viewer_rect()
    if rect is not None:
        folder = tempfile.mkdtemp(prefix="topopt-view-")
        rendered = os.path.join(folder, "view.png")
        try:
            FreeCADGui.ActiveDocument.ActiveView.saveImage(rendered, rect.width(), rect.height(), "Current")
            painter = QtGui.QPainter(image)
            painter.drawImage(rect.topLeft(), QtGui.QImage(rendered))
            painter.end()
        finally:
            shutil.rmtree(folder, ignore_errors=True)
    image.save(path)
    return image


def colours_in(image, rect, step=8):
    """How many different colours `image` (a QImage) has at the points of a `step` pixel grid
    in `rect` (a QRect)."""
    return len({image.pixel(x, y) for x in range(rect.left(), rect.right(), step)
                for y in range(rect.top(), rect.bottom(), step)})


def _room_for_text(edit):
    """The width a QLineEdit (a spin box's edit field) needs to show its text whole: the
    text's advance, Qt's 2 px margin on either side and the cursor's pixel. Narrower, Qt
    scrolls the text to the cursor and the user sees it cut (":.50 mm")."""
    return edit.fontMetrics().horizontalAdvance(edit.text()) + 2 * 2 + 1


def texts_cut(form):
    """The visible entries of `form` (a task panel's widget) too narrow for their text, as
    (class, text, width, width needed): a spin box whose edit field cannot show its current
    text whole (_room_for_text), a combo box or check box narrower than its minimum size hint
    (its longest item, or its box and label), a button narrower than its label in its frame."""
    out = []
    for w in form.findChildren(QtGui.QWidget):
        if not w.isVisible():
            continue
        if isinstance(w, QtGui.QAbstractSpinBox):
            edit = w.findChild(QtGui.QLineEdit)
            needed, width, text = _room_for_text(edit), edit.contentsRect().width(), edit.text()
        elif isinstance(w, QtGui.QComboBox):
            needed, width, text = w.minimumSizeHint().width(), w.width(), w.currentText()
        elif isinstance(w, QtGui.QPushButton):  # its label inside its frame (not the style's minimum of 80 px)
            icon = w.iconSize().width() + 4 if not w.icon().isNull() else 0
            frame = 2 * w.style().pixelMetric(QtGui.QStyle.PM_DefaultFrameWidth) + 2
            needed, width, text = w.fontMetrics().horizontalAdvance(w.text()) + frame + icon, w.width(), w.text()
        elif isinstance(w, (QtGui.QCheckBox, QtGui.QRadioButton)):
            needed, width, text = w.minimumSizeHint().width(), w.width(), w.text()
        else:
            continue
        if width < needed:
            out.append((type(w).__name__, text, width, needed))
    return out
