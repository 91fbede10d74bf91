"""What every HOMesh document object proxy shares: persistence of its type alone, and the view
provider its factory attaches when the GUI is up. No Qt: view providers are imported only then.
"""

import FreeCAD


class Proxy:
    """Persistence of the proxies: only their type (FreeCAD 0.20 uses __getstate__, 0.21+
    dumps)."""

    def __getstate__(self):
        return {"Type": self.Type}

    def __setstate__(self, state):
        return None

    def dumps(self):
        return self.__getstate__()

    def loads(self, state):
        self.__setstate__(state)


def attach_view_provider(obj, name):
    """Gives ``obj`` the view provider class ``name`` of viewproviders.py when the GUI is up
    (headless, objects have no ViewObject)."""
    if FreeCAD.GuiUp:
        from .. import viewproviders
        getattr(viewproviders, name)(obj.ViewObject)
