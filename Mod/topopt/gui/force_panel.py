"""TopOpt's force panel: a FEM force whose direction the user always gives — a vector
(x, y, z), or the direction of a picked straight edge or the normal of a picked planar face —
never a silent default. The force is FreeCAD FEM's own constraint: FEM draws its arrows the
way TopOpt applies it (topopt.app.directions). The panel works inside an undo transaction:
OK keeps the force, Cancel takes a new one away or restores the one being edited."""
import FreeCAD
import FreeCADGui
from PySide import QtGui

from topopt.app import directions, units
from topopt.app.errors import TopOptError

PRESETS = [("+X", (1, 0, 0)), ("-X", (-1, 0, 0)), ("+Y", (0, 1, 0)), ("-Y", (0, -1, 0)), ("+Z", (0, 0, 1)),
           ("-Z", (0, 0, -1))]


def selected_faces(study):
    """[(object, "FaceN"), ...] of the selection that belong to the study's part or non-design
    solids."""
    allowed = [study.Part] + list(study.NonDesign)
    out = []
    for s in FreeCADGui.Selection.getSelectionEx():
        if s.Object in allowed:
            out += [(s.Object, n) for n in s.SubElementNames if n.startswith("Face")]
    return out


def selected_reference():
    """The first selected edge or face (object, "EdgeN"/"FaceN"), or None."""
    for s in FreeCADGui.Selection.getSelectionEx():
        for n in s.SubElementNames:
            if n.startswith("Edge") or n.startswith("Face"):
                return s.Object, n
    return None


def _spin(low, high, decimals, suffix=""):
    """A number field that shrinks with the panel (the combo view is narrow by default)."""
    w = QtGui.QDoubleSpinBox()
    w.setRange(low, high)
    w.setDecimals(decimals)
    w.setSuffix(suffix)
    w.setMinimumWidth(45)
    w.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Fixed)
    return w


