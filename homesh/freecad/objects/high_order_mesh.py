"""The HighOrderMesh document object: a curved mesh of its ``Part``, its parameters as
properties (from the core's parameter table), and recompute (meshing.py does the work). The
proxy only holds properties and runs the job; drawing lives in viewproviders.py, the mesh's
storage in stored_mesh.py.
"""

import FreeCAD

from ..meshing import (DEFAULT_ELEMENT_LIMIT, LargeMeshError, apply_result,
                       check_element_limit, job_for)
from ..object_types import TYPE_HIGH_ORDER_MESH
from ..properties import add_parameter_property
from .base import GuardedProxy


def make_high_order_mesh(doc, part, order=None, size=None, name="HighOrderMesh", sizing=None,
                         boundary_layer=None, fem_mesh=None):
    """Adds a HighOrderMesh object meshing ``part`` (a document object with a Shape).

    ``order`` and ``size`` left out (None) keep the parameter table's defaults. ``size`` 0
    means automatic: the sizing octree of ``sizing`` (a Sizing object, see
    :func:`make_sizing`) if given, else the automatic sizing octree (MaxDelta a twentieth of the
    bounding-box diagonal, MinDelta the smallest size the shape asks for, at most a twentieth
    of MaxDelta, EPS the table's default).
    ``boundary_layer``: a BoundaryLayer object on faces of ``part``
    (:func:`make_boundary_layer`). ``fem_mesh``: a
    FEM mesh object of ``part`` (FEM's Gmsh or Netgen mesher) to curve instead of meshing
    ``part`` (size, sizing and boundary layer then do not apply). The caller recomputes.
    """
    obj = doc.addObject("App::FeaturePython", name)
    HighOrderMeshProxy(obj)
    obj.Part = part
    if order is not None:
        obj.Order = order
    if size is not None:
        obj.Size = size
    obj.Sizing = sizing
    obj.BoundaryLayer = boundary_layer
    obj.FemMesh = fem_mesh
    if FreeCAD.GuiUp:  # headless, objects have no ViewObject
        from ..viewproviders import ViewProviderHighOrderMesh
        ViewProviderHighOrderMesh(obj.ViewObject)
    return obj


