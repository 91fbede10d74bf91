"""The HighOrderMesh and Sizing document objects: properties, recompute and persistence.

The proxies only hold properties and run the core; drawing lives in viewproviders.py. The curved
mesh is stored inside the .FCStd as a compressed array file (property MeshData), so reopening a
document shows and exports the mesh without recomputing it. A Sizing object holds the sizing
octree's parameters (MinDelta, MaxDelta, Eps, refinement spheres) and predicts the element count;
a HighOrderMesh whose Sizing property links to it meshes with that octree. A BoundaryLayer object
holds the faces (picked by selecting them), thickness, layers and progression of a boundary
layer; a HighOrderMesh whose BoundaryLayer property links to it grows, curves and splits it.
"""

import os
import shutil
import tempfile

import FreeCAD

from .properties import ParameterGuard, add_parameter_property, allowed, definition

TYPE_HIGH_ORDER_MESH = "HOMesh::HighOrderMesh"
TYPE_SIZING = "HOMesh::Sizing"
TYPE_BOUNDARY_LAYER = "HOMesh::BoundaryLayer"

_RESULT_PROPERTIES = ("NumNodes", "NumElements", "MinScaledJacobian", "InvalidElements")


def make_high_order_mesh(doc, part, order=None, size=None, name="HighOrderMesh", sizing=None,
                         boundary_layer=None, fem_mesh=None):
    """Adds a HighOrderMesh object meshing ``part`` (a document object with a Shape).

    ``order`` and ``size`` left out (None) keep the parameter table's defaults. ``size`` 0
    means automatic: the sizing octree of ``sizing`` (a Sizing object, see
    :func:`make_sizing`) if given, else the automatic sizing octree (MaxDelta a twentieth of the
    bounding-box diagonal, MinDelta a twentieth of that, EPS the table's default).
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


class _Proxy:
    """Persistence of the proxies: only their type (FreeCAD 0.20 uses __getstate__, 0.21+
    dumps)."""

    def __getstate__(self):
        return {"Type": self.Type}

    def __setstate__(self, state):
        return None

    def dumps(self):
        return self.__getstate__()

    def loads(self, state):
        self.__setstate__(state)


class LargeMeshError(ValueError):
    """The predicted element count exceeds the object's ElementLimit: the GUI asks before going
    on; in Python, raise ElementLimit (0: no limit) to run it."""


class HighOrderMeshProxy(_Proxy, ParameterGuard):
    """Proxy of an App::FeaturePython that meshes its ``Part`` with curved elements.

    Recomputing meshes synchronously without the GUI, and on a worker thread behind a
    cancellable progress dialog with it (FreeCAD keeps drawing); the task panel runs the same
    job (:func:`job_for`) and applies its result (:func:`apply_result`) without a recompute.
    """

    Type = TYPE_HIGH_ORDER_MESH

    def __init__(self, obj):
        obj.Proxy = self
        self.mesh = None
        self.add_properties(obj)
        self.remember(obj)

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
        add_parameter_property(obj, "linear_seconds", "Mesh")
        add_parameter_property(obj, "job_seconds", "Mesh")
        for key in ("heal", "solids_only", "surface", "auto"):
            add_parameter_property(obj, key, "Mesh")
        add_parameter_property(obj, "repair_rounds", "Mesh")
        add_parameter_property(obj, "threads", "Mesh", " Default: all cores.",
                               default=os.cpu_count() or 1)
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
                            "second order): its tetrahedra are put on the CAD and curved "
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
        self.add_properties(obj)
        self.remember(obj)

    def onChanged(self, obj, prop):
        self.guard(obj, prop)

    def execute(self, obj):
        import homesh
        self.mesh = None
        try:
            job = job_for(obj)
            predicted = check_element_limit(obj, job)
        except LargeMeshError as e:
            from .job import confirm_large_mesh
            if not (FreeCAD.GuiUp and confirm_large_mesh(str(e))):
                _fail(obj, e)
                raise
            predicted = None
        except (ValueError, homesh.HOMeshError) as e:
            _fail(obj, e)
            raise
        try:
            if FreeCAD.GuiUp:
                from .job import run_with_progress_dialog
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


DEFAULT_ELEMENT_LIMIT = 2000000


def _fail(obj, error):
    obj.Status = "Failed: %s" % error
    FreeCAD.Console.PrintError("HOMesh: %s: %s\n" % (obj.Label, error))


def mesh_arguments(obj, values=None):
    """The keyword arguments of :func:`homesh.mesh` that a HighOrderMesh object stands for,
    with ``values`` ({property: value}, from a task panel) in place of its own properties.

    Raises ValueError naming the object and the property when something is missing or out of
    range.
    """
    values = dict(values or {})

    def get(prop):
        value = values[prop] if prop in values else getattr(obj, prop)
        value = float(getattr(value, "Value", value))
        p = definition(prop)
        if not allowed(p, value):
            raise ValueError("%s: %s must be %s, got %g" % (obj.Label, prop, p["range"], value))
        return value

    size = get("Size")
    arguments = {"order": int(get("Order")), "size": size if size > 0 else None,
                 "optimise": int(get("OptimiserIterations")),
                 "optimise_seconds": get("OptimiserTimeLimit"),
                 "facet_weight": get("FacetWeight"),
                 "linear_seconds": get("LinearTimeLimit"),
                 "job_seconds": get("JobTimeLimit"),
                 "heal": bool(get("Heal")), "solids_only": bool(get("SolidsOnly")),
                 "surface": bool(get("Surface")), "auto": bool(get("AutoMode")),
                 "repair_rounds": int(get("RepairRounds")), "threads": int(get("Threads"))}
    sizing = values.get("Sizing", getattr(obj, "Sizing", None))
    if arguments["size"] is None and sizing is not None:
        if not is_sizing(sizing):
            raise ValueError("%s: Sizing must link to a HOMesh Sizing object, not %s"
                             % (obj.Label, sizing.Label))
        arguments.update(sizing_arguments(sizing))
    if getattr(obj, "Regions", None) and getattr(obj, "FemMesh", None) is None:
        from .regions import mesh_sources
        if arguments["size"] is not None:
            raise ValueError("%s: mesh regions refine the sizing octree: set Size to 0 "
                             "(automatic) to use them" % obj.Label)
        arguments["sources"] = list(arguments.get("sources", ())) + mesh_sources(obj)
    if obj.BoundaryLayer is not None and getattr(obj, "FemMesh", None) is None:
        if not is_boundary_layer(obj.BoundaryLayer):
            raise ValueError("%s: BoundaryLayer must link to a HOMesh BoundaryLayer object, "
                             "not %s" % (obj.Label, obj.BoundaryLayer.Label))
        arguments["boundary_layer"] = boundary_layer_arguments(obj.BoundaryLayer, obj.Part)
    return arguments


def part_shape(obj):
    """The shape a HighOrderMesh meshes; ValueError naming the object when there is none."""
    if obj.Part is None:
        raise ValueError("%s: no shape to mesh (set its Part property)" % obj.Label)
    shape = getattr(obj.Part, "Shape", None)
    if shape is None or shape.isNull():
        raise ValueError("%s: %s has no shape" % (obj.Label, obj.Part.Label))
    return shape


def job_for(obj, values=None):
    """A :class:`job.MeshJob` (not started) for a HighOrderMesh object, with ``values`` from a
    task panel in place of its properties. The shape (and a FEM mesh's arrays) are read here,
    on the GUI thread."""
    import homesh
    from .job import MeshJob
    shape = part_shape(obj)
    arguments = mesh_arguments(obj, values)
    fem_object = getattr(obj, "FemMesh", None)
    if fem_object is None:
        job = MeshJob(shape.exportBrepToString(), obj.Part.Label, **arguments)
    else:
        from .fem import fem_mesh_arrays, is_fem_mesh
        if not is_fem_mesh(fem_object):
            raise ValueError("%s: FemMesh must link to a FEM mesh object, not %s"
                             % (obj.Label, fem_object.Label))
        try:
            nodes, tets = fem_mesh_arrays(fem_object.FemMesh)
        except ValueError as e:
            raise ValueError("%s: %s: %s" % (obj.Label, fem_object.Label, e)) from None
        job = MeshJob(shape.exportBrepToString(), obj.Part.Label, function=homesh.curve,
                      nodes=nodes, tetrahedra=tets, order=arguments["order"],
                      optimise=arguments["optimise"], threads=arguments["threads"],
                      optimise_seconds=arguments["optimise_seconds"],
                      job_seconds=arguments["job_seconds"],
                      facet_weight=arguments["facet_weight"])
        job.fem_elements = len(tets)
    job.values = values or {}
    return job


def predicted_elements(obj, job):
    """The linear element count the job will make, predicted by the sizing octree (for a
    uniform size, an octree whose sizes are all that size)."""
    import homesh
    del obj
    if hasattr(job, "fem_elements"):
        return job.fem_elements  # the FEM mesh's own tetrahedra
    arguments = job.arguments
    size = arguments.get("size")
    if size is None:
        sizing = {k: arguments[k] for k in ("min_delta", "max_delta", "eps", "sources")
                  if k in arguments}
    else:
        sizing = {"min_delta": size, "max_delta": size}
    cad = {k: arguments[k] for k in ("threads", "heal", "solids_only", "surface", "auto")
           if k in arguments}
    report = homesh.predict(job.brep_text, name=job.name, **cad, **sizing)
    return int(report["predicted_elements"])


def check_element_limit(obj, job):
    """The predicted count; LargeMeshError when it exceeds the object's ElementLimit."""
    predicted = predicted_elements(obj, job)
    limit = int(obj.ElementLimit)
    if limit > 0 and predicted > limit:
        raise LargeMeshError(
            "%s: about %d linear elements predicted, more than ElementLimit (%d); raise "
            "ElementLimit (0: no limit) or use a larger size" % (obj.Label, predicted, limit))
    return predicted


def apply_result(obj, mesh, predicted=None, touch=True, values=None, npz_path=None):
    """Stores a finished job's mesh in a HighOrderMesh object: the task panel's ``values`` (its
    parameters, so the object says what made the mesh), the mesh (MeshData, kept in the .FCStd)
    and the result properties; a warning when elements are invalid or undecided. With ``touch``
    False (inside execute) FreeCAD clears the touched state itself; else it is cleared here,
    since the mesh is up to date."""
    for prop, value in (values or {}).items():
        if prop != "Sizing":
            setattr(obj, prop, value)
    if npz_path is not None:  # written by the job's worker thread
        obj.MeshData = npz_path  # FreeCAD copies the file into the document
    else:
        folder = tempfile.mkdtemp(prefix="homesh-")
        try:
            path = os.path.join(folder, "mesh.npz")
            mesh.write(path)
            obj.MeshData = path
        finally:
            shutil.rmtree(folder, ignore_errors=True)
    obj.Proxy.mesh = mesh
    quality = mesh.quality()
    obj.NumNodes = mesh.num_nodes
    obj.NumElements = mesh.num_elements
    obj.MinScaledJacobian = float(quality["min"])
    obj.InvalidElements = int(quality["invalid_elements"])
    obj.UndecidedElements = int(quality["undecided_elements"])
    report = job_report(mesh)
    notes = report.get("notes", [])
    obj.Status = summary_text(obj, mesh, quality, predicted,
                              report.get("quality", {}).get("where", ""))
    if not_valid(obj):
        FreeCAD.Console.PrintWarning("HOMesh: %s\n" % obj.Status)
    else:
        FreeCAD.Console.PrintMessage("HOMesh: %s\n" % obj.Status)
    for note in notes:  # what the job cut short or left out, and what it tried
        FreeCAD.Console.PrintMessage("HOMesh: note: %s\n" % note)
    if touch:
        obj.purgeTouched()
    if FreeCAD.GuiUp and obj.ViewObject is not None:
        obj.ViewObject.signalChangeIcon()


def not_valid(obj):
    """Whether the object's mesh has elements not proven valid."""
    return obj.InvalidElements > 0 or obj.UndecidedElements > 0


def job_report(mesh):
    """The report of the job that made ``mesh``, or {} for a mesh without one (read back from
    a document)."""
    try:
        return mesh.report()
    except Exception:  # noqa: BLE001 - a mesh without a pipeline result has no report
        return {}


def summary_text(obj, mesh, quality, predicted=None, where=""):
    """``where``: the report's quality "where" (the CAD faces elements not proven valid
    touch: "at Face7 (18 elements), Face3 (6)")."""
    text = ("%s: %d nodes, %d elements of order %d, worst scaled Jacobian %.3f"
            % (obj.Label, mesh.num_nodes, mesh.num_elements, mesh.order, quality["min"]))
    if predicted:
        text += ", %d linear elements predicted" % predicted
    if quality["invalid_elements"] or quality["undecided_elements"]:
        text += (": NOT VALID, %d invalid and %d undecided elements (worst %.3g)"
                 % (quality["invalid_elements"], quality["undecided_elements"], quality["min"]))
        if where:
            text += " " + where
    else:
        text += ", all elements proven valid"
    return text


def make_sizing(doc, part, min_delta=None, max_delta=None, eps=None, name="Sizing"):
    """Adds a Sizing object for ``part`` (a document object with a Shape): the sizing octree's
    parameters and its predicted element count.

    Left out (None): the parameter table's defaults. ``min_delta`` / ``max_delta`` 0 mean
    automatic (max: bounding-box diagonal / 20, min: max / 20). Refinement spheres go in RefinementSpheres (centres), RefinementRadii and
    RefinementDeltas (parallel lists). The caller recomputes.
    """
    obj = doc.addObject("App::FeaturePython", name)
    SizingProxy(obj)
    obj.Part = part
    for prop, value in (("MinDelta", min_delta), ("MaxDelta", max_delta), ("Eps", eps)):
        if value is not None:
            setattr(obj, prop, value)
    if FreeCAD.GuiUp:
        from .viewproviders import ViewProviderSizing
        ViewProviderSizing(obj.ViewObject)
    return obj


def is_sizing(obj):
    """Whether ``obj`` is a HOMesh Sizing object."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TYPE_SIZING


def cad_modes(shape):
    """How a Sizing object sizes `shape`: its solids (faces in no solid left out), or, for a
    shape without solids, its faces as a surface mesh."""
    surface = len(shape.Solids) == 0
    return {"solids_only": not surface, "surface": surface}


def sizing_arguments(obj):
    """The keyword arguments of :func:`homesh.predict` / :func:`homesh.mesh` that a Sizing
    object stands for: min_delta, max_delta (None when automatic), eps and sources.

    Raises ValueError naming the object and the property when a parameter is out of range.
    """
    min_delta = obj.MinDelta.Value
    max_delta = obj.MaxDelta.Value
    eps = obj.Eps
    if not allowed(definition("Eps"), eps):
        raise ValueError("%s: Eps must be %s, got %g" % (obj.Label, definition("Eps")["range"],
                                                         eps))
    if min_delta > 0 and max_delta > 0 and min_delta > max_delta:
        raise ValueError("%s: MinDelta (%g) must not exceed MaxDelta (%g)"
                         % (obj.Label, min_delta, max_delta))
    centres, radii, deltas = obj.RefinementSpheres, obj.RefinementRadii, obj.RefinementDeltas
    if not len(centres) == len(radii) == len(deltas):
        raise ValueError("%s: RefinementSpheres, RefinementRadii and RefinementDeltas must have "
                         "the same length, got %d, %d and %d"
                         % (obj.Label, len(centres), len(radii), len(deltas)))
    sources = []
    for i, (centre, radius, delta) in enumerate(zip(centres, radii, deltas)):
        for prop, value in (("RefinementRadii", radius), ("RefinementDeltas", delta)):
            if not value > 0:
                raise ValueError("%s: %s[%d] must be positive, got %g"
                                 % (obj.Label, prop, i, value))
        sources.append({"kind": "sphere", "a": (centre.x, centre.y, centre.z),
                        "radius": float(radius), "delta": float(delta)})
    return {"min_delta": min_delta if min_delta > 0 else None,
            "max_delta": max_delta if max_delta > 0 else None,
            "eps": float(eps), "sources": sources}


class SizingProxy(_Proxy, ParameterGuard):
    """Proxy of an App::FeaturePython holding the sizing octree's parameters for its ``Part``;
    recomputing predicts the element count (:func:`homesh.predict`).

    A failed prediction or a bad parameter leaves the message in Status, zero outputs, and the
    object marked as failed (the exception goes to FreeCAD's recompute, which reports it).
    """

    Type = TYPE_SIZING
    GRADATION = 0.2  # fixed in the core: sizes change by at most 0.2 per unit distance

    def __init__(self, obj):
        obj.Proxy = self
        self.add_properties(obj)
        self.remember(obj)

    @staticmethod
    def add_properties(obj):
        """Adds missing properties and makes the outputs read-only; safe to call again."""
        have = obj.PropertiesList
        if "Part" not in have:
            obj.addProperty("App::PropertyLink", "Part", "Sizing", "Shape whose sizing this is")
        add_parameter_property(obj, "min_delta", "Sizing", " 0: MaxDelta / 20.")
        add_parameter_property(obj, "max_delta", "Sizing", " 0: bounding-box diagonal / 20.")
        add_parameter_property(obj, "eps", "Sizing")
        if "Gradation" not in have:
            obj.addProperty("App::PropertyFloat", "Gradation", "Sizing",
                            "Most change of size per unit distance (fixed)")
            obj.Gradation = SizingProxy.GRADATION
        if "RefinementSpheres" not in have:
            obj.addProperty("App::PropertyVectorList", "RefinementSpheres", "Refinement",
                            "Centres of refinement spheres: inside sphere i the size is at most "
                            "RefinementDeltas[i]")
        if "RefinementRadii" not in have:
            obj.addProperty("App::PropertyFloatList", "RefinementRadii", "Refinement",
                            "Radius of each refinement sphere (same length as "
                            "RefinementSpheres)")
        if "RefinementDeltas" not in have:
            obj.addProperty("App::PropertyFloatList", "RefinementDeltas", "Refinement",
                            "Element size inside each refinement sphere (same length as "
                            "RefinementSpheres)")
        for prop, kind, doc in (
                ("PredictedElements", "App::PropertyInteger",
                 "Predicted number of linear elements (0 after a failure)"),
                ("OctreeLeaves", "App::PropertyInteger", "Leaves of the sizing octree"),
                ("SmallestSize", "App::PropertyLength", "Smallest size in the octree"),
                ("Status", "App::PropertyString",
                 "Summary of the last prediction, or why it failed")):
            if prop not in have:
                obj.addProperty(kind, prop, "Result", doc)
        for prop in ("Gradation", "PredictedElements", "OctreeLeaves", "SmallestSize", "Status"):
            obj.setEditorMode(prop, 1)  # read-only

    def onDocumentRestored(self, obj):
        self.add_properties(obj)
        self.remember(obj)

    def onChanged(self, obj, prop):
        self.guard(obj, prop)

    def execute(self, obj):
        import homesh
        try:
            if obj.Part is None:
                raise ValueError("%s: no shape (set its Part property)" % obj.Label)
            shape = getattr(obj.Part, "Shape", None)
            if shape is None or shape.isNull():
                raise ValueError("%s: %s has no shape" % (obj.Label, obj.Part.Label))
            # Sizes of the solids (faces in no solid left out): a mesh object without
            # SolidsOnly refuses such a shape and says why; the sizing stays drawable. A shape
            # without solids is sized as a surface mesh of its faces (the mesh object's Surface).
            report = homesh.predict(shape, name=obj.Part.Label, **cad_modes(shape),
                                    **sizing_arguments(obj))
        except (ValueError, homesh.HOMeshError) as e:
            obj.PredictedElements = 0
            obj.OctreeLeaves = 0
            obj.SmallestSize = 0
            obj.Status = "Failed: %s" % e
            FreeCAD.Console.PrintError("HOMesh: %s: %s\n" % (obj.Label, e))
            raise
        sizing = report["sizing"]
        octree = sizing["octree"]
        obj.PredictedElements = int(report["predicted_elements"])
        obj.OctreeLeaves = int(octree["leaves"])
        obj.SmallestSize = float(octree["smallest_delta"])
        obj.Gradation = float(sizing.get("gradation", SizingProxy.GRADATION))
        obj.Status = prediction_summary(report)
        FreeCAD.Console.PrintMessage("HOMesh: %s: %s\n" % (obj.Label, obj.Status))


def prediction_summary(report):
    """One line for a ``homesh.predict`` report: the element count, the sizes and leaves, and
    the faces left out (the prediction is then of the solids alone: said, not hidden). The
    Sizing object's Status and its task panel's Predict both show it."""
    sizing = report["sizing"]
    text = ("%d elements predicted (sizes %.4g to %.4g, %d octree leaves)"
            % (int(report["predicted_elements"]), sizing["min_delta"], sizing["max_delta"],
               int(sizing["octree"]["leaves"])))
    left_out = report.get("healing", {}).get("left_out")
    if left_out:
        text += "; of the solids alone: left out %s" % left_out
    return text


def make_boundary_layer(doc, part, faces, thickness, layers=None, progression=None,
                        name="BoundaryLayer"):
    """Adds a BoundaryLayer object on ``faces`` of ``part`` (FreeCAD's numbers, 1 for Face1, or
    names "Face1"; for a planar shape edges, named "Edge1"): ``thickness`` a length in the model's units or an expression of x, y, z
    (text), split into ``layers`` layers whose heights grow by ``progression`` from the wall
    (left out: the parameter table's defaults).
    Link it from a HighOrderMesh's BoundaryLayer property. The caller recomputes.
    """
    obj = doc.addObject("App::FeaturePython", name)
    BoundaryLayerProxy(obj)
    obj.Faces = (part, [f if isinstance(f, str) else "Face%d" % f for f in faces])
    obj.Thickness = str(thickness)
    if layers is not None:
        obj.Layers = layers
    if progression is not None:
        obj.Progression = progression
    return obj


def is_boundary_layer(obj):
    """Whether ``obj`` is a HOMesh BoundaryLayer object."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == TYPE_BOUNDARY_LAYER


def boundary_layer_arguments(obj, part=None):
    """The ``boundary_layer`` argument of :func:`homesh.mesh` a BoundaryLayer object stands for.

    Raises ValueError naming the object and the property when its faces are missing, are not
    faces, or (with ``part``) belong to another object than the one meshed.
    """
    linked = obj.Faces
    if not linked or linked[0] is None:
        raise ValueError("%s: no faces (select faces of the shape and set Faces)" % obj.Label)
    owner, names = linked[0], list(linked[1])
    if part is not None and owner != part:
        raise ValueError("%s: its faces belong to %s, but the mesh is of %s"
                         % (obj.Label, owner.Label, part.Label))
    # Faces of a solid (3D), or edges of a planar shape (2D: the layer grows from curves).
    kind = "Edge" if names and names[0].startswith("Edge") else "Face"
    faces = []
    for name in names:
        if not name.startswith(kind) or not name[len(kind):].isdigit():
            raise ValueError("%s: Faces must name faces (Face1, Face2, ...), or for a planar "
                             "shape edges (Edge1, ...), all of one kind; got %r"
                             % (obj.Label, name))
        faces.append(int(name[len(kind):]))
    if kind == "Edge" and getattr(owner, "Shape", None) is not None and owner.Shape.Solids:
        raise ValueError("%s: Faces must name faces of a solid (Face1, Face2, ...); edges carry "
                         "a layer only on a planar shape, got %r" % (obj.Label, names[0]))
    if not faces:
        raise ValueError("%s: no faces (select faces of the shape and set Faces)" % obj.Label)
    text = obj.Thickness.strip()
    try:
        thickness = float(text)
    except ValueError:
        thickness = text  # an expression of x, y, z: the core parses it and names any error
    return {"faces": sorted(set(faces)), "thickness": thickness, "layers": int(obj.Layers),
            "progression": float(obj.Progression)}


class BoundaryLayerProxy(_Proxy, ParameterGuard):
    """Proxy of an App::FeaturePython holding a boundary layer's parameters; recomputing checks
    them and gives the first layer's height (for a constant thickness)."""

    Type = TYPE_BOUNDARY_LAYER

    def __init__(self, obj):
        obj.Proxy = self
        self.add_properties(obj)
        self.remember(obj)

    @staticmethod
    def add_properties(obj):
        """Adds missing properties and makes the outputs read-only; safe to call again."""
        have = obj.PropertiesList
        if "Faces" not in have:
            obj.addProperty("App::PropertyLinkSub", "Faces", "Layer",
                            "Faces of the meshed shape that carry the layer (select them); for "
                            "a planar shape, its edges")
        if "Thickness" not in have:
            obj.addProperty("App::PropertyString", "Thickness", "Layer",
                            "Total thickness in the model's units, or an expression of x, y, z "
                            "such as 0.01+0.05*x")
        add_parameter_property(obj, "layers", "Layer")
        add_parameter_property(obj, "progression", "Layer")
        for prop, kind, doc in (
                ("FirstLayerHeight", "App::PropertyFloat",
                 "Height of the wall layer for a constant thickness (0 for an expression)"),
                ("Status", "App::PropertyString", "Summary, or why the parameters are wrong")):
            if prop not in have:
                obj.addProperty(kind, prop, "Result", doc)
            obj.setEditorMode(prop, 1)  # read-only

    def onDocumentRestored(self, obj):
        self.add_properties(obj)
        self.remember(obj)

    def onChanged(self, obj, prop):
        self.guard(obj, prop)

    def execute(self, obj):
        try:
            args = boundary_layer_arguments(obj)
            if not args["thickness"]:
                raise ValueError("%s: no Thickness given" % obj.Label)
        except ValueError as e:
            obj.FirstLayerHeight = 0.0
            obj.Status = "Failed: %s" % e
            FreeCAD.Console.PrintError("HOMesh: %s\n" % e)
            raise
        n, r, t = args["layers"], args["progression"], args["thickness"]
        first = 0.0
        if isinstance(t, float):
            first = t / n if r == 1.0 else t * (1.0 - r) / (1.0 - r ** n)
        obj.FirstLayerHeight = first
        obj.Status = ("%d faces of %s, thickness %s, %d layers, progression %g%s"
                      % (len(args["faces"]), obj.Faces[0].Label, t, n, r,
                         ", first layer %.4g" % first if first else ""))
