"""Where documents saved before the package was split find the MeshRegion and BoundaryGroup
proxies (their Document.xml names ``homesh.freecad.regions`` as the proxies' module). New code
imports them from objects/."""

from .objects.regions import BoundaryGroupProxy, MeshRegionProxy

__all__ = ["BoundaryGroupProxy", "MeshRegionProxy"]
