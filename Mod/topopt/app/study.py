"""The TopOpt study: a document object that holds everything one optimisation needs, and
links to everything a run made (all shown under it in the tree).

Saved in .FCStd files with its proxy's module path "topopt.app.study": never move or rename
this module or the classes in it, or saved documents stop loading their studies.
"""
import FreeCAD

from . import units

PROXY_TYPE = "TopOpt::Study"
#: StepMaxTriangles of a new study: the core's own default budget (StepExportParams::max_triangles
#: in src/result/step_export.h, the native module's STEP_MAX_TRIANGLES; test_study ties them), which a
#: job without "step_max_triangles" gets
STEP_MAX_TRIANGLES = 100000

#: the study's links to what runs and the Mesh command made: (name, doc)
RESULT_LINKS = [
    ("Result", "The smoothed result shape (Mesh feature); non-design solids coloured apart"),
    ("FemResult", "The last SIMP iterate as a FEM result: displacement and von Mises stress "
                  "(FEM's result panel and post-processing work on it)"),
    ("AnalysisMesh", "The tagged analysis mesh as a FEM mesh (the FEM result's mesh)"),
    ("Fields", "The run's fields for FEM's post-processing: Density, Domain, Displacement, von Mises"),
    ("DensityView", "The material where the density reaches the threshold, coloured by density"),
]

#: links to objects a run makes only when asked (verification) and to the solid "Result as
#: solid" makes: (name, doc); None until made
ASBUILT_LINKS = [
    ("ResultSolid", "The result as a Part solid, read from the run's result.step (command Result as solid)"),
    ("VerificationMesh", "The result solid's own tet mesh (the verification's FEM mesh)"),
    ("VerificationResult", "The verification: the result solid analysed with the study's supports and loads "
                           "(FEM result: displacement, von Mises stress)"),
    ("VerificationFields", "The verification's fields for FEM's post-processing (colour bar, clip, probe)"),
]


#: the verification's compliances, quantities of work (N·mm, which FreeCAD shows as mJ): (name, doc)
COMPLIANCES = [
    ("ComplianceAsBuilt", "Compliance of the result solid, analysed on its own mesh (work: N·mm = mJ); "
                          "0 = not verified"),
    ("ComplianceCrisp", "Compliance of the crisp design (densities 0/1 at the threshold) on the FE mesh "
                        "(work: N·mm = mJ); 0 = not verified"),
]


def _add(obj, kind, name, group, doc, default=None):
    if name not in obj.PropertiesList:
        obj.addProperty(kind, name, group, doc)
        if default is not None:
            setattr(obj, name, default)


def _add_density(obj, text, doc):
    """Adds the property Density holding `text` (a quantity such as "7850 kg/m^3"): an
    App::PropertyDensity where this FreeCAD has one (0.21 and later), else (0.20) an
    App::PropertyQuantity given the unit kg/m^3 (units.add_quantity)."""
    units.add_quantity(obj, "Density", "Material", doc, "App::PropertyDensity", "kg/m^3")
    units.set_prop(obj, "Density", units.value_in(text, "kg/m^3", "Density"), "kg/m^3")


def _work(obj, name, doc):
    """Adds (or, for a document saved by an older version, turns from a float in N·mm into) the
    result property `name`: a quantity of work (units.add_quantity: App::PropertyWork, or in
    FreeCAD 0.20 an App::PropertyQuantity given the unit again each time the document opens)."""
    old = None
    if name in obj.PropertiesList and obj.getTypeIdOfProperty(name) == "App::PropertyFloat":
        old = float(getattr(obj, name))
        obj.removeProperty(name)
    units.add_quantity(obj, name, "Result", doc, "App::PropertyWork", "mJ")
    units.keep_unit(obj, name, "mJ")  # a reopened 0.20 document: the bare number again in mJ
    if old is not None:
        units.set_prop(obj, name, old, "N*mm")


def _density_to_retype(obj):
    """The density text of a Density to turn into a quantity, or None: an older document's
    float (t/mm³), or the text older versions kept in FreeCAD 0.20 (App::PropertyString),
    when it is a density FreeCAD understands (a wrong one stays text, and a run names it)."""
    kind = obj.getTypeIdOfProperty("Density") if "Density" in obj.PropertiesList else None
    if kind not in ("App::PropertyFloat", "App::PropertyString"):
        return None
    text = _density_text(obj.Density)
    try:
        units.value_in(text, "kg/m^3", "Density")
    except Exception:  # TopOptError: not a density
        return None
    return text


