"""The BoundaryLayer object: faces picked on the shape, its link from a HighOrderMesh (prisms in
the mesh, certified valid), wrong links and values that leave FreeCAD running, save and reopen."""

import os
import tempfile
import unittest

import FreeCAD

import homesh
import homesh.freecad

from fixtures import box_with_hole


def hole_face(part):
    """FreeCAD's number of the box's cylindrical hole face."""
    (index,) = [i + 1 for i, f in enumerate(part.Shape.Faces)
                if f.Surface.__class__.__name__ == "Cylinder"]
    return index


class BoundaryLayerObject(unittest.TestCase):
    def setUp(self):
        self.doc = FreeCAD.newDocument("HOMeshBoundaryLayerTest")
        self.part = box_with_hole(self.doc)
        self.face = hole_face(self.part)

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def make(self, **kwargs):
        args = dict(thickness=0.1, layers=3, progression=1.3)
        args.update(kwargs)
        layer = homesh.freecad.make_boundary_layer(self.doc, self.part, [self.face], **args)
        mesh = homesh.freecad.make_high_order_mesh(self.doc, self.part, order=2, size=0.5,
                                                   boundary_layer=layer)
        return layer, mesh

    def test_the_mesh_has_the_layer_and_is_valid(self):
        layer, mesh = self.make()
        self.doc.recompute()
        self.assertTrue(layer.isValid() and mesh.isValid(), layer.Status)
        # 0.1 (1 - 1.3) / (1 - 1.3^3): the same formula, a few ulps apart at most.
        self.assertAlmostEqual(layer.FirstLayerHeight, 0.1 * 0.3 / (1.3 ** 3 - 1), places=12)
        self.assertIn("1 faces of Cut", layer.Status)
        m = homesh.freecad.get_mesh(mesh)
        report = m.report()
        self.assertEqual(report["boundary_layer"]["faces"], [self.face])
        self.assertEqual(report["elements"]["prism"],
                         3 * report["boundary_layer"]["macro_cells"])
        self.assertGreater(report["elements"]["prism"], 0)
        self.assertEqual(mesh.InvalidElements, 0)
        self.assertGreater(mesh.MinScaledJacobian, 0.0)
        self.assertEqual(mesh.NumElements, report["elements"]["tet"] + report["elements"]["prism"])

        # Saved and reopened: the link, the faces and the mesh come back.
        path = os.path.join(tempfile.mkdtemp(), "layer.FCStd")
        self.doc.saveAs(path)
        names = mesh.Name, layer.Name
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        mesh, layer = (self.doc.getObject(name) for name in names)
        self.assertEqual(mesh.BoundaryLayer, layer)
        self.assertEqual(list(layer.Faces[1]), ["Face%d" % self.face])
        self.assertEqual(homesh.freecad.get_mesh(mesh).report()["elements"]["prism"],
                         report["elements"]["prism"])

    def test_wrong_faces_and_values_fail_with_a_message(self):
        other = self.doc.addObject("Part::Box", "Other")
        self.doc.recompute()
        layer, mesh = self.make()
        layer.Faces = (other, ["Face1"])
        self.doc.recompute()
        self.assertFalse(mesh.isValid())
        layer.Faces = (self.part, ["Edge1"])
        self.doc.recompute()
        self.assertIn("Faces must name faces", layer.Status)
        layer.Faces = (self.part, ["Face%d" % self.face])
        layer.Thickness = "0.1*q"
        self.doc.recompute()
        self.assertTrue(layer.isValid())  # an expression: the core checks it when meshing
        self.assertEqual(layer.FirstLayerHeight, 0.0)
        self.assertFalse(mesh.isValid())
        layer.Thickness = "0.1"
        self.doc.recompute()
        self.assertTrue(mesh.isValid())
        self.assertEqual(mesh.InvalidElements, 0)


class BoundaryLayerBetweenSolids(unittest.TestCase):
    """A ball inside a box with its hole (two solids of one compound, imprinted by the core so
    that the ball's face lies between them): the layer on it grows into the solid its Solids
    property names, and without one the mesh fails with a message that says how to name it."""

    def setUp(self):
        self.doc = FreeCAD.newDocument("HOMeshLayerBetweenSolids")
        import Part
        ball = Part.makeSphere(1, FreeCAD.Vector(2, 2, 2))
        self.part = self.doc.addObject("Part::Feature", "BallInBox")
        self.part.Shape = Part.makeCompound([Part.makeBox(4, 4, 4).cut(ball), ball])
        self.doc.recompute()
        (self.face,) = [i + 1 for i, f in enumerate(self.part.Shape.Solids[0].Faces)
                        if f.Surface.__class__.__name__ == "Sphere"]

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_the_layer_grows_into_the_solid_named(self):
        layer = homesh.freecad.make_boundary_layer(self.doc, self.part, [self.face],
                                                   thickness=0.1, layers=2)
        mesh = homesh.freecad.make_high_order_mesh(self.doc, self.part, order=2, size=0.8,
                                                   boundary_layer=layer)
        self.doc.recompute()
        self.assertFalse(mesh.isValid())
        self.assertIn("name the one the layer grows into", mesh.Status)
        layer.Solids = [1]  # the box around the ball
        self.doc.recompute()
        self.assertTrue(mesh.isValid(), mesh.Status)
        report = homesh.freecad.get_mesh(mesh).report()
        self.assertEqual(report["boundary_layer"]["solids"], [1])
        self.assertEqual(report["elements"]["prism"],
                         2 * report["boundary_layer"]["macro_cells"])
        self.assertGreater(report["elements"]["prism"], 0)
        self.assertEqual(mesh.InvalidElements, 0)


if __name__ == "__main__":
    unittest.main()
