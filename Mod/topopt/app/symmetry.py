"""Symmetry plane: the support FreeCAD FEM lacks. Fixes the normal displacement on planar faces.

Saved in .FCStd with the proxy path "topopt.app.symmetry": keep it.
"""
import FreeCAD

PROXY_TYPE = "TopOpt::SymmetryPlane"


class SymmetryPlane:
    def __init__(self, obj):
        obj.Proxy = self
        self.Type = PROXY_TYPE
        obj.addProperty("App::PropertyLinkSubList", "References", "Symmetry",
                        "Planar faces of the part on the symmetry plane")

    def execute(self, obj):
        pass

    def __getstate__(self):
        return {"Type": self.Type}

    def __setstate__(self, state):
        if state:
            self.Type = state.get("Type", PROXY_TYPE)


def make_symmetry_plane(doc, references=(), name="SymmetryPlane"):
    """references: [(object, ("Face3", ...)), ...]"""
    obj = doc.addObject("App::FeaturePython", name)
    SymmetryPlane(obj)
    obj.References = list(references)
    if FreeCAD.GuiUp:
        from topopt.gui import view_providers
        view_providers.ViewProviderSymmetry(obj.ViewObject)
    return obj
