"""The study's task panel. It edits the study's own properties (the property editor shows the
same values; changes made there show here), inside an undo transaction: OK keeps the edits,
Cancel takes them back. Run runs the study as it stands (Mesh and Run on the toolbar read the
same properties), with the stage and its % in the panel and FreeCAD's status bar, a live plot
and Stop; a run and each threshold change are undo steps of their own. The threshold slider
moves the shown result only: runs never read it."""
import queue
import threading

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from topopt.app import progress, results, runner
from topopt.app.errors import TopOptError
from topopt.gui.plot import HistoryPlot

EDIT = "Edit TopOpt study"


def report_error(e):
    """Shows a TopOpt error in the report view (and a message box when the GUI is visible)."""
    FreeCAD.Console.PrintError("TopOpt: %s\n" % e)
    if getattr(e, "details", ""):  # the worker's last words, for a bug report
        FreeCAD.Console.PrintLog("TopOpt worker output:\n%s\n" % e.details)
    mw = FreeCADGui.getMainWindow()
    if mw is not None and mw.isVisible() and not FreeCAD.ConfigGet("TopOptNoDialogs"):
        QtGui.QMessageBox.warning(mw, "TopOpt", str(e))


class _StatusLine(QtGui.QLabel):
    """A word-wrapped line of the panel that takes no room while it says nothing (the panel
    is long enough in the default combo view)."""

    def __init__(self, text=""):
        super().__init__()
        self.setWordWrap(True)  # an error says what to try: all of it must show
        self.setText(text)

    def setText(self, text):
        super().setText(text)
        self.setVisible(bool(text))


class _Binding:
    """One study property edited by one widget: `get(widget)` reads the widget, `put(widget,
    value)` shows a property value, `changed` is the widget's signal."""

    def __init__(self, prop, widget, get, put, changed):
        self.prop, self.widget, self.get, self.put, self.changed = prop, widget, get, put, changed

    def show(self, study):
        self.widget.blockSignals(True)
        try:
            self.put(self.widget, getattr(study, self.prop))
        finally:
            self.widget.blockSignals(False)


def _spin(low, high, step, decimals, suffix="", special=""):
    w = QtGui.QDoubleSpinBox()
    w.setRange(low, high)
    w.setSingleStep(step)
    w.setDecimals(decimals)
    w.setSuffix(suffix)
    w.setSpecialValueText(special)
    return w


def _int_spin(low, high, special=""):
    w = QtGui.QSpinBox()
    w.setRange(low, high)
    w.setSpecialValueText(special)
    return w


def _bindings():
    """The study properties the panel edits, with their widgets."""
    mesher = QtGui.QComboBox()
    mesher.addItems(["auto", "native", "gmsh"])
    mesher.setToolTip("auto: the two-B-Rep advancing front, Gmsh where it cannot close a mesh; "
                      "native: the advancing front only; gmsh: OCC fragments meshed by Gmsh")
    layers = _int_spin(0, 4, "off")
    layers.setToolTip("Element layers across walls thinner than two mesh sizes (native mesher); one layer "
                      "of tets is far too stiff in bending, more layers mean more elements")
    volume = _spin(0.01, 0.99, 0.05, 2)
    volume.setToolTip("Share of the design domain's volume to keep")
    size = _spin(0.0, 1e4, 0.5, 2, " mm", "automatic")
    size.setToolTip("Target element size; automatic: the part's bounding-box diagonal / 50")
    iterations = _int_spin(1, 10000)
    iterations.setToolTip("Iteration cap: the optimisation stops there if it has not converged before")
    keep = QtGui.QCheckBox("Keep loaded faces")  # its own label: the label column stays narrow
    keep.setToolTip("Keep the material under every supported and loaded face (one element layer stays solid); "
                    "off: the optimisation may remove it, and the verification then stops naming the face")
    join = QtGui.QCheckBox("Join non-design solids")
    join.setToolTip("Join every non-design solid the design leaves apart to the part by a bridge through the "
                    "design, so the result is one piece; off: such a solid stays apart, named in a warning")
    return [
        _Binding("VolumeFraction", volume, lambda w: w.value(), lambda w, v: w.setValue(float(v)),
                 volume.valueChanged),
        _Binding("MaxIterations", iterations, lambda w: w.value(), lambda w, v: w.setValue(int(v)),
                 iterations.valueChanged),
        _Binding("MeshSize", size, lambda w: w.value(), lambda w, v: w.setValue(float(v)), size.valueChanged),
        _Binding("Mesher", mesher, lambda w: w.currentText(), lambda w, v: w.setCurrentText(str(v)),
                 mesher.currentIndexChanged),
        _Binding("WallLayers", layers, lambda w: w.value(), lambda w, v: w.setValue(int(v)), layers.valueChanged),
        _Binding("KeepLoadedFaces", keep, lambda w: w.isChecked(), lambda w, v: w.setChecked(bool(v)), keep.toggled),
        _Binding("JoinNonDesign", join, lambda w: w.isChecked(), lambda w, v: w.setChecked(bool(v)), join.toggled),
    ]


