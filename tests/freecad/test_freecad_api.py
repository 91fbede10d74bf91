"""`import homesh` inside freecadcmd: meshing Part shapes, arrays, and errors that leave FreeCAD
running."""

import os
import tempfile
import unittest

import FreeCAD
import Part
import numpy as np

import homesh


class MeshingPartShapes(unittest.TestCase):
    def test_sphere_order_4(self):
        m = homesh.mesh(Part.makeSphere(1.0), order=4, size=0.3)
        self.assertEqual(m.order, 4)
        self.assertEqual(m.elements.shape[1], 35)
        on_cad = m.node_cad_dim <= 2  # points of OCCT's sphere: 1 to rounding, 1e-7 is slack
        self.assertTrue(np.all(np.abs(np.linalg.norm(m.nodes[on_cad], axis=1) - 1.0) < 1e-7))
        self.assertEqual(m.quality()["invalid_elements"], 0)

    def test_placement_is_respected(self):
        shape = Part.makeBox(1, 2, 3)
        shape.Placement = FreeCAD.Placement(FreeCAD.Vector(10, 0, 0), FreeCAD.Rotation())
        m = homesh.mesh(shape, order=2, size=0.5)
        # A translation by an integer of integer coordinates: exact; 1e-9 is slack.
        self.assertAlmostEqual(float(m.nodes[:, 0].min()), 10.0, places=9)
        self.assertAlmostEqual(float(m.nodes[:, 0].max()), 11.0, places=9)

    def test_freecad_face_numbering(self):
        """Boundary triangles carry FreeCAD's FaceN: each lies on that face of the shape."""
        shape = Part.makeBox(4, 4, 2).cut(Part.makeCylinder(1, 2, FreeCAD.Vector(2, 2, 0)))
        m = homesh.mesh(shape, order=3, size=0.8)
        (tris,) = [b for b in m.boundary if b.element_type == "tri"]
        self.assertEqual(set(tris.cad_entity.tolist()), set(range(1, len(shape.Faces) + 1)))
        for face_index in set(tris.cad_entity.tolist()):
            face = shape.Faces[face_index - 1]
            nodes = np.unique(tris.elements[tris.cad_entity == face_index])
            # Nodes are S(u, v) of the face (~1e-15 off); a node on the wrong face is >= 0.1 off.
            for p in m.nodes[nodes[:: max(1, len(nodes) // 20)]]:
                self.assertLess(face.distToShape(Part.Vertex(FreeCAD.Vector(*p)))[0], 1e-7)

    def test_compound_of_solids(self):
        compound = Part.makeCompound([Part.makeBox(1, 1, 1),
                                      Part.makeSphere(0.5, FreeCAD.Vector(3, 0, 0))])
        m = homesh.mesh(compound, order=2, size=0.3)
        self.assertEqual(set(m.element_entity.tolist()), {1, 2})

    def test_faces_in_no_solid_are_refused_or_left_out(self):
        """A solid beside an open shell: refused naming the shell's faces, or, with
        solids_only, the solid meshed and the faces named in the report and notes."""
        other = Part.makeBox(1, 1, 1, FreeCAD.Vector(2, 0, 0))
        compound = Part.makeCompound([Part.makeBox(1, 1, 1), Part.Shell(other.Faces[:5])])
        with self.assertRaises(homesh.CadError) as refused:
            homesh.mesh(compound, order=2, size=0.5, name="Compound")
        self.assertIn("5 faces (Face7-Face11) in no solid", str(refused.exception))
        self.assertIn("solids_only=True", str(refused.exception))
        m = homesh.mesh(compound, order=2, size=0.5, solids_only=True)
        report = m.report()
        self.assertIn("Face7-Face11", report["healing"]["left_out"])
        self.assertTrue(any(n.startswith("solids only: left out") for n in report["notes"]))
        # Only the unit box is meshed (its nodes are within the CAD's 1e-7 of it).
        self.assertLess(float(m.nodes[:, 0].max()), 1.0 + 1e-6)

    def test_planar_face(self):
        m = homesh.mesh(Part.makeCircle(1.0).toShape() if False else Part.Face(
            Part.Wire(Part.makeCircle(1.0))), order=4, size=0.25)
        self.assertEqual(m.dim, 2)
        self.assertEqual(m.element_type, "tri")
        on_circle = m.node_cad_dim == 1  # points of the circle: 1 to rounding
        self.assertTrue(np.all(np.abs(np.linalg.norm(m.nodes[on_circle], axis=1) - 1) < 1e-7))


class ErrorsKeepFreeCadRunning(unittest.TestCase):
    def test_bad_parameters_and_inputs_raise(self):
        box = Part.makeBox(1, 1, 1)
        with self.assertRaises(homesh.ParameterError):
            homesh.mesh(box, order=0)
        with self.assertRaises(homesh.ParameterError):
            homesh.mesh(box, size=-1)
        with self.assertRaises(homesh.ParameterError):
            homesh.mesh(Part.Shape())
        with self.assertRaises(homesh.FileError):
            homesh.mesh("/nonexistent/part.step")
        folder = tempfile.mkdtemp()
        fake = os.path.join(folder, "renamed.step")
        with open(fake, "w") as f:
            f.write("plain text\n")
        with self.assertRaises(homesh.FileError):
            homesh.mesh(fake)
        with self.assertRaises(homesh.CadError):  # a wire: nothing to mesh
            homesh.mesh(Part.Wire(Part.makeCircle(1.0)))
        with self.assertRaises(homesh.CadError):  # a curved face without a solid
            homesh.mesh(Part.makeCylinder(1, 1).Faces[0])
        # ...and the process is alive and meshing still works.
        self.assertGreater(homesh.mesh(box, order=1, size=0.5).num_elements, 0)
