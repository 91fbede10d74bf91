"""FreeCAD integration of HOMesh: document objects, view providers, commands, export.

Import only inside FreeCAD (it imports the FreeCAD module). The factories
:func:`make_high_order_mesh` and :func:`make_sizing` work headless (freecadcmd) and in the GUI.
"""

from .objects import (
    TYPE_HIGH_ORDER_MESH,
    TYPE_SIZING,
    get_mesh,
    is_sizing,
    make_high_order_mesh,
    make_sizing,
)

__all__ = [
    "TYPE_HIGH_ORDER_MESH",
    "TYPE_SIZING",
    "get_mesh",
    "is_sizing",
    "make_high_order_mesh",
    "make_sizing",
]
