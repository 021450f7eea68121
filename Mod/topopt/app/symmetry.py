"""Symmetry plane: the support FreeCAD FEM lacks. Fixes the normal displacement on planar faces.

Saved in .FCStd with the proxy path "topopt.app.symmetry": keep it.
"""

PROXY_TYPE = "TopOpt::SymmetryPlane"


class SymmetryPlane:
    def __init__(self, obj):
        obj.Proxy = self
        self.Type = PROXY_TYPE
        obj.addProperty("App::PropertyLinkSubList", "References", "Symmetry",
                        "Planar faces of the part on the symmetry plane")

    def execute(self, obj):
        pass

    def onDocumentRestored(self, obj):
        from .study import attach_view_provider
        attach_view_provider(obj, "ViewProviderSymmetry")

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
    from .study import attach_view_provider
    attach_view_provider(obj, "ViewProviderSymmetry")
    return obj
