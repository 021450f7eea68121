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
    icon = "TopOptStudy.svg"

    def claimChildren(self):
        obj = self.Object
        children = list(obj.Constraints)
        if obj.Result:
            children.append(obj.Result)
        return children

    def doubleClicked(self, vobj):
        from topopt.gui import panels
        panels.open_study_panel(vobj.Object)
        return True


class ViewProviderSymmetry(_ViewProvider):
    icon = "TopOptSymmetry.svg"
