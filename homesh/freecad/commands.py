"""GUI commands of the HOMesh workbench. Importing this module registers them."""

import FreeCAD
import FreeCADGui

from . import resources


def _selected_shape_object():
    selection = FreeCADGui.Selection.getSelection()
    if len(selection) != 1:
        return None
    obj = selection[0]
    shape = getattr(obj, "Shape", None)
    if shape is None or not hasattr(shape, "isNull") or shape.isNull():
        return None
    return obj


class CommandHighOrderMesh:
    """Creates a HighOrderMesh of the selected shape and recomputes it."""

    def GetResources(self):
        return {
            "Pixmap": resources.icon("homesh_mesh.svg"),
            "MenuText": "High-order mesh",
            "ToolTip": "Mesh the selected shape with curved high-order elements "
                       "(boundary nodes on the CAD)",
        }

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _selected_shape_object() is not None

    def Activated(self):
        part = _selected_shape_object()
        if part is None:
            FreeCAD.Console.PrintError("HOMesh: select one object with a shape first\n")
            return
        doc = FreeCAD.ActiveDocument
        doc.openTransaction("High-order mesh")
        try:
            FreeCADGui.addModule("homesh.freecad")
            FreeCADGui.doCommand(
                "_mesh = homesh.freecad.make_high_order_mesh("
                "App.ActiveDocument, App.ActiveDocument.getObject(%r))" % part.Name)
            FreeCADGui.doCommand("Gui.ActiveDocument.getObject(%r).Visibility = False" % part.Name)
            FreeCADGui.doCommand("App.ActiveDocument.recompute()")
        finally:
            doc.commitTransaction()


FreeCADGui.addCommand("HOMesh_HighOrderMesh", CommandHighOrderMesh())