class ForcePanel:
    """Task panel for FEM force `force` of `study`, opened inside an undo transaction (see
    open_force_panel)."""

    def __init__(self, study, force):
        self.study = study
        self.force = force
        self.doc = force.Document
        self.faces = [(obj, n) for obj, subs in force.References for n in subs]
        self.reference = self._current_reference()
        self.form = QtGui.QWidget()
        self.form.setObjectName("TopOptForcePanel")
        self.form.setWindowTitle("TopOpt force")
        layout = QtGui.QVBoxLayout(self.form)
        layout.addWidget(self._faces_box())
        layout.addWidget(self._force_box())
        layout.addWidget(self._direction_box())
        self.message = QtGui.QLabel("")
        self.message.setWordWrap(True)
        layout.addWidget(self.message)
        layout.addStretch(1)
        self._load()
        self._describe()

    # --- layout ----------------------------------------------------------------------------
    def _faces_box(self):
        box = QtGui.QGroupBox("Loaded faces")
        layout = QtGui.QVBoxLayout(box)
        self.face_list = QtGui.QListWidget()
        self.face_list.setMaximumHeight(70)
        layout.addWidget(self.face_list)
        row = QtGui.QHBoxLayout()
        add, remove = QtGui.QPushButton("Add selected"), QtGui.QPushButton("Remove")
        for b in (add, remove):
            b.setMinimumWidth(40)
            b.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Fixed)
        add.setToolTip("Add the faces selected in the 3D view (the study's part or non-design solids)")
        add.clicked.connect(self.add_selected_faces)
        remove.clicked.connect(self._remove_face)
        row.addWidget(add)
        row.addWidget(remove)
        layout.addLayout(row)
        return box

    def _force_box(self):
        box = QtGui.QGroupBox("Total force")
        layout = QtGui.QFormLayout(box)
        self.magnitude = _spin(0.0, 1e12, 3, " N")
        self.magnitude.setToolTip("The total force, spread over the faces by area")
        self.magnitude.valueChanged.connect(self._describe)
        layout.addRow("Magnitude", self.magnitude)
        return box

    def _direction_box(self):
        box = QtGui.QGroupBox("Direction")
        layout = QtGui.QVBoxLayout(box)
        self.by_vector = QtGui.QRadioButton("Vector (x, y, z)")
        self.by_reference = QtGui.QRadioButton("Picked edge or face")
        self.by_reference.setToolTip("Along a straight edge, or the normal of a planar face, picked in the 3D view")
        layout.addWidget(self.by_vector)
        row = QtGui.QHBoxLayout()
        self.xyz = [_spin(-1e9, 1e9, 3) for _ in range(3)]
        for w, axis in zip(self.xyz, "xyz"):
            w.setToolTip("%s component" % axis)
            w.setButtonSymbols(QtGui.QAbstractSpinBox.NoButtons)  # three in a row: room for "-1.000"
            w.valueChanged.connect(self._vector_edited)
            row.addWidget(w)
        layout.addLayout(row)
        presets = QtGui.QGridLayout()
        for i, (name, v) in enumerate(PRESETS):
            b = QtGui.QPushButton(name)
            b.setMinimumWidth(30)
            b.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Fixed)
            b.clicked.connect(lambda checked=False, v=v: self.set_vector(v))
            presets.addWidget(b, i // 3, i % 3)
        layout.addLayout(presets)
        layout.addWidget(self.by_reference)
        pick = QtGui.QPushButton("Use selection")
        pick.setToolTip("Take the direction from the straight edge or planar face selected in the 3D view")
        pick.clicked.connect(self.use_selected_reference)
        layout.addWidget(pick)
        self.reference_label = QtGui.QLabel("")
        self.reference_label.setWordWrap(True)
        layout.addWidget(self.reference_label)
        self.reverse = QtGui.QCheckBox("Reverse")
        self.reverse.toggled.connect(self._describe)
        layout.addWidget(self.reverse)
        self.by_vector.toggled.connect(self._describe)
        return box

    # --- state -----------------------------------------------------------------------------
    def _current_reference(self):
        """The force's own edge/face reference (not TopOpt's direction line), or None."""
        if directions.helper_line(self.force) is not None or not self.force.Direction:
            return None
        obj, subs = self.force.Direction
        return (obj, subs[0]) if subs else None

    def _load(self):
        for obj, n in self.faces:
            self.face_list.addItem("%s: %s" % (obj.Label, n))
        self.magnitude.setValue(units.prop(self.force, "Force", "N"))
        try:
            d = directions.direction_of(self.force)
        except TopOptError:  # no direction yet (a new force) or an unusable reference
            d = (0.0, 0.0, 0.0)
        for w, x in zip(self.xyz, d):
            w.blockSignals(True)
            w.setValue(round(x, 6))
            w.blockSignals(False)
        self.by_reference.setChecked(self.reference is not None)
        self.by_vector.setChecked(self.reference is None)
        self.reverse.setChecked(bool(self.force.Reversed) and self.reference is not None)

    def vector(self):
        return [w.value() for w in self.xyz]

    def set_vector(self, v):
        for w, x in zip(self.xyz, v):
            w.setValue(float(x))
        self.by_vector.setChecked(True)

    def _vector_edited(self, *args):
        self.by_vector.setChecked(True)
        self._describe()

    def add_selected_faces(self):
        new = [f for f in selected_faces(self.study) if f not in self.faces]
        if not new:
            self.message.setText("select faces of %s or its non-design solids in the 3D view first"
                                 % self.study.Part.Label)
        for obj, n in new:
            self.faces.append((obj, n))
            self.face_list.addItem("%s: %s" % (obj.Label, n))
        self._describe()

    def _remove_face(self):
        row = self.face_list.currentRow()
        if 0 <= row < len(self.faces):
            del self.faces[row]
            self.face_list.takeItem(row)
        self._describe()

    def use_selected_reference(self):
        ref = selected_reference()
        if ref is None:
            self.message.setText("select a straight edge or a planar face in the 3D view first")
            return
        self.reference = ref
        self.by_reference.setChecked(True)
        self._describe()

    def _describe(self, *args):
        if self.reference is not None:
            obj, n = self.reference
            self.reference_label.setText("%s of %s%s" % (n, obj.Label, ", reversed" if self.reverse.isChecked()
                                                          else ""))
        else:
            self.reference_label.setText("no edge or face picked")
        if self.by_vector.isChecked():
            v = self.vector()
            self.message.setText("%g N along (%.3g, %.3g, %.3g) on %d face(s)" % (
                self.magnitude.value(), v[0], v[1], v[2], len(self.faces)))
        else:
            self.message.setText("%g N along the picked reference on %d face(s)" % (
                self.magnitude.value(), len(self.faces)))

    # --- writing ---------------------------------------------------------------------------
    def write(self):
        """Writes the panel into the force; raises TopOptError saying what is missing."""
        if not self.faces:
            raise TopOptError("no loaded face: select faces of %s and press 'Add selected'" % self.study.Part.Label,
                              "FaceNotFound")
        if self.magnitude.value() <= 0:
            raise TopOptError("the force is zero: give its magnitude in N", "InvalidParameter")
        refs = {}
        for obj, n in self.faces:
            refs.setdefault(obj, []).append(n)
        self.force.References = [(obj, tuple(names)) for obj, names in refs.items()]
        units.set_prop(self.force, "Force", self.magnitude.value(), "N")
        if self.by_vector.isChecked():
            directions.set_vector_direction(self.force, self.vector())
        elif self.reference is None:
            raise TopOptError("no direction: type a vector (x, y, z) or pick a straight edge or a planar face",
                              "InvalidParameter")
        else:
            directions.set_reference_direction(self.force, self.reference[0], self.reference[1],
                                               self.reverse.isChecked())
        self.doc.recompute()

    # --- task panel protocol ---------------------------------------------------------------
    def getStandardButtons(self):
        return int(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)

    def accept(self):
        try:
            self.write()
        except TopOptError as e:
            self.message.setText("<b>%s</b>" % e)
            return False
        FreeCAD.Console.PrintMessage("TopOpt: %s: %s\n" % (self.force.Label, self.message.text()))
        if self.doc.HasPendingTransaction:
            self.doc.commitTransaction()
        FreeCADGui.Control.closeDialog()
        return True

    def reject(self):
        if self.doc.HasPendingTransaction:
            self.doc.abortTransaction()
        FreeCADGui.Control.closeDialog()
        self.doc.recompute()
        return True


def open_force_panel(study, force, transaction):
    """Opens the force panel for `force` inside a new undo transaction named `transaction`
    (the caller opened it before creating a new force, so that Cancel removes it)."""
    if not force.Document.HasPendingTransaction:
        force.Document.openTransaction(transaction)
    panel = ForcePanel(study, force)
    vp = getattr(study.ViewObject, "Proxy", None)
    if vp is not None:
        vp.force_panel = panel
    FreeCADGui.Control.showDialog(panel)
    return panel
