"""View providers of TopOpt's objects (GUI only)."""
import topopt


def _icon(name):
    return topopt.resources_dir() + "/icons/" + name


class _ViewProvider:
    icon = "TopOptWorkbench.svg"

    def __init__(self, vobj):
        vobj.Proxy = self

    def attach(self, vobj):
        self.Object = vobj.Object

    def getIcon(self):
        return _icon(self.icon)

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None


class ViewProviderStudy(_ViewProvider):
    """The study in the tree: everything it made or uses besides its input solids sits under it
    (constraints with their direction lines, domain meshes, result shape, FEM result and mesh,
    fields with the density view). `panel` is its study panel and `force_panel` its force
    panel when open (not saved)."""
    icon = "TopOptStudy.svg"
    panel = None
    force_panel = None

    def attach(self, vobj):
        self.Object = vobj.Object
        # a reopened document: the result shape's view reads its FaceColors before the mesh is
        # loaded and shows none, and a density view saved without the GUI holds no data (FEM's
        # filters compute only with it); both are redone once loading is done
        from PySide import QtCore
        QtCore.QTimer.singleShot(0, self._after_load)

    def _after_load(self):
        try:
            result, density = self.Object.Result, self.Object.DensityView
        except Exception:  # the study was deleted or its document closed meanwhile
            return
        from topopt.app import results
        if result is not None and "FaceColors" in result.PropertiesList:
            results.style_result(result)
        if density is not None and density.ViewObject is not None and \
                results.DENSITY not in density.ViewObject.getEnumerationsOfProperty("Field"):
            density.touch()
            from topopt.app import quiet
            quiet.recompute(density.Document)
            results.style_density_view(density)

    def claimChildren(self):
        from topopt.app.study import owned_objects
        return owned_objects(self.Object)

    def doubleClicked(self, vobj):
        from topopt.gui import panels
        panels.open_study_panel(vobj.Object)
        return True


class ViewProviderSymmetry(_ViewProvider):
    icon = "TopOptSymmetry.svg"
