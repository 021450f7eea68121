"""Building the native core of a clone of the repository from FreeCAD's menu: runs the build
command (topopt.build_command(): scripts/build --workbench in the repository) as a process of
its own, with CMake's percentage in a progress dialog, its output in the report view's log,
and Cancel. Once built, the workbench uses the core without a restart."""
import re

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

import topopt

_PERCENT = re.compile(r"^\[\s*(\d+)%\]")


def build_percent(line, last=0):
    """The build's progress from one line of its output ("[ 42%] Building CXX object …"),
    never below `last`."""
    m = _PERCENT.match(line.strip())
    return max(last, int(m.group(1))) if m else last


class CoreBuild:
    """One run of the build command. run() blocks (with the progress dialog) and returns
    (exit code, last lines of output)."""

    def __init__(self, root):
        self.root = root
        self.percent = 0
        self.tail = []
        self.process = QtCore.QProcess()
        self.process.setWorkingDirectory(root)
        self.process.setProcessChannelMode(QtCore.QProcess.MergedChannels)
        self.process.readyReadStandardOutput.connect(self._read)
        self.dialog = QtGui.QProgressDialog("Building TopOpt's native core…", "Cancel", 0, 100,
                                            FreeCADGui.getMainWindow())
        self.dialog.setWindowTitle("TopOpt")
        self.dialog.setWindowModality(QtCore.Qt.ApplicationModal)
        self.dialog.setMinimumDuration(0)
        self.dialog.setAutoClose(False)

    def _read(self):
        text = bytes(self.process.readAllStandardOutput()).decode("utf-8", "replace")
        for line in text.splitlines():
            FreeCAD.Console.PrintLog("TopOpt build: %s\n" % line)
            self.percent = build_percent(line, self.percent)
            self.tail = (self.tail + [line])[-15:]
            if line.strip():
                self.dialog.setLabelText("Building TopOpt's native core (%d %%)\n%s" % (self.percent, line[:90]))
        self.dialog.setValue(min(99, self.percent))

    def run(self):
        self.process.start("/bin/sh", ["-c", "scripts/build --workbench"])
        if not self.process.waitForStarted(10000):
            return -1, ["could not start the build: %s" % self.process.errorString()]
        while self.process.state() != QtCore.QProcess.NotRunning:
            QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 100)
            if self.dialog.wasCanceled():
                self.process.kill()
                self.process.waitForFinished(10000)
                self.tail.append("cancelled")
                break
            self.process.waitForFinished(100)
        self._read()
        self.dialog.reset()
        self.dialog.deleteLater()
        cancelled = self.tail[-1:] == ["cancelled"]
        return (-1 if cancelled else self.process.exitCode()), self.tail


def build_native_core():
    """Runs the build of a clone's native core with progress and says how it went (message
    boxes unless TopOptNoDialogs is set, the report view always). Returns True when the core
    is usable afterwards."""
    root = topopt.source_root()
    if root is None:
        _tell("This TopOpt was installed without its sources, so it cannot build its core: install the TopOpt "
              "package again.", error=True)
        return False
    FreeCAD.Console.PrintMessage("TopOpt: building the native core: %s\n" % topopt.build_command())
    code, tail = CoreBuild(root).run()
    problem = topopt.core_problem()
    if code == 0 and problem is None:
        _tell("TopOpt's native core is built and ready.")
        return True
    _tell("The build of TopOpt's native core failed (exit code %s). Its last lines:\n\n%s\n\n"
          "On Debian or Ubuntu, 'sudo scripts/setup --build-deps' in %s installs what the build needs."
          % (code, "\n".join(tail[-8:]), root), error=True)
    return False


def _tell(text, error=False):
    (FreeCAD.Console.PrintError if error else FreeCAD.Console.PrintMessage)("TopOpt: %s\n" % text)
    mw = FreeCADGui.getMainWindow()
    if mw is not None and mw.isVisible() and not FreeCAD.ConfigGet("TopOptNoDialogs"):
        (QtGui.QMessageBox.warning if error else QtGui.QMessageBox.information)(mw, "TopOpt", text)
