"""A HighOrderMesh object's meshing, apart from the document objects themselves: its
properties (or a task panel's values) made into a :class:`job.MeshJob` (``homesh.mesh``, or
``homesh.curve`` for a FEM mesh), the element count predicted and checked against its
ElementLimit, and a finished job's mesh and results written back to the object. Used by the
object's recompute and by its task panel alike; creates no objects, no transactions, no Qt.
"""

import FreeCAD

from .arguments import mesh_arguments, part_shape
from .fem import fem_mesh_arrays, is_fem_mesh
from .job import MeshJob
from .stored_mesh import store_mesh

DEFAULT_ELEMENT_LIMIT = 2000000


class LargeMeshError(ValueError):
    """The predicted element count exceeds the object's ElementLimit: the GUI asks before going
    on; in Python, raise ElementLimit (0: no limit) to run it."""


def job_for(obj, values=None):
    """A :class:`job.MeshJob` (not started) for a HighOrderMesh object, with ``values`` from a
    task panel in place of its properties. The shape (and a FEM mesh's arrays) are read here,
    on the GUI thread."""
    import homesh
    shape = part_shape(obj)
    arguments = mesh_arguments(obj, values)
    fem_object = getattr(obj, "FemMesh", None)
    if fem_object is None:
        job = MeshJob(shape.exportBrepToString(), obj.Part.Label, **arguments)
    else:
        if not is_fem_mesh(fem_object):
            raise ValueError("%s: FemMesh must link to a FEM mesh object, not %s"
                             % (obj.Label, fem_object.Label))
        try:
            nodes, cells = fem_mesh_arrays(fem_object.FemMesh)
        except ValueError as e:
            raise ValueError("%s: %s: %s" % (obj.Label, fem_object.Label, e)) from None
        job = MeshJob(shape.exportBrepToString(), obj.Part.Label, function=homesh.curve,
                      nodes=nodes, cells=cells, order=arguments["order"],
                      optimise=arguments["optimise"], threads=arguments["threads"],
                      optimise_seconds=arguments["optimise_seconds"],
                      job_seconds=arguments["job_seconds"],
                      facet_weight=arguments["facet_weight"],
                      fidelity_weight=arguments["fidelity_weight"])
        job.fem_elements = sum(len(c) for c in cells.values())
    job.values = values or {}
    return job


def predicted_elements(obj, job):
    """The linear element count the job will make, predicted by the sizing octree (for a
    uniform size, an octree whose sizes are all that size)."""
    import homesh
    del obj
    if hasattr(job, "fem_elements"):
        return job.fem_elements  # the FEM mesh's own cells
    arguments = job.arguments
    size = arguments.get("size")
    if size is None:
        sizing = {k: arguments[k] for k in ("min_delta", "max_delta", "eps", "sources")
                  if k in arguments}
    else:
        sizing = {"min_delta": size, "max_delta": size}
    cad = {k: arguments[k] for k in ("threads", "heal", "solids_only", "surface", "auto", "imprint")
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
    store_mesh(obj, mesh, npz_path)  # npz_path: written by the job's worker thread
    quality = mesh.quality()
    obj.NumNodes = mesh.num_nodes
    obj.NumElements = mesh.num_elements
    obj.MinScaledJacobian = float(quality["min"])
    obj.InvalidElements = int(quality["invalid_elements"])
    obj.UndecidedElements = int(quality["undecided_elements"])
    report = job_report(mesh)
    notes = report.get("notes", [])
    obj.Status = summary_text(obj, mesh, predicted)
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


def summary_text(obj, mesh, predicted=None):
    """The object's label, the core's headline of the mesh (the line ``homesh mesh`` prints:
    counts, certified quality, and where elements not proven valid lie on the CAD) and the
    predicted linear element count."""
    text = "%s: %s" % (obj.Label, mesh.headline())
    if predicted:
        text += "; %d linear elements predicted" % predicted
    return text


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
