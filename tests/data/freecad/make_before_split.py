"""Made tests/data/freecad/before_split.FCStd with the workbench of commit 088a005, before
homesh/freecad was split by role: its Document.xml names the proxies' classes as
homesh.freecad.objects.{HighOrderMesh,Sizing,BoundaryLayer}Proxy and
homesh.freecad.regions.{MeshRegion,BoundaryGroup}Proxy, which later versions must still
find (tests/freecad/test_old_documents.py).

Run (OUT: the file to write) from a build of that commit:
  OUT=before_split.FCStd tests/tools/with_freecad_home.py BUILD freecadcmd -c \
    "import runpy; runpy.run_path('tests/data/freecad/make_before_split.py', run_name='__main__')"
"""

import os
import sys

import FreeCAD

here = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else os.getcwd()
sys.path.insert(0, os.path.join(here, "..", "..", "freecad"))
from fixtures import box_with_hole  # noqa: E402

import homesh.freecad  # noqa: E402

ok = True
try:
    doc = FreeCAD.newDocument("Old")
    cut = box_with_hole(doc)
    sizing = homesh.freecad.make_sizing(doc, cut, max_delta=1.5)
    mesh = homesh.freecad.make_high_order_mesh(doc, cut, order=2, sizing=sizing)
    face = [i + 1 for i, f in enumerate(cut.Shape.Faces)
            if f.Surface.__class__.__name__ == "Cylinder"][0]
    layer = homesh.freecad.make_boundary_layer(doc, cut, [face], "0.1")
    homesh.freecad.make_mesh_region(doc, mesh, [(cut, ["Vertex1"])], 0.5)
    homesh.freecad.make_boundary_group(doc, mesh, [(cut, ["Face%d" % face])], "wall")
    mesh.Threads = 1
    doc.recompute()
    for o in doc.Objects:
        assert o.isValid(), o.Label
    print(mesh.Status)
    doc.saveAs(os.environ["OUT"])
except Exception:  # noqa: BLE001 - freecadcmd would exit 0 on an uncaught exception
    import traceback
    traceback.print_exc()
    ok = False
sys.exit(0 if ok else 1)
