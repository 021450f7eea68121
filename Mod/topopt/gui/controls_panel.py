"""The study panel's design controls and responses: symmetry planes (from a picked planar
face or datum plane), cyclic repetition (axis from a picked cylindrical face or edge), a
linear pattern, an extrusion direction (typed or picked), a draw direction (one-sided or
split casting), an overhang limit (build direction, angle, picked base face), the smallest
and largest member size, the objective and its limits
(compliance, stress, displacement on picked faces along a direction). The widgets show the
study's GeometryControls and Responses; apply() writes them through api.set_controls and
api.set_responses, which check every value as a job file is checked (a bad value raises a
TopOptError naming it, and the study is left as it was)."""
import FreeCADGui
from PySide import QtCore, QtGui

from topopt.app import api, picking
from topopt.app import job as jobmod
from topopt.app.errors import TopOptError


def selection():
    """[(obj, sub)] of FreeCAD's selection: each picked sub-element, or the object itself
    (a datum plane or line picked in the tree)."""
    out = []
    for s in FreeCADGui.Selection.getSelectionEx():
        subs = [n for n in s.SubElementNames if n] or [""]
        out += [(s.Object, n) for n in subs]
    return out


def _picked(what):
    picked = selection()
    if not picked:
        raise TopOptError("nothing is selected: pick %s in the 3D view first" % what, "InvalidParameter")
    return picked


def _pick_direction(entry, switch):
    """Sets the direction `entry` from the first selected planar face (its normal) or straight
    edge and checks `switch`, the control it belongs to. Raises TopOptError naming what was
    picked otherwise (or that nothing was)."""
    obj, sub = _picked("a planar face or a straight edge")[0]
    entry.set(picking.direction_of(obj, sub))
    switch.setChecked(True)


def _number(low, high, decimals, suffix="", special="", min_width=50):
    """A number field that the layout may shrink down to min_width pixels (its value and unit
    must still show there)."""
    w = QtGui.QDoubleSpinBox()
    w.setRange(low, high)
    w.setDecimals(decimals)
    w.setSuffix(suffix)
    w.setSpecialValueText(special)
    # a spin box asks for the width of its longest value (-1e9 with decimals): let the layout
    # shrink it, so that the panel fits FreeCAD's default combo view
    w.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Fixed)
    w.setMinimumWidth(min_width)
    return w


class VectorEdit(QtGui.QWidget):
    """Three number fields (x, y, z)."""

    def __init__(self, value=(0.0, 0.0, 1.0)):
        super().__init__()
        layout = QtGui.QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.fields = [_number(-1e6, 1e6, 3) for _ in range(3)]
        for f, axis in zip(self.fields, "xyz"):
            f.setToolTip("%s component" % axis)
            f.setButtonSymbols(QtGui.QAbstractSpinBox.NoButtons)  # three in a row: room for "-1.000"
            layout.addWidget(f)
        self.set(value)

    def set(self, value):
        for f, x in zip(self.fields, value):
            f.setValue(float(x))

    def value(self):
        return [f.value() for f in self.fields]


def _fmt(v):
    return "(%s)" % ", ".join("%.4g" % (x + 0.0) for x in v)  # + 0.0: no "-0"


class _ItemList:
    """A list widget whose rows stand for items (dicts) kept beside it."""

    def __init__(self, describe):
        self.widget = QtGui.QListWidget()
        self.widget.setMaximumHeight(64)
        self.widget.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Preferred)
        self.widget.setWordWrap(True)  # the panel is narrow: rows wrap instead of scrolling sideways
        self.widget.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarAlwaysOff)
        self.describe = describe
        self.items = []

    def set(self, items):
        self.items = list(items)
        self.widget.clear()
        for item in self.items:
            self.widget.addItem(self.describe(item))

    def add(self, item):
        self.set(self.items + [item])

    def remove_selected(self):
        rows = sorted({i.row() for i in self.widget.selectedIndexes()}, reverse=True)
        items = list(self.items)
        for r in rows:
            del items[r]
        self.set(items)


def _buttons(*pairs):
    row = QtGui.QHBoxLayout()
    out = []
    for text, tip in pairs:
        b = QtGui.QPushButton(text)
        b.setToolTip(tip)
        row.addWidget(b)
        out.append(b)
    return row, out