class HighOrderMeshProxy(GuardedProxy):
    """Proxy of an App::FeaturePython that meshes its ``Part`` with curved elements.

    Recomputing meshes synchronously without the GUI, and on a worker thread behind a
    cancellable progress dialog with it (FreeCAD keeps drawing); the task panel runs the same
    job (:func:`job_for`) and applies its result (:func:`apply_result`) without a recompute.
    """

    Type = TYPE_HIGH_ORDER_MESH

    def __init__(self, obj):
        self.mesh = None
        super().__init__(obj)

    @staticmethod
    def add_properties(obj):
        """Adds missing properties; safe to call again on documents from older versions."""
        have = obj.PropertiesList
        if "Part" not in have:
            obj.addProperty("App::PropertyLink", "Part", "Mesh", "Shape to mesh")
        add_parameter_property(obj, "order", "Mesh")
        add_parameter_property(obj, "size", "Mesh",
                               " 0: the Sizing object's octree if Sizing is set, else the "
                               "automatic sizing octree.")
        if "Sizing" not in have:
            obj.addProperty("App::PropertyLink", "Sizing", "Mesh",
                            "Optional HOMesh Sizing object whose octree (MinDelta, MaxDelta, "
                            "Eps, refinement spheres) sizes the elements when Size is 0")
        add_parameter_property(obj, "optimise", "Mesh", " Boundary nodes slide on the CAD.")
        add_parameter_property(obj, "optimise_seconds", "Mesh")
        add_parameter_property(obj, "facet_weight", "Mesh")
        add_parameter_property(obj, "fidelity_weight", "Mesh")
        add_parameter_property(obj, "linear_seconds", "Mesh")
        add_parameter_property(obj, "job_seconds", "Mesh")
        for key in ("heal", "solids_only", "surface", "auto", "imprint"):
            add_parameter_property(obj, key, "Mesh")
        add_parameter_property(obj, "repair_rounds", "Mesh")
        add_parameter_property(obj, "threads", "Mesh")
        if "ElementLimit" not in have:
            obj.addProperty("App::PropertyInteger", "ElementLimit", "Mesh",
                            "A run whose predicted linear element count exceeds this asks "
                            "first (GUI) or fails (Python) until it is raised; 0: no limit")
            obj.ElementLimit = DEFAULT_ELEMENT_LIMIT
        if "BoundaryLayer" not in have:
            obj.addProperty("App::PropertyLink", "BoundaryLayer", "Mesh",
                            "Optional HOMesh BoundaryLayer object: prisms grown from its faces "
                            "of Part, curved and optimised with the rest, then split")
        if "Regions" not in have:
            obj.addProperty("App::PropertyLinkList", "Regions", "Mesh",
                            "HOMesh MeshRegion children: smaller sizes near faces, edges and "
                            "vertices (sources of the sizing octree; Size must be 0)")
        if "Groups" not in have:
            obj.addProperty("App::PropertyLinkList", "Groups", "Mesh",
                            "HOMesh BoundaryGroup children: named boundary groups (wall, "
                            "inlet ...) written as physical groups / composites by every export")
        if "FemMesh" not in have:
            obj.addProperty("App::PropertyLink", "FemMesh", "Mesh",
                            "Optional FEM mesh of Part (FEM's Gmsh or Netgen mesher, first or "
                            "second order; tetrahedra, pyramids, prisms, hexahedra): its cells "
                            "are put on the CAD and curved "
                            "instead of meshing Part (Size, Sizing, RepairRounds and "
                            "BoundaryLayer do not apply)")
        if "MeshData" not in have:
            obj.addProperty("App::PropertyFileIncluded", "MeshData", "Result",
                            "The curved mesh, stored in the document")
            obj.setEditorMode("MeshData", 2)  # hidden
        for prop, kind, doc in (
                ("NumNodes", "App::PropertyInteger", "Number of nodes"),
                ("NumElements", "App::PropertyInteger", "Number of volume (2D: surface) elements"),
                ("MinScaledJacobian", "App::PropertyFloat",
                 "Worst scaled Jacobian (min J / max J, certified); <= 0 means an invalid "
                 "element"),
                ("InvalidElements", "App::PropertyInteger", "Elements with non-positive Jacobian"),
                ("UndecidedElements", "App::PropertyInteger",
                 "Elements whose validity the certified check could not decide"),
                ("Status", "App::PropertyString", "Summary of the last run, or why it failed")):
            if prop not in have:
                obj.addProperty(kind, prop, "Result", doc)
                obj.setEditorMode(prop, 1)  # read-only

    def onDocumentRestored(self, obj):
        self.mesh = None
        super().onDocumentRestored(obj)

    def execute(self, obj):
        import homesh
        self.mesh = None
        try:
            job = job_for(obj)
            predicted = check_element_limit(obj, job)
        except LargeMeshError as e:
            from ..progress_dialog import confirm_large_mesh
            if not (FreeCAD.GuiUp and confirm_large_mesh(str(e))):
                _fail(obj, e)
                raise
            predicted = None
        except (ValueError, homesh.HOMeshError) as e:
            _fail(obj, e)
            raise
        try:
            if FreeCAD.GuiUp:
                from ..progress_dialog import run_with_progress_dialog
                mesh = run_with_progress_dialog(job, "Meshing %s" % obj.Label)
            else:
                job.start().wait()
                if job.error is not None:
                    raise job.error
                mesh = job.result
        except homesh.HOMeshError as e:
            _fail(obj, e)
            raise
        try:
            apply_result(obj, mesh, predicted, touch=False, npz_path=job.npz_path)
        finally:
            job.discard_files()

    def __setstate__(self, state):
        self.mesh = None


def _fail(obj, error):
    obj.Status = "Failed: %s" % error
    FreeCAD.Console.PrintError("HOMesh: %s: %s\n" % (obj.Label, error))
