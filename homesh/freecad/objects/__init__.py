"""HOMesh's document objects, as FreeCAD FEM's femobjects: each module one object, its proxy
(properties, recompute, persistence) and its ``make_*`` factory, which works headless
(freecadcmd) and in the GUI. No Qt here.

The proxy classes are named here too: documents saved before the package was split name
``homesh.freecad.objects.HighOrderMeshProxy`` (and Sizing, BoundaryLayer) as their proxies'
class.
"""

from .boundary_layer import BoundaryLayerProxy, make_boundary_layer
from .high_order_mesh import HighOrderMeshProxy, make_high_order_mesh
from .regions import BoundaryGroupProxy, MeshRegionProxy, make_boundary_group, make_mesh_region
from .sizing import SizingProxy, make_sizing

__all__ = [
    "BoundaryGroupProxy",
    "BoundaryLayerProxy",
    "HighOrderMeshProxy",
    "MeshRegionProxy",
    "SizingProxy",
    "make_boundary_group",
    "make_boundary_layer",
    "make_high_order_mesh",
    "make_mesh_region",
    "make_sizing",
]
