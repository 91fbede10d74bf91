"""Writes the FEM mesh files of tests/python/test_fem_formats.py with FreeCAD itself
(Fem::FemMesh.write, the FEM workbench's own writers of .unv, .vtk and .vtu).

Run:  freecadcmd -c "import runpy; runpy.run_path('tests/data/fem/make_fem_files.py',
                     run_name='__main__')"
Files go to $HOMESH_FEM_OUT (default: this folder); $HOMESH_FEM_FILES names the groups to write
(default "disc,tet10", the files committed here; the test writes "cylinder" itself, its files
being 700 kB: FEM's Gmsh settings give about 850 tetrahedra whatever the size asked for). FEM's
Gmsh mesher needs the gmsh command.

- cylinder_p1.{unv,vtk}, cylinder_p2.{unv,vtk,vtu}: FEM's Gmsh mesh of a cylinder (radius 1,
  height 2, CharacteristicLengthMax 1), first and second order (tetra10 with the boundary
  mid-edge nodes on the cylinder).
- disc_p2.{unv,vtk}: FEM's Gmsh mesh of a planar disc (radius 1, CharacteristicLengthMax 0.5),
  second order (tria6).
- tet10_cases.{unv,vtk,vtu}: six disjoint 10-node tetrahedra built node by node (addNode,
  addVolume in SMESH's order), each the unit tetrahedron A=(0,0,0) B=(1,0,0) C=(0,1,0)
  D=(0,0,1) shifted by 3k along x, with the mid-edge node of AB placed as CASES says. The
  mid-edge node m of AB moved by d from the midpoint changes the volume by
  d . (A_ABC n_ABC + A_ABD n_ABD) / 3 = -(d_y + d_z) / 6 and the Jacobian at B by the factor
  1 - 4 d . grad(lambda_B) ... (see the test): valid iff the factor stays positive.
"""

import os
import sys

import FreeCAD
import Fem
import ObjectsFem
import Part

OUT = os.environ.get("HOMESH_FEM_OUT") or os.path.dirname(os.path.abspath(__file__))
GROUPS = (os.environ.get("HOMESH_FEM_FILES") or "disc,tet10").split(",")

# (name, offset of AB's mid-edge node from the midpoint (0.5, 0, 0))
CASES = [
    ("straight", (0.0, 0.0, 0.0)),
    ("bulged", (0.0, -0.1, -0.1)),       # outwards: volume 1/6 + 1/30 = 0.2, valid
    ("pushed_0.10", (0.0, 0.1, 0.1)),    # inwards, J(B) factor 1 - 8 * 0.10 = 0.2: valid
    ("pushed_0.15", (0.0, 0.15, 0.15)),  # inwards, factor 1 - 8 * 0.15 = -0.2: invalid
    ("along_0.20", (-0.3, 0.0, 0.0)),    # at t = 0.2 along AB: J(A) factor 4t - 1 < 0: invalid
    ("along_0.30", (-0.2, 0.0, 0.0)),    # at t = 0.3: 4t - 1 = 0.2: valid
]


def gmsh_mesh(doc, shape_object, order, size):
    from femmesh.gmshtools import GmshTools
    mesh = ObjectsFem.makeMeshGmsh(doc, "FEMMeshGmsh")
    mesh.Part = shape_object
    mesh.CharacteristicLengthMax = size
    mesh.ElementOrder = order
    doc.recompute()
    error = GmshTools(mesh).create_mesh()
    if error:
        raise RuntimeError(error)
    return mesh.FemMesh


def tet10_cases():
    fem = Fem.FemMesh()
    node = 0
    for k, (_, d) in enumerate(CASES):
        shift = FreeCAD.Vector(3.0 * k, 0, 0)
        a, b, c, dd = (FreeCAD.Vector(*p) + shift for p in
                       [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)])
        m_ab = (a + b) * 0.5 + FreeCAD.Vector(*d)
        # SMESH: corners turning clockwise seen from the fourth (A, C, B, D), then the mid-edge
        # nodes of its edges (0,1) (1,2) (2,0) (0,3) (1,3) (2,3): AC, CB, BA, AD, CD, BD.
        points = [a, c, b, dd, (a + c) * 0.5, (c + b) * 0.5, m_ab, (a + dd) * 0.5,
                  (c + dd) * 0.5, (b + dd) * 0.5]
        ids = []
        for p in points:
            node += 1
            fem.addNode(p.x, p.y, p.z, node)
            ids.append(node)
        fem.addVolume(ids, k + 1)
    return fem


def main():
    doc = FreeCAD.newDocument("HOMeshFemFiles")
    cylinder = doc.addObject("Part::Cylinder", "Cylinder")
    cylinder.Radius, cylinder.Height = 1.0, 2.0
    disc = doc.addObject("Part::Feature", "Disc")
    disc.Shape = Part.Face(Part.Wire(Part.makeCircle(1.0)))
    doc.recompute()
    written = []

    def write(fem, name, formats):
        for ext in formats:
            written.append(os.path.join(OUT, "%s.%s" % (name, ext)))
            fem.write(written[-1])

    if "cylinder" in GROUPS:
        write(gmsh_mesh(doc, cylinder, "1st", 1.0), "cylinder_p1", ("unv", "vtk"))
        write(gmsh_mesh(doc, cylinder, "2nd", 1.0), "cylinder_p2", ("unv", "vtk", "vtu"))
    if "disc" in GROUPS:
        write(gmsh_mesh(doc, disc, "2nd", 0.5), "disc_p2", ("unv", "vtk"))
    if "tet10" in GROUPS:
        write(tet10_cases(), "tet10_cases", ("unv", "vtk", "vtu"))
    FreeCAD.closeDocument(doc.Name)
    for path in written:
        print("wrote", path)


if __name__ == "__main__":
    main()
    sys.exit(0)
