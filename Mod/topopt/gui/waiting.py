"""Worker calls made from the GUI thread (Mesh, the threshold slider, New study's checks): a
modal progress dialog with the stage and its % and Cancel keeps FreeCAD responsive while the
worker process runs, FreeCAD's status bar shows the same, and Cancel kills the worker at
once, even one that has stopped answering."""
import FreeCADGui
from PySide import QtCore, QtGui

from topopt.app import progress


class WaitDialog:
    """Pass on_progress and cancel to a worker call (runner.mesh_only, runner.reextract,
    api.info); `operation` ("mesh", "extract_surface", "info") sets how the stages add up to
    100 %. The dialog appears only when the call takes over half a second, and blocks other
    input meanwhile (so the document cannot change under the call)."""

    def __init__(self, title, operation="mesh"):
        self.dialog = QtGui.QProgressDialog(title, "Cancel", 0, 100, FreeCADGui.getMainWindow())
        self.dialog.setWindowTitle("TopOpt")
        self.dialog.setWindowModality(QtCore.Qt.ApplicationModal)
        self.dialog.setMinimumDuration(500)
        self.dialog.setValue(0)
        self.title = title
        self.tracker = progress.Tracker(operation)
        from topopt.gui.statusbar import StatusProgress
        self.status_bar = StatusProgress()

    def on_progress(self, record):
        self.tracker.update(record)
        self.dialog.setLabelText("%s: %s" % (self.title, self.tracker.label))
        self.dialog.setValue(min(99, self.tracker.percent()))
        self.status_bar.show(self.tracker.fraction, "%s: %s" % (self.title.lower(), self.tracker.label))
        return self.cancel()

    def cancel(self):
        # until the dialog shows (and blocks the rest), no user input may reach the document
        flags = QtCore.QEventLoop.AllEvents if self.dialog.isVisible() else QtCore.QEventLoop.ExcludeUserInputEvents
        QtGui.QApplication.processEvents(flags, 20)
        return self.dialog.wasCanceled()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        self.dialog.reset()
        self.dialog.deleteLater()
        self.status_bar.done("%s: %s" % (self.title.lower(), "done" if exc is None else "stopped"), 5)
        return False
