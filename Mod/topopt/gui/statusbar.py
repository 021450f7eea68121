"""Progress in FreeCAD's status bar: its own progress bar (the one FreeCAD shows while it
recomputes or loads) and its message area, driven from the GUI thread while a worker runs.
FreeCAD's Python progress indicator cannot be used for this: it blocks input to the main
window while it runs, and the panel's Stop button must stay usable."""
import FreeCADGui
from PySide import QtGui


class StatusProgress:
    """show(fraction, text) puts `text` and the percentage into the status bar; done(text)
    leaves `text` there for a while and hides the bar."""

    def __init__(self):
        bar = FreeCADGui.getMainWindow().statusBar()
        bars = bar.findChildren(QtGui.QProgressBar)
        self.status = bar
        self.bar = bars[0] if bars else None  # FreeCAD's own (Gui::ProgressBar)
        self.own = False
        if self.bar is None:
            self.bar = QtGui.QProgressBar()
            bar.addPermanentWidget(self.bar)
            self.own = True
        self.was_visible = self.bar.isVisible()

    def show(self, fraction, text):
        percent = int(round(100 * min(1.0, max(0.0, fraction))))
        self.bar.setRange(0, 100)
        self.bar.setValue(percent)
        self.bar.setFormat("%p %")
        self.bar.show()
        self.status.showMessage("TopOpt: %s (%d %%)" % (text, percent))

    def done(self, text, seconds=15):
        self.bar.reset()
        if self.own or not self.was_visible:
            self.bar.hide()
        self.status.showMessage("TopOpt: %s" % text, int(seconds * 1000))
