"""What every HOMesh document object proxy shares: persistence of its type alone; and what the
proxies with parameter-table properties share: setting them up, restoring them and refusing an
out-of-range value. (Each factory attaches its view provider when the GUI is up, importing
viewproviders.py only then.)
"""

from ..properties import ParameterGuard


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



class GuardedProxy(Proxy, ParameterGuard):
    """A proxy whose class adds its properties with ``add_properties(obj)`` (safe to call again
    on a document from an older version) and whose table properties the guard watches."""

    def __init__(self, obj):
        obj.Proxy = self
        self.add_properties(obj)
        self.remember(obj)

    def onDocumentRestored(self, obj):
        self.add_properties(obj)
        self.remember(obj)

    def onChanged(self, obj, prop):
        self.guard(obj, prop)
