"""What every HOMesh document object proxy shares: persistence of its type alone. (Each
factory attaches its view provider when the GUI is up, importing viewproviders.py only then.)
"""


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

