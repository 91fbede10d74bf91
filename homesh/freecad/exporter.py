"""File > Export of HighOrderMesh objects (registered in Init.py): .msh (Gmsh), .vtu (ParaView),
.xml (Nektar++) and .cgns (CGNS, orders 1 to 4), with the mesh's BoundaryGroup children as named
physical groups / composites / boundary conditions."""

import FreeCAD

from .arguments import mesh_groups
from .object_types import is_high_order_mesh
from .stored_mesh import get_mesh


def export(objects, filename):
    meshes = [o for o in objects if is_high_order_mesh(o)]
    if len(meshes) != 1:
        FreeCAD.Console.PrintError("HOMesh: select exactly one high-order mesh to export\n")
        return
    mesh = get_mesh(meshes[0])
    if mesh is None:
        FreeCAD.Console.PrintError(
            "HOMesh: %s has no valid mesh (never computed, or its last recompute failed): "
            "nothing exported\n" % meshes[0].Label)
        return
    import homesh
    try:
        groups = mesh_groups(meshes[0])
        mesh.write(filename, groups=groups)
    except (ValueError, homesh.HOMeshError) as e:
        FreeCAD.Console.PrintError("HOMesh: %s: nothing exported: %s\n" % (meshes[0].Label, e))
        return
    FreeCAD.Console.PrintMessage("HOMesh: wrote %s%s\n" % (
        filename, " with groups %s" % ", ".join(groups) if groups else ""))
