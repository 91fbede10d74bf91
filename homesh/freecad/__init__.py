"""FreeCAD integration of HOMesh: document objects, view providers, task panels, commands,
export.

Import only inside FreeCAD (it imports the FreeCAD module). The factories
:func:`make_high_order_mesh`, :func:`make_sizing`, :func:`make_boundary_layer`,
:func:`make_mesh_region` and :func:`make_boundary_group` work headless (freecadcmd) and in the
GUI.

The package is layered as FreeCAD FEM's (docs/architecture.md draws it); a module imports only
modules below it (tests/python/test_freecad_imports.py checks it):

- commands.py, exporter.py: the workbench's commands, File > Export
- objects/: document object proxies and their ``make_*`` factories
- viewproviders.py: drawing, icons, double-click to edit (Gui)
- taskpanels/: the task panels, their layout in Resources/ui/*.ui (Gui)
- progress_dialog.py: the GUI's waits on a job (Gui)
- meshing.py: an object's properties -> a MeshJob, and its result back into the object
- arguments.py: objects' properties -> the core's keyword arguments
- job.py: a meshing job on a worker thread; fem.py: FEM meshes in and out
- stored_mesh.py, properties.py, object_types.py, resources.py: the bottom
"""

from .arguments import boundary_layer_arguments
from .object_types import (
    TYPE_BOUNDARY_LAYER,
    TYPE_HIGH_ORDER_MESH,
    TYPE_SIZING,
    is_boundary_layer,
    is_sizing,
)
from .objects import (
    make_boundary_group,
    make_boundary_layer,
    make_high_order_mesh,
    make_mesh_region,
    make_sizing,
)
from .stored_mesh import get_mesh

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
