"""GUI commands of the HOMesh workbench. Importing this module registers them."""

import FreeCAD
import FreeCADGui

from . import resources
from .fem import fem_shape_object, is_fem_mesh
from .object_types import is_high_order_mesh, is_sizing
from .stored_mesh import get_mesh
from .taskpanels import last_panel


def _selected_sizing_object():
    selection = FreeCADGui.Selection.getSelection()
    if len(selection) == 1 and is_sizing(selection[0]) and selection[0].Part is not None:
        return selection[0]
    return None


def _selected_shape_object():
    selection = FreeCADGui.Selection.getSelection()
    if len(selection) != 1:
        return None
    obj = selection[0]
    shape = getattr(obj, "Shape", None)
    if shape is None or not hasattr(shape, "isNull") or shape.isNull():
        return None
    return obj


def _do_commands(title, commands, module="homesh.freecad"):
    """Runs ``commands`` through FreeCADGui.doCommand (so they show in the Python console and
    macros) as one undoable step called ``title``."""
    doc = FreeCAD.ActiveDocument
    doc.openTransaction(title)
    try:
        FreeCADGui.addModule(module)
        for command in commands:
            FreeCADGui.doCommand(command)
    finally:
        doc.commitTransaction()


def _edit_and_mesh(obj):
    """Opens the task panel of a new HighOrderMesh and starts meshing it there."""
    FreeCADGui.ActiveDocument.setEdit(obj.Name)
    panel = active_panel()
    if panel is not None:
        panel.mesh()


def active_panel():
    """The HOMesh task panel being shown, if any."""
    return last_panel() if FreeCADGui.Control.activeDialog() else None


class CommandHighOrderMesh:
    """Creates a HighOrderMesh of the selected shape (or of the selected Sizing object's shape,
    sized by it) and opens its task panel, which meshes it."""

    def GetResources(self):
        return {
            "Pixmap": resources.icon("homesh_mesh.svg"),
            "MenuText": "High-order mesh",
            "ToolTip": "Mesh the selected shape with curved high-order elements "
                       "(boundary nodes on the CAD); with a Mesh sizing object selected, "
                       "mesh its shape with that sizing",
        }

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and (
            _selected_shape_object() is not None or _selected_sizing_object() is not None)

    def Activated(self):
        sizing = _selected_sizing_object()
        part = sizing.Part if sizing is not None else _selected_shape_object()
        if part is None:
            FreeCAD.Console.PrintError(
                "HOMesh: select one object with a shape (or a Mesh sizing object) first\n")
            return
        sizing_arg = ("" if sizing is None else
                      ", sizing=App.ActiveDocument.getObject(%r)" % sizing.Name)
        _do_commands("High-order mesh", [
            "_mesh = homesh.freecad.make_high_order_mesh("
            "App.ActiveDocument, App.ActiveDocument.getObject(%r)%s)" % (part.Name, sizing_arg)])
        # The task panel meshes on a worker thread, with progress, Stop and the log; the
        # object is applied (one undoable step) when the job ends.
        _edit_and_mesh(FreeCAD.ActiveDocument.ActiveObject)


class CommandSizing:
    """Creates a Sizing object (automatic sizing, predicted element count) for the selected
    shape and recomputes it."""

    def GetResources(self):
        return {
            "Pixmap": resources.icon("homesh_sizing.svg"),
            "MenuText": "Mesh sizing",
            "ToolTip": "Add a sizing octree for the selected shape (sizes from its curvature "
                       "between MinDelta and MaxDelta, refinement spheres) and predict the "
                       "element count; link it from a high-order mesh's Sizing property",
        }

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _selected_shape_object() is not None

    def Activated(self):
        part = _selected_shape_object()
        if part is None:
            FreeCAD.Console.PrintError("HOMesh: select one object with a shape first\n")
            return
        _do_commands("Mesh sizing", [
            "_sizing = homesh.freecad.make_sizing("
            "App.ActiveDocument, App.ActiveDocument.getObject(%r))" % part.Name,
            "App.ActiveDocument.recompute()"])