class ControlsBox:
    """The "Design controls" group: symmetry planes, cyclic repetition, a pattern, extrusion."""

    def __init__(self, study):
        self.study = study
        self.box = QtGui.QGroupBox("Design controls")
        layout = QtGui.QFormLayout(self.box)
        layout.setRowWrapPolicy(QtGui.QFormLayout.WrapLongRows)
        self.planes = _ItemList(lambda p: "through %s, normal %s" % (_fmt(p["point"]), _fmt(p["normal"])))
        layout.addRow(QtGui.QLabel("Symmetry planes"))
        layout.addRow(self.planes.widget)
        row, (add, rem) = _buttons(("Add plane", "Add the plane of the selected planar face or datum plane (pick it first)"),
                                   ("Remove", "Remove the selected symmetry plane"))
        add.clicked.connect(self._guard(self.add_plane))
        self.add_plane_button = add
        rem.clicked.connect(self.planes.remove_selected)
        layout.addRow(row)
        self.cyclic = _ItemList(lambda c: "%d sectors about %s through %s" % (c["sectors"], _fmt(c["axis"]),
                                                                              _fmt(c["point"])))
        layout.addRow(QtGui.QLabel("Cyclic"))
        layout.addRow(self.cyclic.widget)
        self.sectors = QtGui.QSpinBox()
        self.sectors.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Fixed)
        self.sectors.setRange(2, 360)
        self.sectors.setValue(4)
        layout.addRow("Sectors", self.sectors)
        row, (add, rem) = _buttons(("Add axis", "Repeat the design about the axis of the selected cylindrical face "
                                    "or edge (pick it first), in the sectors above"), ("Remove", "Remove the selected cyclic "
                                                                            "repetition"))
        add.clicked.connect(self._guard(self.add_cyclic))
        self.add_cyclic_button = add
        rem.clicked.connect(self.cyclic.remove_selected)
        layout.addRow(row)
        self._pattern_rows(layout)
        self._extrusion_rows(layout)
        self.process = ProcessBox(study)
        self.show()

    def _pattern_rows(self, layout):
        self.pattern_on = QtGui.QCheckBox("Linear pattern")
        self.pattern_dir = VectorEdit((1, 0, 0))
        self.pattern_pitch = _number(0, 1e6, 3, " mm")
        self.pattern_count = QtGui.QSpinBox()
        self.pattern_count.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Fixed)
        self.pattern_count.setRange(2, 10000)
        layout.addRow(self.pattern_on)
        layout.addRow("Direction", self.pattern_dir)
        layout.addRow("Pitch", self.pattern_pitch)
        layout.addRow("Copies", self.pattern_count)

    def _extrusion_rows(self, layout):
        self.extrusion_on = QtGui.QCheckBox("Extrusion")
        self.extrusion_on.setToolTip("A constant cross-section along the direction below")
        self.extrusion_dir = VectorEdit((0, 0, 1))
        pick = QtGui.QPushButton("From selection")
        pick.setToolTip("The normal of the selected planar face or the direction of the selected straight edge")
        pick.clicked.connect(self._guard(self.pick_extrusion))
        layout.addRow(self.extrusion_on)
        layout.addRow("Direction", self.extrusion_dir)
        layout.addRow(pick)

    @staticmethod
    def _guard(f):
        def run(*args):
            try:
                f()
            except TopOptError as e:
                from topopt.gui.panels import report_error
                report_error(e)
        return run

    def add_plane(self):
        for obj, sub in _picked("a planar face or a datum plane"):
            point, normal = picking.plane_of(obj, sub)
            self.planes.add({"point": point, "normal": normal})

    def add_cyclic(self):
        for obj, sub in _picked("a cylindrical face or an edge"):
            point, axis = picking.axis_of(obj, sub)
            self.cyclic.add({"point": point, "axis": axis, "sectors": self.sectors.value()})

    def pick_extrusion(self):
        _pick_direction(self.extrusion_dir, self.extrusion_on)

    def show(self):
        """Shows the study's GeometryControls."""
        c = jobmod.study_controls(self.study)
        self.planes.set(c.get("symmetry_planes", []))
        self.cyclic.set(c.get("cyclic", []))
        patterns = c.get("patterns", [])
        self.pattern_on.setChecked(bool(patterns))
        if patterns:
            self.pattern_dir.set(patterns[0]["direction"])
            self.pattern_pitch.setValue(float(patterns[0]["pitch"]))
            self.pattern_count.setValue(int(patterns[0]["count"]))
        self.extrusion_on.setChecked("extrusion" in c)
        if "extrusion" in c:
            self.extrusion_dir.set(c["extrusion"])
        self.tolerance = float(c.get("tolerance", 0.0))
        self.process.show(c)

    def apply(self):
        """Writes the controls to the study (api.set_controls: checked; raises TopOptError)."""
        patterns = [(self.pattern_dir.value(), self.pattern_pitch.value(), self.pattern_count.value())] \
            if self.pattern_on.isChecked() else []
        return api.set_controls(
            self.study, symmetry_planes=[(p["point"], p["normal"]) for p in self.planes.items],
            cyclic=[(c["point"], c["axis"], c["sectors"]) for c in self.cyclic.items], patterns=patterns,
            extrusion=self.extrusion_dir.value() if self.extrusion_on.isChecked() else None,
            tolerance=self.tolerance, **self.process.arguments())