def _retype(obj, name, kind, group, doc, convert):
    """Re-creates property `name` as `kind` when a document saved by an older version holds it
    with another type, keeping its value through convert(old value)."""
    if name in obj.PropertiesList and obj.getTypeIdOfProperty(name) != kind:
        old = getattr(obj, name)
        obj.removeProperty(name)
        obj.addProperty(kind, name, group, doc)
        setattr(obj, name, convert(old))


def _density_text(value):
    """A density as the quantity text the study stores: a Quantity or text as it is, a plain
    float as older versions stored it (t/mm³)."""
    if isinstance(value, FreeCAD.Units.Quantity):
        return "%.6g kg/m^3" % value.getValueAs("kg/m^3")
    if isinstance(value, str):
        return value
    return "%.6g kg/m^3" % (float(value) * 1e12)


class Study:
    """Proxy of the study object (App::FeaturePython)."""

    def __init__(self, obj):
        obj.Proxy = self
        self.Type = PROXY_TYPE
        self.ensure_properties(obj)

    def ensure_properties(self, obj):
        """Adds any property the object lacks and gives old documents' properties their
        current types (documents saved by older versions load as studies of this one)."""
        self._geometry(obj)
        self._material(obj)
        self._mesh(obj)
        self._optimization(obj)
        self._results(obj)

    def _geometry(self, obj):
        _add(obj, "App::PropertyLink", "Part", "Geometry", "The whole part Ω: one solid")
        _add(obj, "App::PropertyLinkList", "NonDesign", "Geometry",
             "Non-design solids Ω̄ (material to keep), in order")
        _add(obj, "App::PropertyLinkList", "Constraints", "Geometry",
             "Supports and loads: FEM constraints (fixed, displacement, force, pressure, "
             "self weight) and TopOpt symmetry planes")

    def _material(self, obj):
        doc_e, doc_rho = "Young's modulus E", "Mass density, for self weight"
        _retype(obj, "YoungsModulus", "App::PropertyPressure", "Material", doc_e, lambda v: "%.12g MPa" % v)
        text = _density_to_retype(obj)  # an older document's float or text
        if text is not None:
            obj.removeProperty("Density")
            _add_density(obj, text, doc_rho)
        if "Density" in obj.PropertiesList:
            units.keep_unit(obj, "Density", "kg/m^3")  # a reopened 0.20 document: the bare number again in kg/m³
        _add(obj, "App::PropertyPressure", "YoungsModulus", "Material", doc_e, "210000 MPa")
        _add(obj, "App::PropertyFloat", "PoissonRatio", "Material", "Poisson's ratio ν", 0.3)
        if "Density" not in obj.PropertiesList:
            _add_density(obj, "7850 kg/m^3", doc_rho)

    def _mesh(self, obj):
        _add(obj, "App::PropertyLength", "MeshSize", "Mesh", "Target element size; 0 = automatic", 0.0)
        if "Mesher" not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", "Mesher", "Mesh",
                            "auto: the two-B-Rep advancing front, Gmsh where it fails; native: the "
                            "advancing front only; gmsh: OCC fragments meshed by Gmsh")
            obj.Mesher = ["auto", "native", "gmsh"]
        _add(obj, "App::PropertyInteger", "WallLayers", "Mesh",
             "Element layers across walls thinner than two mesh sizes (native mesher; 0 = off, "
             "2 = two layers, more elements)", 0)

    def _optimization(self, obj):
        # a plain float, checked when the study is run (job.study_numbers): a constrained float
        # would silently clamp 0 to its lower bound and run
        _add(obj, "App::PropertyFloat", "VolumeFraction", "Optimization",
             "Share of the design domain's volume to keep, strictly between 0 and 1", 0.3)
        _add(obj, "App::PropertyFloat", "Penalty", "Optimization", "SIMP penalty p", 3.0)
        _add(obj, "App::PropertyLength", "FilterRadius", "Optimization",
             "Density filter radius; 0 = 1.5 × mesh size", 0.0)
        if "Filter" not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", "Filter", "Optimization", "Filter weights")
            obj.Filter = ["gaussian", "cone"]
        if "Update" not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", "Update", "Optimization",
                            "Update scheme: optimality criteria or MMA")
            obj.Update = ["oc", "mma"]
        _add(obj, "App::PropertyInteger", "MaxIterations", "Optimization", "Iteration cap", 80)
        _add(obj, "App::PropertyBool", "KeepLoadedFaces", "Optimization",
             "Keep the material under every supported and loaded face: the design elements touching those "
             "faces stay solid (one element layer, outside the volume fraction), so the result keeps every "
             "face a load or support acts on. Off: the optimisation may remove it (the verification then "
             "stops, naming the face it lost)", True)
        _add(obj, "App::PropertyBool", "JoinNonDesign", "Optimization",
             "Join every non-design solid the optimised design leaves apart (a boss or pad that carries no "
             "load) to the part by a bridge through the design, so the result is one piece; a warning names "
             "each bridge's solid, material and length. Off: such a solid stays apart, named in a warning", True)
        _add(obj, "App::PropertyString", "GeometryControls", "Optimization",
             "Geometry controls as the job's \"controls\" object in JSON (symmetry planes, cyclic, "
             "patterns, extrusion; docs/optimization.md; lengths in mm, angles in degrees); empty = none. Set with "
             "api.set_controls", "")
        _add(obj, "App::PropertyString", "Responses", "Optimization",
             "Objective and limits as the job's optimization keys in JSON (objective, compliance_limit, "
             "stress_limit, displacement_limits; docs/optimization.md; compliance in N·mm, stress in MPa, "
             "displacements in mm); empty = the stiffest design of the "
             "volume fraction. Set with api.set_responses or the study's panel", "")

    def _results(self, obj):
        doc_t = ("Density threshold of the shown result shape: the run's (the one that keeps the volume "
                 "fraction) until the threshold slider moves it; never an input of the next run")
        _add(obj, "App::PropertyFloat", "Threshold", "Result", doc_t, -1.0)
        obj.setDocumentationOfProperty("Threshold", doc_t)  # older documents: it used to be an input
        for name, doc in RESULT_LINKS + ASBUILT_LINKS:
            _add(obj, "App::PropertyLink", name, "Result", doc)
        self._asbuilt(obj)
        _add(obj, "App::PropertyLinkList", "DomainMeshes", "Result",
             "The tagged mesh by domain (FEM meshes: design, then each non-design solid)")
        _add(obj, "App::PropertyFloatList", "ComplianceHistory", "Result",
             "Compliance per iteration in N·mm (FreeCAD has no list of quantities: plain numbers)")
        _add(obj, "App::PropertyFloatList", "VolumeHistory", "Result", "Volume fraction per iteration")
        _add(obj, "App::PropertyString", "Status", "Result", "What the last run did")
        # The analysis mesh and the densities, kept so the result can be re-extracted at another
        # threshold without re-running.
        _add(obj, "App::PropertyVectorList", "MeshNodes", "Result", "Analysis mesh nodes")
        _add(obj, "App::PropertyIntegerList", "MeshTets", "Result", "Analysis mesh tets, 4 per tet")
        _add(obj, "App::PropertyIntegerList", "MeshDomains", "Result", "0 design, i non-design solid i")
        _add(obj, "App::PropertyFloatList", "Densities", "Result", "Element densities of the last run")
        # its boundary numbered by the part's faces: the supports and loads the threshold slider
        # cleans the result by, as the run did (empty in documents saved before)
        _add(obj, "App::PropertyIntegerList", "MeshBoundary", "Result", "Boundary triangles of the mesh, 3 per triangle")
        _add(obj, "App::PropertyIntegerList", "MeshBoundaryFaces", "Result",
             "Per boundary triangle, the part's face it lies on (N of FaceN; 0 none)")
        _add(obj, "App::PropertyIntegerList", "MeshBoundaryNonDesignFaces", "Result",
             "Per boundary triangle, the non-design compound's face it also lies on (0 none)")
        for name in ("Status", "MeshNodes", "MeshTets", "MeshDomains", "Densities", "ComplianceHistory",
                     "VolumeHistory", "Threshold", "DomainMeshes") + tuple(n for n, _ in RESULT_LINKS + ASBUILT_LINKS):
            obj.setEditorMode(name, 1)  # read-only in the property editor
        for name in ("MeshNodes", "MeshTets", "MeshDomains", "Densities", "MeshBoundary", "MeshBoundaryFaces",
                     "MeshBoundaryNonDesignFaces"):
            obj.setEditorMode(name, 2)  # and hidden: they are large

    def _asbuilt(self, obj):
        """What a run writes besides the shape: its options and the files it wrote, kept in the
        document (an .FCStd holds the included files)."""
        _add(obj, "App::PropertyBool", "WriteStep", "Output",
             "Write the result as one CAD solid (result.step) with each run: Result as solid and Export STEP "
             "need it", True)
        _add(obj, "App::PropertyInteger", "StepMaxTriangles", "Output",
             "The most triangles of the result surface that become faces of result.step (0: no bound): a larger "
             "surface is coarsened until it fits, its volume within 0.5 %, or not written (a warning names this "
             "property). Also bounds the STEP written when the threshold slider moves", STEP_MAX_TRIANGLES)
        _add(obj, "App::PropertyBool", "Verify", "Output",
             "Analyse the result solid after each run (its own tet mesh, the study's supports and loads): "
             "the as-built compliance and stresses", True)
        _add(obj, "App::PropertyFloat", "RunThreshold", "Result",
             "Density threshold of the last run's result (the one its result.step was written at); the "
             "threshold slider moves Threshold, and Result as solid and Export STEP follow it", -1.0)
        _add(obj, "App::PropertyStringList", "ResultFiles", "Result",
             "The files the last run wrote (result.step, verification.json, verification.vtu)")
        _add(obj, "App::PropertyFileIncluded", "ResultStep", "Result", "The last run's result.step (one solid)")
        _add(obj, "App::PropertyFileIncluded", "VerificationVtu", "Result", "The last run's verification.vtu")
        _add(obj, "App::PropertyString", "VerificationReport", "Result",
             "The last run's verification.json (compliance_as_built, max_von_mises, crisp, failed, ...)")
        for name, doc in COMPLIANCES:
            _work(obj, name, doc)
        for name in ("RunThreshold", "ResultFiles", "ResultStep", "VerificationVtu", "VerificationReport",
                     "ComplianceAsBuilt", "ComplianceCrisp"):
            obj.setEditorMode(name, 1)

    def onDocumentRestored(self, obj):
        self.ensure_properties(obj)
        from . import directions
        directions.migrate_scripted_forces(obj)
        attach_view_provider(obj, "ViewProviderStudy")

    def execute(self, obj):
        pass

    def __getstate__(self):
        return {"Type": self.Type}

    def __setstate__(self, state):
        if state:
            self.Type = state.get("Type", PROXY_TYPE)