def _selected_faces():
    """(object, ["FaceN", ...]) when faces of one object are selected (or edges, for a layer on
    a planar shape; nothing else), else None."""
    selection = FreeCADGui.Selection.getSelectionEx()
    if len(selection) != 1:
        return None
    names = list(selection[0].SubElementNames)
    if not names or not (all(n.startswith("Face") for n in names) or
                         all(n.startswith("Edge") for n in names)):
        return None
    return selection[0].Object, names


class CommandBoundaryLayer:
    """Creates a BoundaryLayer object on the selected faces (thickness a hundredth of the
    shape's bounding-box diagonal, 2 layers, progression 2), links it from the shape's
    high-order mesh when there is exactly one, and recomputes."""

    def GetResources(self):
        return {
            "Pixmap": resources.icon("homesh_layer.svg"),
            "MenuText": "Boundary layer",
            "ToolTip": "Add a boundary layer on the selected faces: prisms grown from them, "
                       "curved with the mesh and split into thin layers (set Thickness, Layers "
                       "and Progression in its properties)",
        }

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _selected_faces() is not None

    def Activated(self):
        selected = _selected_faces()
        if selected is None:
            FreeCAD.Console.PrintError("HOMesh: select faces of one shape first\n")
            return
        part, faces = selected
        thickness = "%.4g" % (part.Shape.BoundBox.DiagonalLength / 100.0)
        meshes = [o for o in part.Document.Objects if is_high_order_mesh(o) and o.Part == part]
        link = (["App.ActiveDocument.getObject(%r).BoundaryLayer = _layer" % meshes[0].Name]
                if len(meshes) == 1 else [])
        _do_commands("Boundary layer", [
            "_layer = homesh.freecad.make_boundary_layer(App.ActiveDocument, "
            "App.ActiveDocument.getObject(%r), %r, %r)" % (part.Name, faces, thickness)]
            + link + ["App.ActiveDocument.recompute()"])


def _selected_fem_mesh():
    """The selected FEM mesh object whose shape is known, or None."""
    selection = FreeCADGui.Selection.getSelection()
    if len(selection) == 1 and is_fem_mesh(selection[0]) and \
            fem_shape_object(selection[0]) is not None:
        return selection[0]
    return None


def _selected_high_order_mesh():
    selection = FreeCADGui.Selection.getSelection()
    if len(selection) == 1 and is_high_order_mesh(selection[0]):
        return selection[0]
    return None


class CommandCurveFemMesh:
    """Curves the selected FEM mesh (FEM's Gmsh or Netgen mesher) on its shape: a HighOrderMesh
    whose FemMesh property links it, meshed from the task panel."""

    def GetResources(self):
        return {
            "Pixmap": resources.icon("homesh_curve_fem.svg"),
            "MenuText": "Curve FEM mesh",
            "ToolTip": "Put the selected FEM mesh (Gmsh or Netgen, first or second order) on "
                       "its shape and curve it: a high-order mesh whose boundary nodes lie on "
                       "the CAD, optimised",
        }

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _selected_fem_mesh() is not None

    def Activated(self):
        fem = _selected_fem_mesh()
        if fem is None:
            FreeCAD.Console.PrintError("HOMesh: select one FEM mesh object made from a shape\n")
            return
        part = fem_shape_object(fem)
        _do_commands("Curve FEM mesh", [
            "_mesh = homesh.freecad.make_high_order_mesh(App.ActiveDocument, "
            "App.ActiveDocument.getObject(%r), name=%r, "
            "fem_mesh=App.ActiveDocument.getObject(%r))"
            % (part.Name, "Curved" + fem.Name, fem.Name)])
        _edit_and_mesh(FreeCAD.ActiveDocument.ActiveObject)


