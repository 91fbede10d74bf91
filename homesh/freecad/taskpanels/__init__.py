"""Task panels, as FreeCAD FEM's femtaskpanels: one module per object's panel, the layout in
Resources/ui/*.ui, parameter widgets filled from the core's parameter table
(parameter_widgets.py). Panels hold the values typed and hand them to meshing.py; they do no
meshing of their own. Gui only.
"""

from ..object_types import is_sizing
from .task_high_order_mesh import TaskPanelHighOrderMesh
from .task_sizing import TaskPanelSizing

_LAST = []


def panel_for(obj):
    """The task panel of a HOMesh object (remembered for :func:`last_panel`)."""
    panel = TaskPanelSizing(obj) if is_sizing(obj) else TaskPanelHighOrderMesh(obj)
    _LAST[:] = [panel]
    return panel


def last_panel():
    """The panel :func:`panel_for` made last (FreeCAD's Control.activeDialog() says only
    whether one is shown, not which)."""
    return _LAST[0] if _LAST else None


__all__ = ["TaskPanelHighOrderMesh", "TaskPanelSizing", "last_panel", "panel_for"]
