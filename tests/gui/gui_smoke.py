"""GUI smoke test, run by FreeCAD itself under Xvfb (see tests/CMakeLists.txt):

activates the HOMesh workbench, selects a box-minus-cylinder, runs the toolbar command
"High-order mesh", and saves two screenshots to $HOMESH_SCREENSHOT_DIR: the 3D view rendered
off-screen (view.png) and the whole main window (window.png). It checks that the command made a
valid mesh object and that the rendered view shows it (pixels in the quality colour map).
FreeCAD's GUI never exits by itself, so the script ends with os._exit(status).
"""

import os
import sys
import traceback

status = 1
try:
    import FreeCAD
    import FreeCADGui
    from PySide2 import QtGui, QtWidgets

    out = os.environ.get("HOMESH_SCREENSHOT_DIR", os.getcwd())
    os.makedirs(out, exist_ok=True)

    assert "HOMeshWorkbench" in FreeCADGui.listWorkbenches(), "workbench not registered"
    FreeCADGui.activateWorkbench("HOMeshWorkbench")

    sys.path.insert(0, os.path.join(os.environ["HOMESH_TESTS_DIR"], "freecad"))
    from fixtures import box_with_hole

    doc = FreeCAD.newDocument("Smoke")
    cut = box_with_hole(doc)

    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(cut)
    FreeCADGui.runCommand("HOMesh_HighOrderMesh")
    meshes = [o for o in doc.Objects if getattr(o, "Proxy", None) is not None
              and getattr(o.Proxy, "Type", "") == "HOMesh::HighOrderMesh"]
    assert len(meshes) == 1, "the command made %d mesh objects" % len(meshes)
    mesh = meshes[0]
    assert mesh.isValid(), "the mesh object failed to recompute"
    assert mesh.NumElements > 0 and mesh.Order == 4
    assert not cut.ViewObject.Visibility, "the meshed shape should be hidden"
    print("HOMesh GUI smoke: %d nodes, %d elements, worst scaled Jacobian %.3f"
          % (mesh.NumNodes, mesh.NumElements, mesh.MinScaledJacobian))

    view = FreeCADGui.ActiveDocument.ActiveView
    view.viewIsometric()
    view.fitAll()
    for _ in range(10):
        QtWidgets.QApplication.processEvents()
    view_png = os.path.join(out, "view.png")
    view.saveImage(view_png, 800, 600, "White")
    window = FreeCADGui.getMainWindow()
    QtWidgets.QApplication.primaryScreen().grabWindow(window.winId()).save(
        os.path.join(out, "window.png"))

    # The rendered view must show the mesh: many pixels of the colour map (green to yellow,
    # little blue), none of which a white background or black edges have.
    image = QtGui.QImage(view_png)
    coloured = total = 0
    for y in range(0, image.height(), 4):
        for x in range(0, image.width(), 4):
            c = QtGui.QColor(image.pixel(x, y))
            total += 1
            if c.green() > 60 and c.green() > c.blue() + 40:
                coloured += 1
    fraction = coloured / float(total)
    print("HOMesh GUI smoke: %.0f %% of the view shows the mesh" % (100 * fraction))
    # The fitted isometric view of the 4 x 4 x 2 part fills about a third of the image; a view
    # without the mesh has no such pixels at all. 0.15 does not depend on rounding.
    assert fraction > 0.15, "the mesh is not visible in the 3D view"

    # A boundary layer on the hole: the face picked in the selection, the toolbar command,
    # the mesh recomputed with prisms and drawn again (layer.png).
    (hole,) = [i + 1 for i, f in enumerate(cut.Shape.Faces)
               if f.Surface.__class__.__name__ == "Cylinder"]
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(cut, "Face%d" % hole)
    FreeCADGui.runCommand("HOMesh_BoundaryLayer")
    assert mesh.BoundaryLayer is not None, "the command did not link the layer to the mesh"
    assert mesh.isValid() and mesh.InvalidElements == 0, "the mesh with a layer is not valid"
    import homesh.freecad
    prisms = homesh.freecad.get_mesh(mesh).report()["elements"]["prism"]
    assert prisms > 0, "no prisms in the mesh"
    print("HOMesh GUI smoke: with a boundary layer: %d elements (%d prisms), worst %.3f"
          % (mesh.NumElements, prisms, mesh.MinScaledJacobian))
    view.viewTop()
    view.fitAll()
    for _ in range(10):
        QtWidgets.QApplication.processEvents()
    view.saveImage(os.path.join(out, "layer.png"), 800, 600, "White")
    status = 0
except Exception:
    traceback.print_exc()
finally:
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