class CommandToFemMesh:
    """Makes a FEM mesh object (order 2 at most) of the selected high-order mesh."""

    def GetResources(self):
        return {
            "Pixmap": resources.icon("homesh_to_fem.svg"),
            "MenuText": "To FEM mesh",
            "ToolTip": "Make a FEM mesh object of the selected high-order mesh (quadratic "
                       "tetrahedra through the curved elements' midpoints, the highest order "
                       "FEM holds) for FEM's solvers and post-processing",
        }

    def IsActive(self):
        obj = _selected_high_order_mesh()
        return obj is not None and get_mesh(obj) is not None

    def Activated(self):
        obj = _selected_high_order_mesh()
        if obj is None:
            return
        try:
            _do_commands("To FEM mesh", [
                "_fem = homesh.freecad.fem.make_fem_mesh_object(App.ActiveDocument, "
                "App.ActiveDocument.getObject(%r))" % obj.Name], module="homesh.freecad.fem")
        except ValueError as e:
            FreeCAD.Console.PrintError("HOMesh: %s\n" % e)
        FreeCAD.ActiveDocument.recompute()


def _selected_subshapes(kinds):
    """(object, [names]) when sub-shapes of the given kinds of one object are selected."""
    selection = FreeCADGui.Selection.getSelectionEx()
    if len(selection) != 1:
        return None
    names = list(selection[0].SubElementNames)
    if not names or not all(n.startswith(kinds) for n in names):
        return None
    return selection[0].Object, names


def _mesh_of(part):
    meshes = [o for o in part.Document.Objects if is_high_order_mesh(o) and o.Part == part]
    return meshes[0] if len(meshes) == 1 else None


class CommandMeshRegion:
    """A MeshRegion on the selected faces, edges or vertices, child of their shape's mesh."""

    def GetResources(self):
        return {"Pixmap": resources.icon("homesh_region.svg"), "MenuText": "Mesh region",
                "ToolTip": "Refine the mesh near the selected faces, edges or vertices (a "
                           "child of the shape's high-order mesh; set its Size)"}

    def IsActive(self):
        picked = _selected_subshapes(("Face", "Edge", "Vertex"))
        return picked is not None and _mesh_of(picked[0]) is not None

    def Activated(self):
        part, names = _selected_subshapes(("Face", "Edge", "Vertex"))
        mesh = _mesh_of(part)
        size = part.Shape.BoundBox.DiagonalLength / 100.0
        _do_commands("Mesh region", [
            "_region = homesh.freecad.make_mesh_region(App.ActiveDocument, "
            "App.ActiveDocument.getObject(%r), [(App.ActiveDocument.getObject(%r), %r)], "
            "%r)" % (mesh.Name, part.Name, names, size)])


class CommandBoundaryGroup:
    """A named BoundaryGroup on the selected faces (2D: edges), child of their shape's mesh."""

    def GetResources(self):
        return {"Pixmap": resources.icon("homesh_group.svg"), "MenuText": "Boundary group",
                "ToolTip": "Name the selected faces (wall, inlet, outlet ...): every export "
                           "writes them as one Gmsh physical group / Nektar++ composite"}

    def IsActive(self):
        picked = _selected_subshapes(("Face", "Edge"))
        return picked is not None and _mesh_of(picked[0]) is not None

    def Activated(self):
        part, names = _selected_subshapes(("Face", "Edge"))
        mesh = _mesh_of(part)
        existing = len(getattr(mesh, "Groups", []) or [])
        _do_commands("Boundary group", [
            "_group = homesh.freecad.make_boundary_group(App.ActiveDocument, "
            "App.ActiveDocument.getObject(%r), [(App.ActiveDocument.getObject(%r), %r)], "
            "%r)" % (mesh.Name, part.Name, names, "group%d" % (existing + 1))])


FreeCADGui.addCommand("HOMesh_MeshRegion", CommandMeshRegion())
FreeCADGui.addCommand("HOMesh_BoundaryGroup", CommandBoundaryGroup())
FreeCADGui.addCommand("HOMesh_HighOrderMesh", CommandHighOrderMesh())
FreeCADGui.addCommand("HOMesh_CurveFemMesh", CommandCurveFemMesh())
FreeCADGui.addCommand("HOMesh_ToFemMesh", CommandToFemMesh())
FreeCADGui.addCommand("HOMesh_BoundaryLayer", CommandBoundaryLayer())
FreeCADGui.addCommand("HOMesh_Sizing", CommandSizing())