def attach_view_provider(obj, name):
    """With the GUI, gives `obj` TopOpt's view provider `name` (topopt.gui.view_providers) when
    it has none: a document saved without the GUI holds no view data, and its objects would
    open without their icon, their children in the tree and their panel."""
    vobj = getattr(obj, "ViewObject", None) if FreeCAD.GuiUp else None
    if vobj is None:
        return
    from topopt.gui import view_providers
    cls = getattr(view_providers, name)
    if not isinstance(getattr(vobj, "Proxy", None), cls):
        cls(vobj)


def is_study(obj):
    return getattr(getattr(obj, "Proxy", None), "Type", None) == PROXY_TYPE


def owned_objects(study):
    """Every object the study made or refers to besides its inputs, in tree order:
    constraints with their direction lines, the domain meshes, then the result objects."""
    from . import directions
    out = []
    for c in study.Constraints:
        out.append(c)
        line = directions.helper_line(c)
        if line is not None:
            out.append(line)
    out += [o for o in study.DomainMeshes if o is not None]
    for name, _ in RESULT_LINKS:
        obj = getattr(study, name, None)
        if obj is not None and not (name == "DensityView" and study.Fields is not None):
            out.append(obj)  # the density view sits under the fields (FEM's pipeline claims it)
    out += [getattr(study, n, None) for n, _ in ASBUILT_LINKS if getattr(study, n, None) is not None]
    return out


def make_study(doc, part, nondesign=(), name="TopOptStudy"):
    """Adds a study to `doc` for `part` (a document object with a Shape) and the non-design
    objects `nondesign`. Returns the study object."""
    obj = doc.addObject("App::FeaturePython", name)
    Study(obj)
    obj.Part = part
    obj.NonDesign = list(nondesign)
    attach_view_provider(obj, "ViewProviderStudy")
    return obj
