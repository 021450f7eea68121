"""The study's task panel: parameters, Run with a live plot, Cancel, and the threshold slider."""
import queue
import threading

import FreeCAD
import FreeCADGui
from PySide2 import QtCore, QtWidgets

from topopt.app import runner
from topopt.app.errors import TopOptError
from topopt.gui.plot import HistoryPlot


def report_error(e):
    """Shows a TopOpt error in the report view (and a message box when the GUI is visible)."""
    FreeCAD.Console.PrintError("TopOpt: %s\n" % e)
    if getattr(e, "details", ""):  # the worker's last words, for a bug report
        FreeCAD.Console.PrintLog("TopOpt worker output:\n%s\n" % e.details)
    mw = FreeCADGui.getMainWindow()
    if mw is not None and mw.isVisible() and not FreeCAD.ConfigGet("TopOptNoDialogs"):
        QtWidgets.QMessageBox.warning(mw, "TopOpt", str(e))


class StudyPanel:
    """Task panel of a study. A run is the worker process (topopt.app.worker), followed from a
    thread of this panel; the document is only touched here, in the GUI thread, when the run
    has succeeded. Cancel kills the worker at once, even one that has gone silent."""

    def __init__(self, study):
        self.study = study
        self.thread = None
        self.messages = queue.Queue()
        self.cancel_requested = False
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle("TopOpt study")
        layout = QtWidgets.QVBoxLayout(self.form)
        grid = QtWidgets.QFormLayout()
        self.volume = QtWidgets.QDoubleSpinBox()
        self.volume.setRange(0.01, 0.99)
        self.volume.setSingleStep(0.05)
        self.volume.setValue(study.VolumeFraction)
        self.size = QtWidgets.QDoubleSpinBox()
        self.size.setRange(0.0, 1e4)
        self.size.setSuffix(" mm")
        self.size.setSpecialValueText("automatic")
        self.size.setValue(float(study.MeshSize))
        self.mesher = QtWidgets.QComboBox()
        self.mesher.addItems(["auto", "native", "gmsh"])
        self.mesher.setToolTip("auto: the two-B-Rep advancing front, Gmsh where it cannot close a mesh; "
                               "native: the advancing front only; gmsh: OCC fragments meshed by Gmsh")
        if hasattr(study, "Mesher"):
            self.mesher.setCurrentText(str(study.Mesher))
        self.layers = QtWidgets.QSpinBox()
        self.layers.setRange(0, 4)
        self.layers.setSpecialValueText("off")
        self.layers.setToolTip("Element layers across walls thinner than two mesh sizes (native mesher); "
                               "one layer of tets is far too stiff in bending, more layers mean more elements")
        self.layers.setValue(int(getattr(study, "WallLayers", 0)))
        self.iterations = QtWidgets.QSpinBox()
        self.iterations.setRange(1, 10000)
        self.iterations.setValue(study.MaxIterations)
        grid.addRow("Volume fraction", self.volume)
        grid.addRow("Mesh size", self.size)
        grid.addRow("Mesher", self.mesher)
        grid.addRow("Layers across thin walls", self.layers)
        grid.addRow("Iterations (max)", self.iterations)
        layout.addLayout(grid)
        self.summary = QtWidgets.QLabel(self._summary_text())
        self.summary.setWordWrap(True)
        layout.addWidget(self.summary)
        buttons = QtWidgets.QHBoxLayout()
        self.run_button = QtWidgets.QPushButton("Run")
        self.cancel_button = QtWidgets.QPushButton("Cancel run")
        self.cancel_button.setEnabled(False)
        buttons.addWidget(self.run_button)
        buttons.addWidget(self.cancel_button)
        layout.addLayout(buttons)
        self.progress = QtWidgets.QProgressBar()
        self.progress.setRange(0, 100)
        layout.addWidget(self.progress)
        self.status = QtWidgets.QLabel(study.Status or "")
        self.status.setWordWrap(True)  # an error says what to try: all of it must show
        layout.addWidget(self.status)
        self.plot = HistoryPlot()
        self.plot.set_history(study.ComplianceHistory, study.VolumeHistory)
        layout.addWidget(self.plot)
        slider_row = QtWidgets.QHBoxLayout()
        slider_row.addWidget(QtWidgets.QLabel("Threshold"))
        self.threshold = QtWidgets.QSlider(QtCore.Qt.Horizontal)
        self.threshold.setRange(1, 99)
        self.threshold.setValue(int(round(100 * study.Threshold)) if study.Threshold > 0 else 50)
        self.threshold.setEnabled(bool(study.Densities))
        slider_row.addWidget(self.threshold)
        self.threshold_label = QtWidgets.QLabel("%.2f" % (self.threshold.value() / 100.0))
        slider_row.addWidget(self.threshold_label)
        layout.addLayout(slider_row)
        self.run_button.clicked.connect(self.start_run)
        self.cancel_button.clicked.connect(self.request_cancel)
        self.threshold.valueChanged.connect(
            lambda v: self.threshold_label.setText("%.2f" % (v / 100.0)))
        self.threshold.sliderReleased.connect(self.reextract)
        self.timer = QtCore.QTimer()
        self.timer.setInterval(100)
        self.timer.timeout.connect(self.poll)

    def _summary_text(self):
        s = self.study
        return "Part: %s · non-design solids: %d · supports and loads: %d" % (
            s.Part.Label if s.Part else "(none)", len(s.NonDesign), len(s.Constraints))

    def store_parameters(self):
        self.study.VolumeFraction = self.volume.value()
        self.study.MeshSize = self.size.value()
        if hasattr(self.study, "Mesher"):
            self.study.Mesher = self.mesher.currentText()
        if hasattr(self.study, "WallLayers"):
            self.study.WallLayers = self.layers.value()
        self.study.MaxIterations = self.iterations.value()

    # --- running ---------------------------------------------------------------------------
    def start_run(self):
        if self.thread is not None:
            return
        self.store_parameters()
        try:
            prepared = runner.prepare(self.study)
        except TopOptError as e:
            report_error(e)
            return
        self.cancel_requested = False
        self.plot.set_history([], [])
        self.run_button.setEnabled(False)
        self.cancel_button.setEnabled(True)
        self.status.setText("running…")
        self.thread = threading.Thread(target=self._work, args=(prepared,), daemon=True)
        self.thread.start()
        self.timer.start()

    def _work(self, prepared):
        def on_progress(record):
            self.messages.put(("progress", record))
            return self.cancel_requested
        try:
            self.messages.put(("done", runner.execute(prepared, on_progress, lambda: self.cancel_requested)))
        except TopOptError as e:
            self.messages.put(("error", e))
        except Exception as e:  # never let a worker exception vanish
            self.messages.put(("error", TopOptError("unexpected failure: %s" % e)))

    def request_cancel(self):
        self.cancel_requested = True
        self.status.setText("cancelling…")

    def poll(self):
        while True:
            try:
                kind, payload = self.messages.get_nowait()
            except queue.Empty:
                return
            if kind == "progress":
                if "iteration" in payload:
                    self.plot.add(payload["compliance"], payload["volume"])
                    maxit = max(1, self.study.MaxIterations)
                    self.progress.setValue(min(100, int(100 * payload["iteration"] / maxit)))
                    self.status.setText("iteration %d: compliance %.4g, volume %.3f, change %.3f" % (
                        payload["iteration"], payload["compliance"], payload["volume"], payload["change"]))
                else:
                    self.status.setText(payload.get("message", payload.get("stage", "")))
            else:
                self.timer.stop()
                self.thread = None
                self.run_button.setEnabled(True)
                self.cancel_button.setEnabled(False)
                if kind == "done":
                    runner.apply(self.study, payload)
                    from topopt.gui import display
                    display.show_density(self.study)
                    self.progress.setValue(100)
                    self.status.setText(self.study.Status)
                    self.threshold.setEnabled(True)
                else:
                    self.status.setText("stopped: %s" % payload)
                    report_error(payload)
                return

    def wait(self, seconds=600.0):
        """Blocks (processing events) until the run ends; for scripted GUI tests."""
        deadline = QtCore.QDeadlineTimer(int(seconds * 1000))
        while self.thread is not None and not deadline.hasExpired():
            QtWidgets.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
            self.poll()

    def reextract(self):
        from topopt.gui.waiting import WaitDialog
        try:
            with WaitDialog("Extracting the result shape") as wait:
                runner.reextract(self.study, self.threshold.value() / 100.0, wait.cancel)
        except TopOptError as e:
            report_error(e)

    # --- task panel protocol ---------------------------------------------------------------
    def getStandardButtons(self):
        return int(QtWidgets.QDialogButtonBox.Close)

    def reject(self):
        if self.thread is not None:
            self.request_cancel()
            self.wait(30)
        self.store_parameters()
        FreeCADGui.Control.closeDialog()
        return True


def open_study_panel(study):
    FreeCADGui.Control.closeDialog()
    panel = StudyPanel(study)
    FreeCADGui.Control.showDialog(panel)
    return panel