class ProcessBox:
    """The "Manufacturing" group: a draw direction (one-sided or split casting,
    typed or picked), an overhang limit (build direction typed or picked, angle, a picked base
    face) and the smallest and largest member size. arguments() gives them as api.set_controls'
    keyword arguments; the grid cells, which the panel does not edit, are kept as the study has
    them."""

    def __init__(self, study):
        self.study = study
        self.box = QtGui.QGroupBox("Manufacturing")
        layout = QtGui.QFormLayout(self.box)
        layout.setRowWrapPolicy(QtGui.QFormLayout.WrapLongRows)
        self._draw_rows(layout)
        self._overhang_rows(layout)
        self._member_rows(layout)
        self.show(jobmod.study_controls(study))

    def _draw_rows(self, layout):
        self.draw_on = QtGui.QCheckBox("Draw direction")
        self.draw_on.setToolTip("Casting, forging, milling: every line along the direction meets the design in "
                                "one stretch, so a die can be drawn off it")
        self.draw_kind = QtGui.QComboBox()
        self.draw_kind.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Fixed)
        self.draw_kind.addItems(["one-sided", "split"])
        self.draw_kind.setToolTip("one-sided: one die drawn along the direction; split: two dies drawn apart "
                                  "from the parting plane through the point below, normal to the direction")
        self.draw_dir = VectorEdit((0, 0, 1))
        self.parting_point = VectorEdit((0, 0, 0))
        self.parting_point.setToolTip("A point of the parting plane (split casting), mm")
        row, (pick_dir, pick_point) = _buttons(
            ("Pick direction", "The draw direction from the selected planar face (its normal) or straight edge"),
            ("Pick point", "The parting plane's point from the selected vertex, or the centre of the selected face "
             "or edge"))
        pick_dir.clicked.connect(ControlsBox._guard(self.pick_draw))
        pick_point.clicked.connect(ControlsBox._guard(self.pick_parting_point))
        self.draw_kind.currentIndexChanged.connect(lambda *a: self.parting_point.setEnabled(self.split()))
        layout.addRow(self.draw_on)
        layout.addRow("Dies", self.draw_kind)
        layout.addRow("Direction", self.draw_dir)
        layout.addRow("Parting point", self.parting_point)
        layout.addRow(row)

    def _overhang_rows(self, layout):
        self.overhang_on = QtGui.QCheckBox("Overhang limit")
        self.overhang_on.setToolTip("Additive manufacturing: the design prints without supports when built "
                                    "along the direction below, from the base plate up")
        self.build_dir = VectorEdit((0, 0, 1))
        self.overhang_angle = _number(10, 80, 1, "°")
        self.overhang_angle.setToolTip("The smallest angle to the base plate at which a downward-facing surface "
                                       "still prints (10° to 80°; 45° usual)")
        self.base_face = QtGui.QLabel()
        self.base_face.setWordWrap(True)
        self.base_face.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Preferred)
        row, (pick_dir, pick_face) = _buttons(
            ("Pick direction", "The build direction from the selected planar face (its normal) or straight edge"),
            ("Pick base face", "The selected face of the part stands on the base plate (flat, facing against "
             "the build direction)"))
        pick_dir.clicked.connect(ControlsBox._guard(self.pick_build))
        pick_face.clicked.connect(ControlsBox._guard(self.pick_base_face))
        clear = QtGui.QPushButton("Clear")
        clear.setToolTip("No base face: the plate touches the part's lowest point")
        clear.clicked.connect(lambda: self._show_base_face(None))
        face_row = QtGui.QHBoxLayout()
        face_row.addWidget(self.base_face, 1)
        face_row.addWidget(clear)
        layout.addRow(self.overhang_on)
        layout.addRow("Build direction", self.build_dir)
        layout.addRow("Angle", self.overhang_angle)
        layout.addRow("Base face", face_row)
        layout.addRow(row)

    def _member_rows(self, layout):
        self.min_member = _number(0, 1e6, 2, " mm", "none", 95)
        self.min_member.setToolTip("The thinnest member and gap of the design (at least 2 mesh sizes; sets the "
                                   "filter radius, so the study's FilterRadius must be 0)")
        self.max_member = _number(0, 1e6, 2, " mm", "none", 95)
        self.max_member.setToolTip("The widest solid ball the design may hold (at least 3 mesh sizes; needs "
                                   "MMA: the study's Update becomes mma)")
        layout.addRow("Min member size", self.min_member)
        layout.addRow("Max member size", self.max_member)

    def split(self):
        """True for split casting (two dies, a parting plane), False for one-sided."""
        return self.draw_kind.currentText() == "split"

    def pick_draw(self):
        """The draw direction from the first selected planar face (normal) or straight edge;
        turns the draw direction on. Raises TopOptError naming what was picked otherwise."""
        _pick_direction(self.draw_dir, self.draw_on)

    def pick_parting_point(self):
        """The parting plane's point from the first selected vertex (or a face's or edge's
        centre); makes the draw direction a split one. Raises TopOptError when nothing fits."""
        obj, sub = _picked("a vertex, an edge or a face")[0]
        self.parting_point.set(picking.point_of(obj, sub))
        self.draw_kind.setCurrentText("split")
        self.draw_on.setChecked(True)

    def pick_build(self):
        """The build direction from the first selected planar face (normal) or straight edge;
        turns the overhang limit on. Raises TopOptError naming what was picked otherwise."""
        _pick_direction(self.build_dir, self.overhang_on)

    def pick_base_face(self):
        """The base plate's face ("FaceN") from the first selected face of the study's part;
        turns the overhang limit on. Raises TopOptError for anything else (another object, an
        edge): the base face is left as it was."""
        obj, sub = _picked("the part's face on the base plate")[0]
        self._show_base_face(picking.part_face(self.study.Part, obj, sub))
        self.overhang_on.setChecked(True)

    def _show_base_face(self, name):
        self.base_face_name = name
        self.base_face.setText(name or "none: the part's lowest point")

    def show(self, c):
        """Shows the controls' dict `c` (the study's GeometryControls)."""
        draw = c.get("draw_direction")
        self.draw_on.setChecked(draw is not None)
        draw = draw or {}
        self.draw_dir.set(draw.get("direction", (0, 0, 1)))
        self.draw_kind.setCurrentText("split" if "parting_point" in draw else "one-sided")
        self.parting_point.set(draw.get("parting_point", (0, 0, 0)))
        self.parting_point.setEnabled(self.split())
        self.draw_cell = float(draw.get("cell", 0.0))
        over = c.get("overhang")
        self.overhang_on.setChecked(over is not None)
        over = over or {}
        self.build_dir.set(over.get("direction", (0, 0, 1)))
        self.overhang_angle.setValue(float(over.get("angle", 45.0)))
        self._show_base_face(over.get("base_face"))
        self.overhang_cell = float(over.get("cell", 0.0))
        self.min_member.setValue(float(c.get("min_member_size", 0.0)))
        self.max_member.setValue(float(c.get("max_member_size", 0.0)))

    def arguments(self):
        """api.set_controls' keyword arguments for what the group shows."""
        a = {"min_member_size": self.min_member.value(), "max_member_size": self.max_member.value()}
        if self.draw_on.isChecked():
            a.update(draw_direction=self.draw_dir.value(), draw_cell=self.draw_cell,
                     parting_point=self.parting_point.value() if self.split() else None)
        if self.overhang_on.isChecked():
            a.update(build_direction=self.build_dir.value(), overhang_angle=self.overhang_angle.value(),
                     base_face=self.base_face_name, overhang_cell=self.overhang_cell)
        return a