#: the settings' labels, short: in the default combo view width the label column and the fields
#: share about 200 px, and a field narrower than its value shows it cut (tests/python/gui)
_LABELS = {"VolumeFraction": "Volume fraction", "MaxIterations": "Iterations", "MeshSize": "Mesh size",
           "Mesher": "Mesher", "WallLayers": "Wall layers"}


class _StudyObserver:
    """Tells the panel when the study changes elsewhere (property editor, undo)."""

    def __init__(self, panel):
        self.panel = panel

    def slotChangedObject(self, obj, prop):
        if obj == self.panel.study and self.panel.is_open():
            self.panel.property_changed(prop)


class StudyPanel:
    """Task panel of a study. A run is the worker process (topopt.app.worker), followed from a
    thread of this panel; the document is only touched here, in the GUI thread, when the run
    has succeeded. Stop kills the worker at once, even one that has gone silent."""

    def __init__(self, study):
        self.study = study
        self.doc = study.Document
        self.thread = None
        self.messages = queue.Queue()
        self.cancel_requested = False
        self.tracker = None
        self.verifying = False  # the result is shown; the worker still verifies it
        self.verify_started = 0.0
        self.status_bar = None
        self.writing = False
        self.closed = False
        self.volume_data = None
        self.bindings = _bindings()
        self.form = self._build()
        for b in self.bindings:
            b.show(study)
            b.changed.connect(lambda *args, b=b: self._write(b))
        self._show_result_state()
        self.observer = _StudyObserver(self)
        FreeCAD.addDocumentObserver(self.observer)
        self._begin_edit()

    # --- layout ----------------------------------------------------------------------------
    def _build(self):
        form = QtGui.QWidget()
        form.setObjectName("TopOptStudyPanel")
        form.setWindowTitle("TopOpt study")
        layout = QtGui.QVBoxLayout(form)
        self.summary = QtGui.QLabel(self._summary_text())
        self.summary.setWordWrap(True)
        layout.addWidget(self.summary)
        layout.addWidget(self._settings_box())
        # Run and Result next to the settings every study needs, so they show without scrolling
        # in the default combo view; the optional controls and objectives follow below them
        layout.addWidget(self._run_box())
        layout.addWidget(self._result_box())
        from topopt.gui.controls_panel import ControlsBox, ResponsesBox
        self.controls = ControlsBox(self.study)
        self.responses = ResponsesBox(self.study)
        layout.addWidget(self.controls.box)
        layout.addWidget(self.controls.process.box)
        layout.addWidget(self.responses.box)
        layout.addStretch(1)
        return form

    def _settings_box(self):
        box = QtGui.QGroupBox("Settings")
        grid = QtGui.QFormLayout(box)
        grid.setRowWrapPolicy(QtGui.QFormLayout.WrapLongRows)
        grid.setFieldGrowthPolicy(QtGui.QFormLayout.AllNonFixedFieldsGrow)
        for b in self.bindings:
            if b.prop in _LABELS:
                b.widget.setMinimumWidth(60)
                grid.addRow(_LABELS[b.prop], b.widget)
            else:  # a check box, labelled itself
                grid.addRow(b.widget)
        return box

    def _run_box(self):
        box = QtGui.QGroupBox("Run")
        layout = QtGui.QVBoxLayout(box)
        buttons = QtGui.QHBoxLayout()
        self.run_button = QtGui.QPushButton("Run")
        self.run_button.setToolTip("Mesh, optimise and show the result (uses the settings above)")
        self.cancel_button = QtGui.QPushButton("Stop")
        self.cancel_button.setToolTip("Stop the run; the document stays as it was before it")
        self.cancel_button.setEnabled(False)
        buttons.addWidget(self.run_button)
        buttons.addWidget(self.cancel_button)
        layout.addLayout(buttons)
        self.progress = QtGui.QProgressBar()
        self.progress.setRange(0, 100)
        self.progress.setToolTip("Meshing, then the optimisation: estimated from the iteration cap and how "
                                 "close the compliance is to converging")
        layout.addWidget(self.progress)
        self.status = _StatusLine(self.study.Status or "")
        layout.addWidget(self.status)
        self.verify_status = _StatusLine(_verification_text(self.study))
        self.verify_status.setToolTip("The verification of the result solid (the study's Verify): it runs after "
                                      "the result is shown; Stop during it stops the verification only")
        layout.addWidget(self.verify_status)
        self.plot = HistoryPlot()
        layout.addWidget(self.plot)
        self._show_history()
        self.run_button.clicked.connect(self.start_run)
        self.cancel_button.clicked.connect(self.request_cancel)
        self.timer = QtCore.QTimer()
        self.timer.setInterval(100)
        self.timer.timeout.connect(self.poll)
        return box

    def _result_box(self):
        box = QtGui.QGroupBox("Result")
        layout = QtGui.QVBoxLayout(box)
        row = QtGui.QHBoxLayout()
        row.addWidget(QtGui.QLabel("Threshold"))
        self.threshold = QtGui.QSlider(QtCore.Qt.Horizontal)
        self.threshold.setRange(1, 99)
        self.threshold.setToolTip("Density threshold of the result shape; moves the shown result only, never "
                                  "the next run")
        row.addWidget(self.threshold)
        layout.addLayout(row)
        self.threshold_label = QtGui.QLabel("")
        self.threshold_label.setWordWrap(True)
        layout.addWidget(self.threshold_label)
        self.threshold.valueChanged.connect(self._show_threshold)
        self.threshold.sliderReleased.connect(self.reextract)
        return box

    def _summary_text(self):
        s = self.study
        return "Part: %s · non-design solids: %d · supports and loads: %d" % (
            s.Part.Label if s.Part else "(none)", len(s.NonDesign), len(s.Constraints))

    # --- the study's properties ------------------------------------------------------------
    def _begin_edit(self):
        """Opens the panel's undo transaction for property edits unless one is open."""
        if not self.doc.HasPendingTransaction:
            self.doc.openTransaction(EDIT)

    def _commit(self):
        if self.doc.HasPendingTransaction:
            self.doc.commitTransaction()
        _close_application_transaction(False)

    def _write(self, binding):
        self._begin_edit()
        self.writing = True
        try:
            setattr(self.study, binding.prop, binding.get(binding.widget))
        except Exception as e:  # a value the property refuses: show the study's value again
            FreeCAD.Console.PrintError("TopOpt: %s: %s\n" % (binding.prop, e))
            binding.show(self.study)
        finally:
            self.writing = False

    def property_changed(self, prop):
        """The study changed (property editor, undo, a run): show it."""
        if self.writing:
            return
        for b in self.bindings:
            if b.prop == prop:
                b.show(self.study)
        if prop == "GeometryControls":
            self.controls.show()
        if prop == "Responses":
            self.responses.show()
        if prop in ("Constraints", "Part", "NonDesign"):
            self.summary.setText(self._summary_text())
        if prop in ("Densities", "Threshold", "MeshTets"):
            self.volume_data = None
            self._show_result_state()
        if prop in ("ComplianceHistory", "VolumeHistory") and self.thread is None:
            self._show_history()

    def _show_history(self):
        """The plot of the study's last run; hidden while the study has none (the panel is long
        enough in the default combo view)."""
        self.plot.set_history(self.study.ComplianceHistory, self.study.VolumeHistory)
        self.plot.setVisible(bool(self.study.ComplianceHistory))

    # --- running ---------------------------------------------------------------------------
    def _set_running(self, running):
        self.run_button.setEnabled(not running)
        self.cancel_button.setEnabled(running)
        self.threshold.setEnabled(not running and bool(self.study.Densities))
        for b in self.bindings:
            b.widget.setEnabled(not running)

    def apply_controls(self):
        """Writes the design controls and the objective and limits to the study (checked as a
        job file is). Returns False, after saying what is wrong, when a value is refused."""
        self._begin_edit()
        self.writing = True
        try:
            self.controls.apply()
            self.responses.apply()
        except TopOptError as e:
            report_error(e)
            return False
        finally:
            self.writing = False
        return True

    def start_run(self):
        if self.thread is not None:
            return
        if not self.apply_controls():
            return
        self._commit()  # the settings the run uses are one undo step
        try:
            prepared = runner.prepare(self.study)
        except TopOptError as e:
            self._begin_edit()
            report_error(e)
            return
        self.cancel_requested = False
        self.tracker = progress.Tracker("optimize", prepared.max_iterations)
        from topopt.gui.statusbar import StatusProgress
        self.status_bar = StatusProgress()
        self.plot.set_history([], [])
        self.plot.show()  # its axes wait for the first iteration
        self.progress.setValue(0)
        self._set_running(True)
        self.status.setText("starting…")
        FreeCAD.Console.PrintMessage("TopOpt: running %s\n" % self.study.Label)
        self.thread = threading.Thread(target=self._work, args=(prepared,), daemon=True)
        self.thread.start()
        self.timer.start()

    def _work(self, prepared):
        def on_progress(record):
            self.messages.put(("progress", record))
            return self.cancel_requested

        def on_result(result):  # result first, the verification after (the study's Verify)
            self.messages.put(("result", (result, self.tracker.clock())))  # when the worker said so
        try:
            self.messages.put(("done", runner.execute(prepared, on_progress, lambda: self.cancel_requested,
                                                      on_result)))
        except TopOptError as e:
            self.messages.put(("error", e))
        except Exception as e:  # never let a worker exception vanish
            self.messages.put(("error", TopOptError("unexpected failure: %s" % e)))

    def request_cancel(self):
        self.cancel_requested = True
        (self.verify_status if self.verifying else self.status).setText("stopping…")

    def poll(self):
        while True:
            try:
                kind, payload = self.messages.get_nowait()
            except queue.Empty:
                return
            if kind == "progress":
                self._show_progress(payload)
            elif kind == "result":
                self._show_result_first(*payload)
            else:
                self._finish(kind, payload)
                return

    def _show_progress(self, record):
        self.tracker.update(record)
        if "iteration" in record:
            self.plot.add(record["compliance"], record["volume"])
        self.status_bar.show(self.tracker.fraction, self.tracker.label)
        if self.verifying:  # the result is shown: the verification has its own line
            self.verify_status.setText("verification: %s" % self.tracker.label)
            return
        self.progress.setValue(self.tracker.percent())
        self.status.setText(self.tracker.label)

    def _finish(self, kind, payload):
        self.timer.stop()
        self.thread = None
        self.tracker.finish()
        if self.verifying:
            self._finish_verification(kind, payload)
        elif kind == "done":
            self._apply(payload)
        elif payload.code == "Cancelled" and self.cancel_requested:
            self.status.setText("stopped (%s); the document is as it was" % payload)
            self.status_bar.done("run stopped")
            FreeCAD.Console.PrintMessage("TopOpt: run of %s stopped: %s\n" % (self.study.Label, payload))
        else:
            self.status.setText("failed: %s" % payload)
            self.status_bar.done("run failed")
            report_error(payload)
        self._set_running(False)
        self._begin_edit()

    def _apply(self, result):
        try:
            with self.tracker.timed("document"):
                with runner.transaction(self.doc, "TopOpt run"):
                    runner.apply(self.study, result)
        except TopOptError as e:
            report_error(e)
            return False
        seconds = self.tracker.clock() - self.tracker.started
        runner.report_run(self.study, result, self.tracker, seconds)
        self.progress.setValue(100)
        self.status.setText("%s in %.0f s" % (self.study.Status, seconds))
        self.status_bar.done("%s: %s in %.0f s" % (self.study.Label, self.study.Status, seconds))
        self.volume_data = None
        self._show_result_state()
        return True

    def _show_result_first(self, result, ready):
        """The result is written and the worker goes on to verify it: the result is applied and
        shown now (its own undo step), the study is usable again (settings, threshold), and
        Stop now stops the verification only. ready: the tracker's clock when the worker
        said the result was written (the verification's start)."""
        if not self._apply(result):  # the document refused the result: no verification of it either
            self.request_cancel()
            return
        self.verifying = True
        self.verify_started = ready
        self._set_running(False)
        self.run_button.setEnabled(False)  # one worker at a time: Run again after the verification
        self.cancel_button.setEnabled(True)
        self.cancel_button.setText("Stop verification")
        self.verify_status.setText("verification: meshing and analysing the result solid…")
        self._begin_edit()

    def _finish_verification(self, kind, payload):
        """The verification after the shown result ended: its files and FEM objects kept (an
        undo step, "TopOpt verification"), or stopped or failed, the result staying."""
        self.verifying = False
        self.cancel_button.setText("Stop")
        seconds = self.tracker.clock() - self.verify_started
        label = self.study.Label
        if kind == "done":
            self._commit()
            try:
                with runner.transaction(self.doc, "TopOpt verification"):
                    runner.apply_verification(self.study, payload)
            except TopOptError as e:
                self.verify_status.setText("verification failed: %s; the result stays" % e)
                report_error(e)
                return
            from topopt.app import asbuilt
            lines = ["TopOpt: verification of %s in %.0f s" % (label, seconds)] + asbuilt.summary_lines(self.study)
            FreeCAD.Console.PrintMessage("\n".join(lines) + "\n")
            self.verify_status.setText(_verification_text(self.study, seconds))
            self.status_bar.done("%s: verified in %.0f s" % (label, seconds))
        elif payload.code == "Cancelled" and self.cancel_requested:
            self.verify_status.setText("verification stopped; the result stays")
            self.status_bar.done("verification stopped")
            FreeCAD.Console.PrintMessage("TopOpt: verification of %s stopped; the result stays\n" % label)
        else:
            self.verify_status.setText("verification failed: %s; the result stays" % payload)
            self.status_bar.done("verification failed")
            report_error(payload)

    def wait(self, seconds=600.0):
        """Blocks (processing events) until the run ends; for scripted GUI tests."""
        deadline = QtCore.QDeadlineTimer(int(seconds * 1000))
        while self.thread is not None and not deadline.hasExpired():
            QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
            self.poll()

    # --- the result's threshold ------------------------------------------------------------
    def _stored(self):
        """(nodes, tets, domain, densities) of the study's last run, read once; None if none."""
        if self.volume_data is None and self.study.Densities:
            from topopt.app import checks
            try:
                self.volume_data = checks.stored_mesh(self.study)
            except TopOptError:
                self.volume_data = None
        return self.volume_data

    def _show_result_state(self):
        """The slider at the shown result's threshold (the run's, or where the slider left it)."""
        data = self._stored()
        self.threshold.setEnabled(data is not None and (self.thread is None or self.verifying))
        t = float(self.study.Threshold)
        if data is not None and not 0 < t < 1:  # a document of an older version
            t = results.volume_threshold(data[0], data[1], data[2], data[3], float(self.study.VolumeFraction))
        self.threshold.blockSignals(True)
        self.threshold.setValue(int(round(100 * t)) if 0 < t < 1 else 50)
        self.threshold.blockSignals(False)
        self._show_threshold(self.threshold.value())

    def _show_threshold(self, value):
        data = self._stored()
        if data is None:
            self.threshold_label.setText("no result yet: run the study")
            return
        kept = results.kept_volume_fraction(data[0], data[1], data[2], data[3], value / 100.0)
        self.threshold_label.setText("%.2f: keeps %.0f %% of the design domain" % (value / 100.0, 100 * kept))

    def reextract(self):
        """Re-extracts the result at the slider's threshold (one undo step)."""
        from topopt.gui.waiting import WaitDialog
        t = self.threshold.value() / 100.0
        if abs(t - float(self.study.Threshold)) < 0.005:
            return
        self._commit()
        try:
            with WaitDialog("Extracting the result shape", "extract_surface") as wait:
                runner.reextract(self.study, t, wait.cancel)
        except TopOptError as e:
            if not (e.code == "Cancelled"):
                report_error(e)
            self._show_result_state()
        self._begin_edit()

    # --- task panel protocol ---------------------------------------------------------------
    def getStandardButtons(self):
        return int(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)

    def is_open(self):
        """True until the panel is closed, by OK or Cancel or by FreeCAD (which drops `form`
        when it closes a task dialog without asking it, e.g. for another command's panel)."""
        return not self.closed and getattr(self, "form", None) is not None

    def _close(self):
        self.closed = True
        FreeCAD.removeDocumentObserver(self.observer)
        FreeCADGui.Control.closeDialog()
        vp = getattr(self.study.ViewObject, "Proxy", None)
        if getattr(vp, "panel", None) is self:
            vp.panel = None

    def accept(self):
        """OK: keeps the edits (one undo step). A run still going is stopped first. A design
        control or limit the study refuses keeps the panel open, saying what to fix."""
        self._stop_run()
        if not self.apply_controls():
            return False
        self._commit()
        self._close()
        return True

    def reject(self):
        """Cancel: takes back the edits made since the panel opened (or since the last run or
        threshold change, which are undo steps of their own). A run still going is stopped."""
        self._stop_run()
        if self.doc.HasPendingTransaction:
            self.doc.abortTransaction()
        _close_application_transaction(True)
        self._close()
        return True

    def _stop_run(self):
        if self.thread is not None:
            self.request_cancel()
            self.wait(30)


