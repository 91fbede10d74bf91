"""Documents saved before homesh/freecad was split by role (tests/data/freecad/
before_split.FCStd, made by the script beside it) reopen: their proxies' classes are found
where those documents name them, the stored mesh reads back without a recompute, and every
object recomputes valid."""

import os
import shutil
import tempfile
import unittest

import FreeCAD

import homesh.freecad

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "freecad",
                    "before_split.FCStd")


class DocumentsFromBeforeTheSplit(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp()
        path = os.path.join(self.folder, "before_split.FCStd")
        shutil.copy(DATA, path)  # the committed file is never written
        self.doc = FreeCAD.openDocument(path)

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)
        shutil.rmtree(self.folder, ignore_errors=True)

    def test_every_object_gets_its_proxy_back(self):
        types = sorted(o.Proxy.Type for o in self.doc.Objects if hasattr(o, "Proxy"))
        self.assertEqual(types, ["HOMesh::BoundaryGroup", "HOMesh::BoundaryLayer",
                                 "HOMesh::HighOrderMesh", "HOMesh::MeshRegion",
                                 "HOMesh::Sizing"])

    def test_the_stored_mesh_reads_back_and_the_objects_recompute(self):
        mesh = self.doc.getObject("HighOrderMesh")
        stored = homesh.freecad.get_mesh(mesh)
        self.assertIsNotNone(stored)
        self.assertEqual((stored.num_nodes, stored.num_elements, stored.order),
                         (mesh.NumNodes, mesh.NumElements, 2))
        for obj in self.doc.Objects:
            obj.touch()
        self.doc.recompute()
        for obj in self.doc.Objects:
            self.assertTrue(obj.isValid(), obj.Label)
        self.assertEqual(homesh.freecad.get_mesh(mesh).order, 2)
        self.assertEqual(len(mesh.Regions), 1)
        self.assertEqual(len(mesh.Groups), 1)


if __name__ == "__main__":
    unittest.main()
