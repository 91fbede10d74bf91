"""FreeCAD integration of HOMesh: document objects, view providers, commands, export.

Import only inside FreeCAD (it imports the FreeCAD module). The factory
:func:`make_high_order_mesh` works headless (freecadcmd) and in the GUI.
"""

from .objects import TYPE_HIGH_ORDER_MESH, get_mesh, make_high_order_mesh  # noqa: F401
