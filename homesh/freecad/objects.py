"""The HighOrderMesh document object: properties, recompute and persistence.

The proxy only holds properties and runs the core; drawing lives in viewproviders.py. The curved
mesh is stored inside the .FCStd as a compressed array file (property MeshData), so reopening a
document shows and exports the mesh without recomputing it.
"""

import os
import shutil
import tempfile

import FreeCAD

TYPE_HIGH_ORDER_MESH = "HOMesh::HighOrderMesh"

_RESULT_PROPERTIES = ("NumNodes", "NumElements", "MinScaledJacobian", "InvalidElements")


def make_high_order_mesh(doc, part, order=4, size=0.0, name="HighOrderMesh"):
    """Adds a HighOrderMesh object meshing ``part`` (a document object with a Shape).

    ``size`` 0 means automatic (bounding-box diagonal / 20). The caller recomputes.
    """
    obj = doc.addObject("App::FeaturePython", name)
    HighOrderMeshProxy(obj)
    obj.Part = part
    obj.Order = order
    obj.Size = size
    if FreeCAD.GuiUp:
        from .viewproviders import ViewProviderHighOrderMesh
        ViewProviderHighOrderMesh(obj.ViewObject)
    return obj


def get_mesh(obj):
    """The :class:`homesh.HighOrderMesh` of a HighOrderMesh object (from the last recompute,
    or read back from the document), or None if it has none or its last recompute failed (the
    view then still shows the last good mesh, as FreeCAD does for failed features)."""
    if not obj.isValid():
        return None
    proxy = getattr(obj, "Proxy", None)
    cached = getattr(proxy, "mesh", None)
    if cached is not None:
        return cached
    path = getattr(obj, "MeshData", "")
    if not path or not os.path.isfile(path):
        return None
    import homesh
    mesh = homesh.load(path)
    if proxy is not None:
        proxy.mesh = mesh
    return mesh


class HighOrderMeshProxy:
    """Proxy of an App::FeaturePython that meshes its ``Part`` with curved elements."""

    Type = TYPE_HIGH_ORDER_MESH

    def __init__(self, obj):
        obj.Proxy = self
        self.mesh = None
        self.add_properties(obj)

    @staticmethod
    def add_properties(obj):
        """Adds missing properties; safe to call again on documents from older versions."""
        have = obj.PropertiesList
        if "Part" not in have:
            obj.addProperty("App::PropertyLink", "Part", "Mesh", "Shape to mesh")
        if "Order" not in have:
            obj.addProperty("App::PropertyIntegerConstraint", "Order", "Mesh",
                            "Polynomial order of the elements (1 to 10)")
            obj.Order = (4, 1, 10, 1)
        if "Size" not in have:
            obj.addProperty("App::PropertyLength", "Size", "Mesh",
                            "Target element size; 0 chooses a twentieth of the bounding-box "
                            "diagonal")
        if "OptimiserIterations" not in have:
            obj.addProperty("App::PropertyIntegerConstraint", "OptimiserIterations", "Mesh",
                            "Most sweeps of the variational optimiser after curving (0: none; "
                            "it stops earlier once the mesh is valid and no longer improving); "
                            "boundary nodes slide on the CAD")
            obj.OptimiserIterations = (20, 0, 1000, 1)
        if "MeshData" not in have:
            obj.addProperty("App::PropertyFileIncluded", "MeshData", "Result",
                            "The curved mesh, stored in the document")
            obj.setEditorMode("MeshData", 2)  # hidden
        for prop, kind, doc in (
                ("NumNodes", "App::PropertyInteger", "Number of nodes"),
                ("NumElements", "App::PropertyInteger", "Number of volume (2D: surface) elements"),
                ("MinScaledJacobian", "App::PropertyFloat",
                 "Worst scaled Jacobian (min J / max J); <= 0 means an invalid element"),
                ("InvalidElements", "App::PropertyInteger", "Elements with non-positive Jacobian")):
            if prop not in have:
                obj.addProperty(kind, prop, "Result", doc)
                obj.setEditorMode(prop, 1)  # read-only

    def onDocumentRestored(self, obj):
        self.mesh = None
        self.add_properties(obj)

    def execute(self, obj):
        import homesh
        self.mesh = None
        if obj.Part is None:
            raise ValueError("%s: no shape to mesh (set its Part property)" % obj.Label)
        shape = getattr(obj.Part, "Shape", None)
        if shape is None or shape.isNull():
            raise ValueError("%s: %s has no shape" % (obj.Label, obj.Part.Label))
        size = obj.Size.Value if obj.Size.Value > 0 else None
        progress = _Progress(obj.Label)
        try:
            mesh = homesh.mesh(shape, order=obj.Order, size=size, progress=progress,
                               name=obj.Part.Label, optimise=obj.OptimiserIterations)
        except homesh.HOMeshError as e:
            FreeCAD.Console.PrintError("HOMesh: %s: %s\n" % (obj.Label, e))
            raise
        finally:
            progress.stop()
        folder = tempfile.mkdtemp(prefix="homesh-")
        try:
            path = os.path.join(folder, "mesh.npz")
            mesh.write(path)
            obj.MeshData = path  # FreeCAD copies the file into the document
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        self.mesh = mesh
        quality = mesh.quality()
        obj.NumNodes = mesh.num_nodes
        obj.NumElements = mesh.num_elements
        obj.MinScaledJacobian = float(quality["min"])
        obj.InvalidElements = int(quality["invalid_elements"])
        FreeCAD.Console.PrintMessage(
            "HOMesh: %s: %d nodes, %d elements of order %d, worst scaled Jacobian %.3f, "
            "%d invalid\n" % (obj.Label, mesh.num_nodes, mesh.num_elements, mesh.order,
                              quality["min"], quality["invalid_elements"]))

    # Persistence: the proxy has no state of its own (FreeCAD 0.20 uses __getstate__, 0.21+
    # dumps).
    def __getstate__(self):
        return {"Type": self.Type}

    def __setstate__(self, state):
        self.mesh = None

    def dumps(self):
        return self.__getstate__()

    def loads(self, state):
        self.__setstate__(state)


class _Progress:
    """Reports pipeline stages to FreeCAD's progress bar (GUI) and report view."""

    STAGES = 4

    def __init__(self, label):
        self.label = label
        self.bar = None
        if FreeCAD.GuiUp:
            self.bar = FreeCAD.Base.ProgressIndicator()
            self.bar.start("HOMesh: meshing %s" % label, self.STAGES)

    def __call__(self, stage, seconds):
        if seconds is None:
            return
        FreeCAD.Console.PrintLog("HOMesh: %s: %s %.3f s\n" % (self.label, stage, seconds))
        if self.bar is not None:
            self.bar.next()

    def stop(self):
        if self.bar is not None:
            self.bar.stop()
            self.bar = None
