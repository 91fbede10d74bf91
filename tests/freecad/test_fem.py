"""FEM both ways, headless: a FemMeshGmsh of a cylinder (made by FEM's own Gmsh tools) curved
into a certified valid order-4 mesh whose boundary nodes lie on the cylinder, and a HOMesh mesh
turned into a Fem::FemMeshObject of order 2 with the node and element counts of the order-2
mesh, SMESH's node order and FEM's orientation."""

import math
import os
import shutil
import tempfile
import unittest

import FreeCAD
import numpy as np

import homesh
import homesh.freecad
from homesh.freecad import fem

GMSH = shutil.which("gmsh")


def gmsh_fem_mesh(doc, part, order="2nd", size=0.5):
    import ObjectsFem
    from femmesh.gmshtools import GmshTools
    mesh = ObjectsFem.makeMeshGmsh(doc, "FEMMeshGmsh")
    mesh.Part = part
    mesh.CharacteristicLengthMax = size
    mesh.ElementOrder = order
    doc.recompute()
    error = GmshTools(mesh).create_mesh()
    assert not error, error
    return mesh


def corner_sign(fm, element):
    p = [fm.getNodeById(i) for i in fm.getElementNodes(element)[:4]]
    return math.copysign(1.0, (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]))


@unittest.skipIf(GMSH is None, "FEM's Gmsh mesher needs the gmsh command")
class FemBothWays(unittest.TestCase):
    def setUp(self):
        self.doc = FreeCAD.newDocument("HOMeshFem")
        self.cyl = self.doc.addObject("Part::Cylinder", "Cylinder")
        self.cyl.Radius, self.cyl.Height = 1.0, 2.0
        self.doc.recompute()

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_curve_a_gmsh_fem_mesh_of_a_cylinder(self):
        femmesh = gmsh_fem_mesh(self.doc, self.cyl)
        tets = femmesh.FemMesh.VolumeCount
        obj = homesh.freecad.make_high_order_mesh(self.doc, self.cyl, order=4,
                                                  fem_mesh=femmesh)
        obj.OptimiserIterations = 20
        self.doc.recompute()
        self.assertTrue(obj.isValid(), obj.Status)
        mesh = homesh.freecad.get_mesh(obj)
        quality = mesh.quality()
        self.assertEqual(mesh.order, 4)
        self.assertEqual(mesh.num_elements, tets)  # FEM's tetrahedra, curved, none added
        self.assertEqual(quality["invalid_elements"], 0)
        self.assertEqual(quality["undecided_elements"], 0)
        self.assertGreater(quality["min"], 0.0)
        # Every node on the lateral face (Face1 of Part's cylinder) at radius 1, every node on
        # the caps at z = 0 or 2; CAD evaluation rounds at |x| <= 2: 1e-12 is slack, a
        # straight-sided (uncurved) boundary is off by up to 0.03 at this size.
        lateral = [i + 1 for i, f in enumerate(self.cyl.Shape.Faces)
                   if f.Surface.__class__.__name__ == "Cylinder"]
        on_face = mesh.node_cad_dim == 2
        nodes = mesh.nodes
        radius = np.hypot(nodes[:, 0], nodes[:, 1])
        side = on_face & np.isin(mesh.node_cad_index, lateral)
        self.assertGreater(side.sum(), 100)
        self.assertLess(np.abs(radius[side] - 1.0).max(), 1e-12)
        caps = on_face & ~side
        self.assertLess(np.minimum(np.abs(nodes[caps, 2]), np.abs(nodes[caps, 2] - 2.0)).max(),
                        1e-12)
        # The linear mesh's nodes are FEM's corner nodes.
        corners = fem.fem_mesh_arrays(femmesh.FemMesh)[0]
        self.assertEqual(len(corners), len(set(map(tuple, corners))))
        self.assertIn("classify", mesh.timings())

    def test_curve_a_mesh_netgen_made_and_wrote(self):
        """Netgen itself (Debian's python3-netgen; Debian's FreeCAD is built without FEM's
        Netgen mesher) meshes the cylinder and writes the mesh (Abaqus .inp, 8 digits); FEM
        reads the file, and the HighOrderMesh object curves it at order 4, certified valid."""
        import Fem
        import netgen.NgOCC
        folder = tempfile.mkdtemp(prefix="homesh-netgen-test-")
        step, inp = os.path.join(folder, "cyl.step"), os.path.join(folder, "cyl.inp")
        self.cyl.Shape.exportStep(step)
        netgen.NgOCC.LoadOCCGeometry(step).GenerateMesh(maxh=0.5).Export(inp, "Abaqus Format")
        femmesh = self.doc.addObject("Fem::FemMeshObject", "NetgenMesh")
        femmesh.FemMesh = Fem.read(inp)
        tets = femmesh.FemMesh.VolumeCount
        self.assertGreater(tets, 100)
        self.curve_at_order_four(femmesh, tets, optimise=20)
        shutil.rmtree(folder)

    def test_curve_a_fem_mesh_of_prisms(self):
        """A FEM mesh of prisms (Gmsh's cylinder made by extruding its disk in 4 layers, put
        into a Fem::FemMesh as SMESH's 6-node volumes) curved by a HighOrderMesh object at
        order 4, certified valid: Curve FEM mesh takes every volume type FEM holds."""
        import Fem
        folder = tempfile.mkdtemp(prefix="homesh-fem-prisms-")
        geo, msh = os.path.join(folder, "cyl.geo"), os.path.join(folder, "cyl.msh")
        with open(geo, "w") as f:
            f.write('SetFactory("OpenCASCADE");\nDisk(1) = {0, 0, 0, 1};\n'
                    "Extrude {0, 0, 2} { Surface{1}; Layers{4}; Recombine; }\n"
                    "Mesh.MeshSizeMax = 0.5;\n")
        import subprocess
        subprocess.run([GMSH, geo, "-3", "-format", "msh41", "-o", msh], check=True,
                       capture_output=True)
        given = homesh.read(msh)
        blocks = [b for b in given.element_blocks if b.element_type == "prism"]
        self.assertEqual(len(blocks), 1)
        fm = Fem.FemMesh()
        for k, x in enumerate(given.nodes):
            fm.addNode(float(x[0]), float(x[1]), float(x[2]), k + 1)
        for cell in blocks[0].elements:
            fm.addVolume([int(n) + 1 for n in cell])
        femmesh = self.doc.addObject("Fem::FemMeshObject", "Prisms")
        femmesh.FemMesh = fm
        self.assertEqual(fm.PrismCount, len(blocks[0].elements))
        self.curve_at_order_four(femmesh, len(blocks[0].elements), optimise=0)
        shutil.rmtree(folder)

    def curve_at_order_four(self, femmesh, cells, optimise):
        """A HighOrderMesh object curving `femmesh` on the cylinder at order 4: certified valid,
        with the FEM mesh's `cells`, and every node on the lateral face at radius 1 (CAD
        evaluation rounding, as above)."""
        obj = homesh.freecad.make_high_order_mesh(self.doc, self.cyl, order=4,
                                                  fem_mesh=femmesh)
        obj.OptimiserIterations = optimise
        self.doc.recompute()
        self.assertTrue(obj.isValid(), obj.Status)
        mesh = homesh.freecad.get_mesh(obj)
        quality = mesh.quality()
        self.assertEqual(mesh.num_elements, cells)
        self.assertEqual(quality["invalid_elements"] + quality["undecided_elements"], 0)
        lateral = [i + 1 for i, f in enumerate(self.cyl.Shape.Faces)
                   if f.Surface.__class__.__name__ == "Cylinder"]
        side = (mesh.node_cad_dim == 2) & np.isin(mesh.node_cad_index, lateral)
        self.assertGreater(side.sum(), 100)
        radius = np.hypot(mesh.nodes[side, 0], mesh.nodes[side, 1])
        self.assertLess(np.abs(radius - 1.0).max(), 1e-12)

    def test_to_fem_mesh_has_the_counts_of_the_order_two_mesh(self):
        own = gmsh_fem_mesh(self.doc, self.cyl).FemMesh
        signs = {corner_sign(own, element) for element in own.Volumes}
        self.assertEqual(len(signs), 1)
        self.fem_sign = signs.pop()
        order4 = homesh.freecad.make_high_order_mesh(self.doc, self.cyl, order=4, size=0.5)
        order2 = homesh.freecad.make_high_order_mesh(self.doc, self.cyl, order=2, size=0.5)
        order4.OptimiserIterations = order2.OptimiserIterations = 0
        order4.RepairRounds = order2.RepairRounds = 0
        self.doc.recompute()
        m2 = homesh.freecad.get_mesh(order2)
        for source in (order4, order2):
            target = fem.make_fem_mesh_object(self.doc, source)
            self.doc.recompute()
            fm = target.FemMesh
            self.assertEqual(fm.NodeCount, m2.num_nodes)
            self.assertEqual(fm.VolumeCount, m2.num_elements)
            self.assertEqual(fm.TetraCount, m2.num_elements)
            # SMESH's node order: in every element each mid-edge node is nearer the midpoint
            # of its own edge's corners (SMESH's edges (0,1) (1,2) (2,0) (0,3) (1,3) (2,3))
            # than that of any other edge. The curved node is off its chord's midpoint by the
            # edge's sagitta, far less than the distance between two edges' midpoints (half
            # an edge length at least); a wrong order swaps nodes between edges.
            edges = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))
            for element in fm.Volumes:
                p = [fm.getNodeById(i) for i in fm.getElementNodes(element)]
                mids = [(p[a] + p[b]) * 0.5 for a, b in edges]
                for k in range(6):
                    nearest = min(range(6), key=lambda j: (p[4 + k] - mids[j]).Length)
                    self.assertEqual(nearest, k, (element, k))
            # Oriented as FEM's own meshes are: the corners' signed volume has the sign it has
            # in every element of FEM's Gmsh mesh of the same shape (SMESH turns the other
            # way from Gmsh).
            for element in fm.Volumes:
                self.assertEqual(corner_sign(fm, element), self.fem_sign, element)

    def test_fem_files_of_a_quadratic_mesh_are_read_with_their_curved_geometry(self):
        # FEM's own writers (.unv, .vtk, .vtu) and read_fem_mesh: the same certified verdicts
        # on the same curved elements; the volume is the cylinder's to O(h^4) (measured 1e-5
        # relative at this size, 1e-2 for the straight-sided first-order mesh).
        femmesh = gmsh_fem_mesh(self.doc, self.cyl, order="2nd")
        fm = femmesh.FemMesh
        folder = tempfile.mkdtemp(prefix="homesh-fem-test-")
        try:
            meshes = [fem.read_fem_mesh(fm)]
            for ext in ("unv", "vtk", "vtu"):
                path = os.path.join(folder, "mesh." + ext)
                fm.write(path)
                meshes.append(homesh.read(path))
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        reference = meshes[0].quality()
        for mesh in meshes:
            self.assertEqual(mesh.order, 2)
            self.assertEqual(mesh.num_elements, fm.VolumeCount)
            quality = mesh.quality()
            self.assertEqual(quality["invalid_elements"], 0)
            self.assertEqual(quality["undecided_elements"], 0)
            np.testing.assert_array_equal(quality["validity"], reference["validity"])
            volume = mesh.element_volumes().sum()
            self.assertLess(abs(volume - 2 * math.pi), 1e-4 * 2 * math.pi)

    def test_a_fem_mesh_without_volumes_or_faces_is_refused(self):
        class Empty:
            Volumes = ()
            Faces = ()
        with self.assertRaisesRegex(ValueError, "no volume or face elements"):
            fem.fem_mesh_arrays(Empty())

    def test_curve_a_2d_gmsh_fem_mesh_of_a_disk(self):
        """FEM's Gmsh mesher on a disk (a face, no solid) gives triangles; Curve FEM mesh makes
        them order 4, certified valid, every boundary node on the circle."""
        import Part
        disk = self.doc.addObject("Part::Feature", "Disk")
        disk.Shape = Part.Face(Part.Wire(Part.makeCircle(1.0)))
        self.doc.recompute()
        femmesh = gmsh_fem_mesh(self.doc, disk, order="1st", size=0.3)
        triangles = femmesh.FemMesh.FaceCount
        self.assertGreater(triangles, 20)
        obj = homesh.freecad.make_high_order_mesh(self.doc, disk, order=4, fem_mesh=femmesh)
        self.doc.recompute()
        self.assertTrue(obj.isValid(), obj.Status)
        mesh = homesh.freecad.get_mesh(obj)
        self.assertEqual((mesh.dim, mesh.order, mesh.num_elements), (2, 4, triangles))
        quality = mesh.quality()
        self.assertEqual(quality["invalid_elements"], 0)
        self.assertEqual(quality["undecided_elements"], 0)
        on_curve = mesh.node_cad_dim <= 1
        self.assertGreater(on_curve.sum(), 40)
        radius = np.hypot(mesh.nodes[on_curve, 0], mesh.nodes[on_curve, 1])
        self.assertLess(np.abs(radius - 1.0).max(), 1e-12)


if __name__ == "__main__":
    unittest.main()