OBJECTIVES = [("compliance", "Stiffest design of the volume fraction"),
              ("mass", "Lightest design within the limits below"),
              ("frequency", "Highest first eigenfrequency of the volume fraction")]


class ResponsesBox:
    """The "Objective and limits" group: objective, compliance limit, stress limit, and
    displacement limits on picked faces along a direction."""

    def __init__(self, study):
        self.study = study
        self.box = QtGui.QGroupBox("Objective and limits")
        layout = QtGui.QFormLayout(self.box)
        layout.setRowWrapPolicy(QtGui.QFormLayout.WrapLongRows)
        self.objective = QtGui.QComboBox()
        self.objective.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Fixed)
        for name, tip in OBJECTIVES:
            self.objective.addItem(name)
            self.objective.setItemData(self.objective.count() - 1, tip, QtCore.Qt.ToolTipRole)
        layout.addRow(QtGui.QLabel("Objective"))
        layout.addRow(self.objective)  # the whole row: its names show whole
        self.compliance_limit = _number(0, 1e15, 3, " N·mm", "none")
        self.compliance_limit.setToolTip("With the mass objective: the largest compliance allowed")
        # the limits under their labels: beside them, "250.00 MPa" would not show whole in the
        # default combo view's width
        layout.addRow(QtGui.QLabel("Compliance limit"))
        layout.addRow(self.compliance_limit)
        self.stress_limit = _number(0, 1e9, 2, " MPa", "none")
        self.stress_limit.setToolTip("The largest von Mises stress allowed (e.g. yield stress / safety factor)")
        layout.addRow(QtGui.QLabel("Stress limit"))
        layout.addRow(self.stress_limit)
        self.limits = _ItemList(lambda d: "%s along %s ≤ %.4g mm" % (", ".join(d["label"]), _fmt(d["direction"]),
                                                                      d["limit"]))
        layout.addRow(QtGui.QLabel("Displacement limits"))
        layout.addRow(self.limits.widget)
        self.limit_dir = VectorEdit((0, 0, -1))
        layout.addRow("Direction", self.limit_dir)
        self.limit_value = _number(0, 1e6, 4, " mm", "", 85)
        self.limit_value.setButtonSymbols(QtGui.QAbstractSpinBox.NoButtons)  # room for "0.0000 mm"
        layout.addRow("Limit", self.limit_value)
        row, (add, rem) = _buttons(("Limit faces", "Limit the mean displacement of the selected faces (pick them "
                                    "first) along the direction above to the value above"), ("Remove", "Remove the selected limit"))
        add.clicked.connect(ControlsBox._guard(self.add_limit))
        rem.clicked.connect(self.limits.remove_selected)
        layout.addRow(row)
        self.show()

    def add_limit(self):
        picked = _picked("the faces whose displacement to limit")
        refs = {}
        for obj, sub in picked:
            refs.setdefault(obj, []).append(sub)
        references = [(obj, tuple(subs)) for obj, subs in refs.items()]
        faces = jobmod.face_names(self.study, references, "the displacement limit")  # checks now: faces only
        self.limits.add({"faces": faces, "references": references, "direction": self.limit_dir.value(),
                         "limit": self.limit_value.value(), "label": faces})

    def show(self):
        """Shows the study's Responses."""
        r = jobmod.study_responses(self.study)
        self.objective.setCurrentText(str(r.get("objective", "compliance")))
        self.compliance_limit.setValue(float(r.get("compliance_limit", 0.0)))
        self.stress_limit.setValue(float(r.get("stress_limit", 0.0)))
        self.limits.set([dict(d, label=d["faces"]) for d in r.get("displacement_limits", [])])

    def _limit_args(self):
        """(faces, direction, limit) per limit: picked references, or the job's face names of
        limits read from the study."""
        return [(d.get("references") or d["faces"], d["direction"], d["limit"]) for d in self.limits.items]

    def apply(self):
        """Writes the responses to the study (api.set_responses: checked; raises TopOptError)."""
        return api.set_responses(self.study, objective=self.objective.currentText(),
                                 compliance_limit=self.compliance_limit.value() or None,
                                 stress_limit=self.stress_limit.value() or None, displacement_limits=self._limit_args())
