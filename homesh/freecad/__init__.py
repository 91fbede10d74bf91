"""FreeCAD integration of HOMesh: document objects, view providers, commands, export.

Import only inside FreeCAD (it imports the FreeCAD module). The factories
:func:`make_high_order_mesh`, :func:`make_sizing` and :func:`make_boundary_layer` work headless
(freecadcmd) and in the GUI.
"""

from .objects import (
    TYPE_BOUNDARY_LAYER,
    TYPE_HIGH_ORDER_MESH,
    TYPE_SIZING,
    boundary_layer_arguments,
    get_mesh,
    is_boundary_layer,
    is_sizing,
    make_boundary_layer,
    make_high_order_mesh,
    make_sizing,
)
from .regions import make_boundary_group, make_mesh_region

__all__ = [
    "TYPE_BOUNDARY_LAYER",
    "TYPE_HIGH_ORDER_MESH",
    "TYPE_SIZING",
    "boundary_layer_arguments",
    "get_mesh",
    "is_boundary_layer",
    "is_sizing",
    "make_boundary_layer",
    "make_boundary_group",
    "make_high_order_mesh",
    "make_mesh_region",
    "make_sizing",
]
