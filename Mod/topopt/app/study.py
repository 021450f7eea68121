"""The TopOpt study: a document object that holds everything one optimisation needs.

Saved in .FCStd files with its proxy's module path "topopt.app.study": never move or rename
this module or the classes in it, or saved documents stop loading their studies.
"""
import FreeCAD

PROXY_TYPE = "TopOpt::Study"


def _add(obj, kind, name, group, doc, default=None):
    if name not in obj.PropertiesList:
        obj.addProperty(kind, name, group, doc)
        if default is not None:
            setattr(obj, name, default)


class Study:
    """Proxy of the study object (App::FeaturePython)."""

    def __init__(self, obj):
        obj.Proxy = self
        self.Type = PROXY_TYPE
        self.ensure_properties(obj)

    def ensure_properties(self, obj):
        """Adds any property the object lacks (documents saved by older versions)."""
        _add(obj, "App::PropertyLink", "Part", "Geometry", "The whole part Ω: one solid")
        _add(obj, "App::PropertyLinkList", "NonDesign", "Geometry",
             "Non-design solids Ω̄ (material to keep), in order")
        _add(obj, "App::PropertyLinkList", "Constraints", "Geometry",
             "Supports and loads: FEM constraints (fixed, displacement, force, pressure, "
             "self weight) and TopOpt symmetry planes")
        _add(obj, "App::PropertyFloat", "YoungsModulus", "Material", "Young's modulus E (MPa)", 210000.0)
        _add(obj, "App::PropertyFloat", "PoissonRatio", "Material", "Poisson's ratio", 0.3)
        _add(obj, "App::PropertyFloat", "Density", "Material", "Mass density (t/mm³), for self weight", 7.85e-9)
        _add(obj, "App::PropertyLength", "MeshSize", "Mesh", "Target element size; 0 = automatic", 0.0)
        if "Mesher" not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", "Mesher", "Mesh",
                            "auto: the two-B-Rep advancing front, Gmsh where it fails; native: the "
                            "advancing front only; gmsh: OCC fragments meshed by Gmsh")
            obj.Mesher = ["auto", "native", "gmsh"]
        _add(obj, "App::PropertyInteger", "WallLayers", "Mesh",
             "Element layers across walls thinner than two mesh sizes (native mesher; 0 = off, "
             "2 = two layers, more elements)", 0)
        # a plain float, checked when the study is run (job.study_numbers): a constrained float
        # would silently clamp 0 to its lower bound and run (documents saved with the older
        # PropertyFloatConstraint load without its bounds, so they behave the same)
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
        _add(obj, "App::PropertyFloat", "Threshold", "Result",
             "Density threshold of the result shape; -1 = the one that meets the volume", -1.0)
        _add(obj, "App::PropertyLink", "Result", "Result", "The smoothed result shape (Mesh feature)")
        _add(obj, "App::PropertyFloatList", "ComplianceHistory", "Result", "Compliance per iteration (N·mm)")
        _add(obj, "App::PropertyFloatList", "VolumeHistory", "Result", "Volume fraction per iteration")
        _add(obj, "App::PropertyString", "Status", "Result", "What the last run did")
        # The analysis mesh and the densities, kept so the result can be re-extracted at another
        # threshold without re-running.
        _add(obj, "App::PropertyVectorList", "MeshNodes", "Result", "Analysis mesh nodes")
        _add(obj, "App::PropertyIntegerList", "MeshTets", "Result", "Analysis mesh tets, 4 per tet")
        _add(obj, "App::PropertyIntegerList", "MeshDomains", "Result", "0 design, i non-design solid i")
        _add(obj, "App::PropertyFloatList", "Densities", "Result", "Element densities of the last run")
        for name in ("Status", "MeshNodes", "MeshTets", "MeshDomains", "Densities",
                     "ComplianceHistory", "VolumeHistory"):
            obj.setEditorMode(name, 1)  # read-only in the property editor
        for name in ("MeshNodes", "MeshTets", "MeshDomains", "Densities"):
            obj.setEditorMode(name, 2)  # and hidden: they are large

    def onDocumentRestored(self, obj):
        self.ensure_properties(obj)

    def execute(self, obj):
        pass

    def __getstate__(self):
        return {"Type": self.Type}

    def __setstate__(self, state):
        if state:
            self.Type = state.get("Type", PROXY_TYPE)


def is_study(obj):
    return getattr(getattr(obj, "Proxy", None), "Type", None) == PROXY_TYPE


def make_study(doc, part, nondesign=(), name="TopOptStudy"):
    """Adds a study to `doc` for `part` (a document object with a Shape) and the non-design
    objects `nondesign`. Returns the study object."""
    obj = doc.addObject("App::FeaturePython", name)
    Study(obj)
    obj.Part = part
    obj.NonDesign = list(nondesign)
    if FreeCAD.GuiUp:
        from topopt.gui import view_providers
        view_providers.ViewProviderStudy(obj.ViewObject)
    return obj