def _verification_text(study, seconds=None):
    """The verification's line: its figures, why it failed, or nothing when none ran."""
    from topopt.app import asbuilt
    report = asbuilt.verification_report(study)
    took = " in %.0f s" % seconds if seconds is not None else ""
    if "compliance_as_built" in report:
        if not report.get("crisp_carries_load", True):
            compared = "the crisp design on the FE mesh does not carry the load: not converged"
        else:
            compared = "%.3g × the crisp design's" % report.get("ratio", 0.0)
        return "verified%s: as-built compliance %.4g N·mm (%s), max von Mises %.4g MPa" % (
            took, report["compliance_as_built"], compared, report.get("max_von_mises", 0.0))
    failed = report.get("failed", {}).get("verification")
    if failed:
        return "verification failed: %s" % failed.get("message", "")
    return ""


def _close_application_transaction(abort):
    """Ends the application's active transaction that doc.openTransaction started. FreeCAD
    keeps it open when nothing changed (the document then has no pending transaction), and a
    document made afterwards would put its new objects into it: Cancel would delete them."""
    name = FreeCAD.getActiveTransaction() if hasattr(FreeCAD, "getActiveTransaction") else None
    if name and name[0] == EDIT:
        FreeCAD.closeActiveTransaction(abort)


def open_study_panel(study):
    """Opens the study's panel (closing any other task dialog first, as FreeCAD allows one)."""
    close_study_panel(study)
    FreeCADGui.Control.closeDialog()
    panel = StudyPanel(study)
    vp = getattr(study.ViewObject, "Proxy", None)
    if vp is not None:
        vp.panel = panel
    FreeCADGui.Control.showDialog(panel)
    return panel


def close_study_panel(study):
    """Closes the study's panel if it is open, keeping its edits (as OK does). Returns False
    when it cannot be closed because a run is going."""
    vp = getattr(getattr(study, "ViewObject", None), "Proxy", None)
    panel = getattr(vp, "panel", None)
    if panel is not None and not panel.is_open() and not panel.closed:  # closed by FreeCAD, not by us
        panel.closed = True
        FreeCAD.removeDocumentObserver(panel.observer)
    if panel is None or panel.closed:
        return True
    if panel.thread is not None:
        return False
    panel.accept()
    return True
