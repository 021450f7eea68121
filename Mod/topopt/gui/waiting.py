"""Worker calls made from the GUI thread (Mesh, the threshold slider, New study's checks): a
modal progress dialog with Cancel keeps FreeCAD responsive while the worker process runs, and
Cancel kills the worker at once, even one that has stopped answering."""
import FreeCADGui
from PySide2 import QtCore, QtWidgets


class WaitDialog:
    """Pass on_progress and cancel to a worker call (runner.mesh_only, runner.reextract,
    api.info); the dialog shows the stage, appears only when the call takes over half a
    second, and blocks other input meanwhile (so the document cannot change under the call)."""

    def __init__(self, title):
        self.dialog = QtWidgets.QProgressDialog(title, "Cancel", 0, 0, FreeCADGui.getMainWindow())
        self.dialog.setWindowTitle("TopOpt")
        self.dialog.setWindowModality(QtCore.Qt.ApplicationModal)
        self.dialog.setMinimumDuration(500)
        self.dialog.setValue(0)
        self.title = title

    def on_progress(self, record):
        if "iteration" in record:
            self.dialog.setLabelText("%s: iteration %d" % (self.title, record["iteration"]))
        else:
            self.dialog.setLabelText("%s: %s" % (self.title, record.get("message", record.get("stage", ""))))
        return self.cancel()

    def cancel(self):
        # until the dialog shows (and blocks the rest), no user input may reach the document
        flags = QtCore.QEventLoop.AllEvents if self.dialog.isVisible() else QtCore.QEventLoop.ExcludeUserInputEvents
        QtWidgets.QApplication.processEvents(flags, 20)
        return self.dialog.wasCanceled()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.dialog.reset()
        self.dialog.deleteLater()
        return False
