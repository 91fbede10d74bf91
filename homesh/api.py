"""The Python face of the meshing core: :func:`mesh`, :func:`load` and :class:`HighOrderMesh`."""

import json
import numbers
import os
import warnings
import zipfile
from dataclasses import dataclass

import numpy as np

from . import _core
from ._core import FileError, HOMeshError, ParameterError

_NPZ_FORMAT = 1


@dataclass(frozen=True)
class BoundaryBlock:
    """Cells of one type and order: ``elements`` is (count, nodes per cell) int64 in Gmsh order;
    ``cad_entity`` gives the 1-based FreeCAD index of the solid, face (``FaceN``) or edge
    (``EdgeN``) each cell lies on (Gmsh entity tags for meshes read from files)."""

    element_type: str
    order: int
    elements: np.ndarray
    cad_entity: np.ndarray


class HighOrderMesh:
    """A curved mesh: flat arrays of nodes and connectivity, with quality and writers.

    Attributes (numpy arrays, copied from the core once):
      nodes            (N, 3) float64
      element_blocks   list of :class:`BoundaryBlock`: the cells of dimension ``dim``, one block
                       per type (a mesh read from a file may mix tetrahedra, prisms, ...)
      elements         (E, k) int64, element_type ("tet", "tri", ...), element_entity (E,):
                       the single element block (HOMeshError when types are mixed)
      boundary         list of :class:`BoundaryBlock`: the lower-dimensional cells
      node_cad_dim     (N,) uint8: 0 vertex, 1 edge, 2 face, 3 solid interior
      node_cad_index   (N,) int32: 1-based FreeCAD index of that entity (VertexN, EdgeN, ...)
      node_cad_params  (N, 2) float64: t on an edge (second column NaN) or (u, v) on a face
    """

    def __init__(self, core):
        self._core = core
        self.order = core.order
        self.dim = core.dim
        self.plane_normal = tuple(core.plane_normal)
        self.nodes = core.nodes()
        self.node_cad_dim = core.node_cad_dim()
        self.node_cad_index = core.node_cad_index()
        self.node_cad_params = core.node_cad_params()
        self._blocks = core.blocks()
        self.element_blocks = [BoundaryBlock(t, o, conn, ent)
                               for t, o, conn, ent in self._blocks if _cell_dim(t) == self.dim]
        self.boundary = [BoundaryBlock(t, o, conn, ent)
                         for t, o, conn, ent in self._blocks if _cell_dim(t) != self.dim]

    def _single_block(self):
        if len(self.element_blocks) != 1:
            raise _core.HOMeshError(
                "the mesh mixes %s elements: use element_blocks"
                % ", ".join(b.element_type for b in self.element_blocks))
        return self.element_blocks[0]

    @property
    def elements(self):
        return self._single_block().elements

    @property
    def element_type(self):
        return self._single_block().element_type

    @property
    def element_entity(self):
        return self._single_block().cad_entity

    def __repr__(self):
        return "<HighOrderMesh order %d: %d nodes, %s>" % (
            self.order, len(self.nodes),
            ", ".join("%d %s" % (len(b.elements), b.element_type) for b in self.element_blocks))

    @property
    def num_nodes(self):
        return len(self.nodes)

    @property
    def num_elements(self):
        return sum(len(b.elements) for b in self.element_blocks)

    def quality(self):
        """Quality per element (in block order) and its summary.

        Returns a dict: ``scaled_jacobian`` (E,) array (certified lower bound of min J / max J,
        from Bezier bounds), ``scaled_jacobian_upper`` (E,) (the true value lies between the
        two), ``validity`` (E,) int8 (1 proven valid, -1 invalid, 0 undecided),
        ``distortion`` (E,) array, ``min``/``mean`` of the scaled Jacobian,
        ``distortion_min``/``distortion_mean``, ``invalid_elements``, ``undecided_elements``,
        ``certified`` and ``by_type``.
        """
        summary = dict(self._core.quality_summary())
        summary["scaled_jacobian"] = self._core.scaled_jacobian()
        summary["scaled_jacobian_upper"] = self._core.scaled_jacobian_upper()
        summary["validity"] = self._core.validity()
        summary["distortion"] = self._core.distortion()
        return summary

    def element_volumes(self):
        """Signed volume (area in 2D) of every element, in block order: the exact integral of
        the Jacobian of each curved element."""
        return self._core.element_volumes()

    def optimise(self, functional="hyperelastic", maxiter=100, tolerance=1e-6, threads=1,
                 region=None, layers=2, focus=2, free_interfaces=False, facet_weight=0.0):
        """Curves the interior by the variational optimiser, in place, and returns its record.

        ``functional``: "hyperelastic" (default), "linearelastic", "winslow" or "distortion".
        ``maxiter`` sweeps at most; stops earlier when no node moves more than ``tolerance``
        times the mean element size. ``region``: move only nodes near elements whose scaled
        Jacobian is below it (with ``layers`` layers of neighbours). ``focus``: extra passes
        over the worst elements' nodes after each sweep. On a mesh made from CAD, nodes on CAD
        curves and faces slide on them (CAD vertices stay); on a mesh read from a file,
        boundary nodes (and nodes on interfaces between volumes unless ``free_interfaces``)
        stay fixed. ``facet_weight`` (0 to 100, default 0 = off): on a mesh made from CAD, once
        every element is proven valid, also keep the sliding boundary facets' nodes evenly
        spread, so that the curved boundary stays on the CAD between them (as in :func:`mesh`).

        The mesh kept is never worse than before in worst scaled Jacobian or invalid count.
        Returns a dict: functional, iterations, converged, stopped (the rule that ended the
        run: displacement, energy, stalled, iterations, cancelled), kept_iteration, worst_before,
        worst_after, invalid_before, invalid_after, nodal_worst_before/after (min J / max J at
        the nodes, NekMesh's measure), seconds, history (per sweep) and more.
        """
        region = None if region is None else float(region)
        core, record = self._core.optimise(
            str(functional), _check_int("maxiter", maxiter), float(tolerance),
            _check_int("threads", threads), region, _check_int("layers", layers),
            _check_int("focus", focus), bool(free_interfaces),
            _check_number(facet_weight, "facet_weight"))
        self.__init__(core)
        return json.loads(record)["optimiser"]

    def geometry(self):
        """How closely the boundary follows the CAD, for a mesh made from CAD (None for a mesh
        read from a file): the report's "geometry" record as a dict, with ``max_distance`` (and
        ``max_distance_relative`` to the model's diagonal) of boundary sample points to their
        CAD face or curve, ``max_normal_angle_deg`` and ``mean_normal_angle_deg`` between mesh
        and CAD normals, ``samples`` and the worst entity and point."""
        return self.report().get("geometry")

    def report(self, input_name=""):
        """The JSON report of ``homesh mesh --report`` as a dict."""
        return json.loads(self._core.report_json(str(input_name)))

    def timings(self):
        """Seconds spent in each pipeline stage."""
        return dict(self._core.timings())

    def write(self, path, binary=False, compressed=False, groups=None):
        """Writes .msh (Gmsh 4.1), .vtu (VTK Lagrange cells), .xml (Nektar++) or .npz (this
        object's arrays). ``binary``: binary MSH, raw appended VTU data; ``compressed``:
        compressed Nektar++ XML (B64Z-LittleEndian). ``groups``: named boundary groups, a dict
        such as ``{"wall": [1, 2], "inlet": [3]}`` (boundary faces, FaceN; 2D: curves, EdgeN)
        written as one physical group (MSH) or composite (Nektar++) each, named so, in place of
        "FaceN"; VTU has no boundary cells, hence no groups."""
        path = os.fspath(path)
        if path.lower().endswith(".npz"):
            self._save_npz(path)
            return
        pairs = []
        for name, entities in (groups or {}).items():
            if isinstance(entities, numbers.Integral):
                entities = [entities]
            pairs.append((str(name), [_check_int("group %s entity" % name, e)
                                      for e in entities]))
        self._core.write(path, bool(binary), bool(compressed), pairs)
        if path.lower().endswith(".xml"):
            # Nektar++ rebuilds 3D element interiors from the faces: the solver's geometry is the
            # file read back, not this mesh. Say so when that geometry is not proven valid.
            q = read(path).quality()
            if q["invalid_elements"] + q["undecided_elements"] > 0:
                warnings.warn(
                    "%s as Nektar++ builds it (element interiors from the faces): scaled "
                    "Jacobian min %.4f; %d invalid, %d undecided"
                    % (path, q["min"], q["invalid_elements"], q["undecided_elements"]),
                    stacklevel=2)

    def _save_npz(self, path):
        arrays = {
            "format": np.array([_NPZ_FORMAT]),
            "dim": np.array([self.dim]),
            "order": np.array([self.order]),
            "plane_normal": np.array(self.plane_normal),
            "nodes": self.nodes,
            "node_cad_dim": self.node_cad_dim,
            "node_cad_index": self.node_cad_index,
            "node_cad_params": self.node_cad_params,
            "block_types": np.array([b[0] for b in self._blocks]),
            "block_orders": np.array([b[1] for b in self._blocks]),
        }
        for i, (_, _, conn, ent) in enumerate(self._blocks):
            arrays["block%d_elements" % i] = conn
            arrays["block%d_entity" % i] = ent
        try:
            with open(path, "wb") as f:
                np.savez_compressed(f, **arrays)
        except OSError as e:
            raise FileError("cannot write '%s': %s" % (path, e.strerror)) from None


_PARAMETERS = None


def parameters():
    """The core's one parameter table: a list of dicts with key (the keyword of :func:`mesh`),
    property (the FreeCAD property), option (the command line's), label, kind ("integer",
    "real", "length"), min, max, min_exclusive, default, zero_is_automatic, group, doc and
    range (in words). The core, the command line and the FreeCAD objects all check against
    it."""
    global _PARAMETERS
    if _PARAMETERS is None:
        _PARAMETERS = [dict(p) for p in _core.parameters()]
    return [dict(p) for p in _PARAMETERS]


def read(path, threads=1):
    """Reads a mesh file: .msh (Gmsh 2.2 or 4.1, ASCII or binary), .xml (Nektar++, plain or
    compressed), or FreeCAD FEM's .unv (I-DEAS), .vtk (legacy VTK) and .vtu (VTK XML), linear or
    quadratic, and evaluates its quality. Solids a FEM file lists left-handed (FreeCAD's VTK
    export) are read mirrored: ``report()["notes"]`` says so. Raises FileError naming the file,
    the line or data array and the element."""
    return HighOrderMesh(_core.read_mesh(os.fspath(path), _check_int("threads", threads)))


def load(path):
    """Reads a mesh saved with ``write('....npz')`` and recomputes its quality."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise FileError("mesh file '%s' does not exist" % path)
    try:
        with np.load(path, allow_pickle=False) as data:
            if int(data["format"][0]) != _NPZ_FORMAT:
                raise FileError("'%s' has an unknown HOMesh array format" % path)
            blocks = [
                (str(t), int(o), data["block%d_elements" % i], data["block%d_entity" % i])
                for i, (t, o) in enumerate(zip(data["block_types"], data["block_orders"]))
            ]
            core = _core.mesh_from_arrays(
                int(data["dim"][0]), int(data["order"][0]), data["nodes"],
                data["node_cad_dim"], data["node_cad_index"], data["node_cad_params"],
                blocks, tuple(float(x) for x in data["plane_normal"]))
    except HOMeshError:
        raise
    except (KeyError, ValueError, TypeError, OSError, zipfile.BadZipFile) as e:
        raise FileError("'%s' is not a HOMesh array file: %s" % (path, e)) from None
    return HighOrderMesh(core)


def _sizing(min_delta, max_delta, eps, sources):
    """The sizing dict the core takes, or None when nothing was asked (automatic sizing)."""
    if min_delta is None and max_delta is None and eps is None and not sources:
        return None
    out = {}
    for key, value in (("min_delta", min_delta), ("max_delta", max_delta), ("eps", eps)):
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise ParameterError("%s must be a positive number, got %r" % (key, value))
        if not float(value) > 0.0:
            raise ParameterError("%s must be a positive number, got %g" % (key, value))
        out[key] = float(value)
    out["sources"] = [_source(i + 1, src) for i, src in enumerate(sources or ())]
    return out


_SOURCE_FIELDS = {"segment": ("a", "b", "radius", "delta"), "sphere": ("a", "radius", "delta"),
                  "box": ("a", "b", "delta"), "curve": ("edge", "radius", "delta")}


def _source(number, src):
    """A refinement source dict checked field by field (messages name the source and field)."""
    if not isinstance(src, dict) or src.get("kind") not in _SOURCE_FIELDS:
        raise ParameterError(
            "source %d must be a dict with 'kind' segment, sphere, box or curve, got %r"
            % (number, src))
    kind = src["kind"]
    out = {"kind": kind}
    for field in _SOURCE_FIELDS[kind]:
        if field not in src:
            raise ParameterError("source %d (%s) needs '%s'" % (number, kind, field))
        value = src[field]
        if field in ("a", "b"):
            try:
                point = tuple(float(x) for x in value)
            except (TypeError, ValueError):
                point = ()
            if len(point) != 3:
                raise ParameterError("source %d (%s): '%s' must be three numbers, got %r"
                                     % (number, kind, field, value))
            out[field] = point
        elif field == "edge":
            if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
                raise ParameterError("source %d (curve): 'edge' must be an edge number >= 1, "
                                     "got %r" % (number, value))
            out[field] = int(value)
        else:
            if (isinstance(value, bool) or not isinstance(value, numbers.Real)
                    or not float(value) > 0.0):
                raise ParameterError("source %d (%s): '%s' must be a positive number, got %r"
                                     % (number, kind, field, value))
            out[field] = float(value)
    return out


def _cad_source(shape, name):
    """('brep', text, label) or ('file', path, path) for a shape, path or BRep text."""
    label = str(name) if name else "the shape"
    if hasattr(shape, "exportBrepToString"):
        if shape.isNull():
            raise ParameterError("%s is null (empty)" % label)
        return "brep", shape.exportBrepToString(), label
    if isinstance(shape, (str, os.PathLike)):
        text = os.fspath(shape)
        if "\n" in text and "CASCADE Topology" in text[:200]:
            return "brep", text, label
        return "file", text, text
    raise ParameterError(
        "shape must be a Part.Shape, a CAD file path or BRep text, got %s" % type(shape).__name__)


def predict(shape, min_delta=None, max_delta=None, eps=None, sources=(), write_octree=None,
            name=None, threads=1, heal=True, solids_only=False, surface=False, auto=False):
    """The element count the linear mesh of a CAD shape will have, without making it.

    Builds the sizing octree (curvature sizes between min_delta and max_delta with sagitta
    ratio eps, graded by 0.2; None: automatic, see ``homesh mesh --help``) and integrates it.
    sources: refinement regions, dicts such as ``{"kind": "sphere", "a": (0, 0, 0),
    "radius": 1, "delta": 0.05}``, ``{"kind": "segment", "a": ..., "b": ..., "radius": ...,
    "delta": ...}``, ``{"kind": "box", "a": lo, "b": hi, "delta": ...}`` or ``{"kind":
    "curve", "edge": 3, "radius": ..., "delta": ...}``. write_octree: a .vtu path for the
    octree's leaves and sizes. shape may be a NekMesh .mcf path: its CAD (in metres) and,
    unless given here, its sizes are used (likewise in :func:`mesh`). heal, solids_only,
    surface, auto: the CAD check and healing, as for :func:`mesh` (the prediction is of the
    model meshed; for a surface mesh, of its triangles).

    Returns the report as a dict: "predicted_elements", "dimension" and "sizing" (parameters,
    integrals and octree statistics).
    """
    sizing = _sizing(min_delta, max_delta, eps, sources)
    threads = _check_int("threads", threads)
    octree = "" if write_octree is None else os.fspath(write_octree)
    kind, value, label = _cad_source(shape, name)
    if kind == "brep":
        text = _core.predict_brep(value, label, sizing, octree, threads, bool(heal),
                                  _cad_modes(solids_only, surface, auto))
    else:
        text = _core.predict_file(value, sizing, octree, threads, bool(heal),
                                  _cad_modes(solids_only, surface, auto))
    return json.loads(text)


def size_field(shape, min_delta=None, max_delta=None, eps=None, sources=(), name=None,
               threads=1, heal=True, solids_only=False, surface=False, auto=False):
    """The sizing octree's leaves inside the model or on its boundary, for drawing the size
    field: a dict of numpy arrays ``centre`` (L, 3), ``half_width`` (L,), ``delta`` (L,), the
    size there, and ``boundary`` (L,) 1 where the model's boundary passes through the leaf,
    with ``predicted_elements``. Arguments as for :func:`predict` (a shape, or BRep text)."""
    sizing = _sizing(min_delta, max_delta, eps, sources)
    threads = _check_int("threads", threads)
    kind, value, label = _cad_source(shape, name)
    if kind != "brep":
        raise ParameterError("size_field takes a shape or BRep text, not a file path")
    return dict(_core.size_field(value, label, sizing, threads, bool(heal),
                                 _cad_modes(solids_only, surface, auto)))


def mesh(shape, order=4, size=None, threads=1, verbosity=0, progress=None, name=None,
         optimise=0, min_delta=None, max_delta=None, eps=None, sources=(), repair_rounds=8,
         boundary_layer=None, cancel=None, optimise_seconds=0.0, linear_seconds=600.0,
         heal=True, job_seconds=0.0, solids_only=False, surface=False, auto=False,
         facet_weight=0.0):
    """Meshes a CAD shape with curved elements of the given order.

    shape     a FreeCAD ``Part.Shape`` (or any object with ``exportBrepToString()``), a path to
              a .step/.stp/.iges/.igs/.brep/.brp file, or BRep text.
    order     polynomial order, 1..10.
    size      a uniform target element size (a positive length) instead of the sizing octree.
    min_delta, max_delta, eps, sources
              sizing octree parameters, as for :func:`predict`; all None (and no size):
              automatic sizing. ``report()`` then has "predicted_elements" and "sizing".
    threads   threads the core may use.
    progress  optional ``callable(stage, seconds)``: called with ``seconds=None`` when a stage
              starts and with its duration when it ends. A callable of four parameters,
              ``(stage, seconds, fraction, detail)``, is also called within stages (the linear
              mesher when Gmsh is done, the optimiser per sweep) with ``seconds=None``, the
              estimated ``fraction`` of the stage done and ``detail`` in words. Raising inside
              it cancels the job (:class:`CancelledError`). It is called on the thread that
              runs :func:`mesh`.
    cancel    optional :class:`CancelToken`: ``cancel.cancel()`` from another thread (a GUI's
              Cancel button while a worker thread runs this) stops the job within a fraction
              of a second with :class:`CancelledError`; the core runs with the GIL released.
    name      how error messages call a shape given as an object or BRep text (for example
              the FreeCAD object's label); default "the shape".
    optimise  > 0: after curving, at most this many sweeps of the variational optimiser
              (hyperelastic; boundary nodes slide on the CAD), stage "optimise".
    optimise_seconds
              > 0: each optimiser run stops after this many seconds with its best state so
              far (``report()["optimiser"]["stopped"] == "time budget"``); 0: no limit.
    facet_weight
              > 0 (0..100; 1 is a good start): once every element is proven valid, the
              optimiser also keeps the boundary facets' nodes evenly spread as they slide on
              the CAD, so the curved boundary stays on it between them
              (``report()["geometry"]``); 0: off.
    linear_seconds
              Gmsh's linear meshing runs in a child process (a crash inside Gmsh becomes a
              :class:`MeshingError`); it is stopped after this many seconds and the job fails
              naming this limit; 0: no limit. ``report()["notes"]`` says when Gmsh crashed and
              was run again another way.
    job_seconds
              > 0: the whole job's wall-time budget, from loading the CAD. Gmsh and every
              optimiser run get at most what is left of it, a repair round starts only if what
              is left covers what the round before took, the geometry check is left out once it
              is spent, and the best mesh so far is returned (not proven valid, perhaps:
              check ``quality()``); ``report()["job"]`` has ``"stopped": "time budget"`` and
              lists what it ``"cut"`` short or ``"skipped"``. Spent before there is a mesh (in
              the CAD, sizing or linear stage): :class:`MeshingError` naming the stage. 0: no
              budget.
    heal      check the CAD after loading and, where the check finds a problem (faces not
              sewn into a solid, OCCT-invalid shapes, edges or faces far smaller than the model),
              repair it with OpenCASCADE's shape healing; ``report()["healing"]`` says what was
              found and done (a healed model's faces are numbered afresh). False: check only.
    solids_only
              faces in no solid (a loose shell beside solids, shells sewing cannot close) are
              left out, and ``report()["healing"]["left_out"]`` and a note say which and where;
              False: such a model is refused (:class:`CadError` naming the faces).
    surface   for a model without solids (a shell, faces that do not close): a surface mesh
              of its faces, triangles curved on the CAD (``dimension`` 2, no plane), sewn
              where faces meet; ``report()["healing"]["surface"]`` says so. No volume, no
              optimiser (a note says so when optimise > 0), no boundary layer. False: such a
              model is refused (:class:`CadError` naming a free edge).
    auto      for batch runs over files nobody looked at: a model with solids is meshed as
              with solids_only; one without a solid is sewn into solids where every shell
              closes (as without auto), else meshed as with surface (planar faces in one
              plane stay 2D); ``report()["healing"]["automatic"]`` and a note say which.
              Not with solids_only or surface. False: faces in no solid and open shells are
              refused by name.
    repair_rounds
              at most this many repair rounds (0..20) while elements are not proven valid:
              each splits the offending linear elements' edges on curved CAD faces (or refines
              around them), then curves, optimises and checks again (stages "repair 1", ...;
              ``report()["rounds"]``). 0: none.
    boundary_layer
              a 3D boundary layer: ``{"faces": [1, 8], "thickness": 0.04, "layers": 6,
              "progression": 1.5}`` (faces as FreeCAD numbers them, FaceN; thickness a number
              or an expression of x, y, z such as ``"0.01+0.05*x"``; layers and progression
              optional, 2 and 2 by default as in NekMesh). A macro prism layer is grown,
              curved and optimised with the rest, then split (``report()["boundary_layer"]``).
              For a NekMesh .mcf file, its BndLayer* keys are used when this is None.

    Raises ParameterError, FileError, CadError, MeshingError or CancelledError.
    """
    order, threads, verbosity, optimise, progress, optimise_seconds = _job_arguments(
        order, threads, verbosity, optimise, progress, cancel, optimise_seconds)
    repair_rounds = _check_int("repair_rounds", repair_rounds)
    limits = {"optimise_seconds": optimise_seconds,
              "linear_seconds": _check_seconds(linear_seconds, "linear_seconds"),
              "job_seconds": _check_seconds(job_seconds, "job_seconds"),
              "facet_weight": _check_number(facet_weight, "facet_weight")}
    if size is not None:
        if isinstance(size, bool) or not isinstance(size, numbers.Real):
            raise ParameterError("size must be a positive number, got %r" % (size,))
        size = float(size)
        if not size > 0.0:
            raise ParameterError("size must be a positive length, got %g" % size)
    sizing = _sizing(min_delta, max_delta, eps, sources)
    if size is not None and sizing is not None:
        raise ParameterError("give either size (uniform) or the sizing octree parameters")

    layer = _boundary_layer(boundary_layer)

    kind, value, label = _cad_source(shape, name)
    if kind == "brep":
        core = _core.mesh_brep(value, label, order, size, threads, verbosity, progress, optimise,
                               sizing, repair_rounds, layer, cancel, limits, bool(heal),
                               _cad_modes(solids_only, surface, auto))
    else:
        core = _core.mesh_file(value, order, size, threads, verbosity, progress, optimise,
                               sizing, repair_rounds, layer, cancel, limits, bool(heal),
                               _cad_modes(solids_only, surface, auto))
    return HighOrderMesh(core)


def _cad_modes(solids_only, surface, auto):
    """The core's one string for the CAD modes asked for (conflicts are the core's to name)."""
    return ",".join(name for name, on in (("solids_only", solids_only), ("surface", surface),
                                          ("auto", auto)) if on)


def _job_arguments(order, threads, verbosity, optimise, progress, cancel, optimise_seconds):
    """The arguments :func:`mesh` and :func:`curve` share, checked (types here, ranges by the
    core): order, threads, verbosity, optimise, the progress callable in the core's
    four-argument form and optimise_seconds."""
    if progress is not None and not callable(progress):
        raise ParameterError("progress must be callable")
    if cancel is not None and not isinstance(cancel, _core.CancelToken):
        raise ParameterError("cancel must be a homesh.CancelToken, got %r" % (cancel,))
    return (_check_int("order", order), _check_int("threads", threads),
            _check_int("verbosity", verbosity), _check_int("optimise", optimise),
            _four_argument_progress(progress), _check_seconds(optimise_seconds))


def _four_argument_progress(progress):
    """The core calls ``progress(stage, seconds, fraction, detail)``; a callable taking two
    parameters gets only the stage starts and ends, as before."""
    if progress is None:
        return None
    import inspect
    try:
        parameters = inspect.signature(progress).parameters.values()
    except (TypeError, ValueError):  # a builtin without a signature: assume the old form
        parameters = ()
    positional = [p for p in parameters
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    if any(p.kind == p.VAR_POSITIONAL for p in parameters) or len(positional) >= 4:
        return progress

    def stages_only(stage, seconds, fraction, detail):
        if seconds is not None or fraction == 0.0 and not detail:
            progress(stage, seconds)

    return stages_only


def curve(shape, nodes, tetrahedra, order=4, threads=1, verbosity=0, progress=None, name=None,
          optimise=0, cancel=None, optimise_seconds=0.0, job_seconds=0.0, facet_weight=0.0):
    """Curves a linear tetrahedral mesh made by another tool (FreeCAD FEM's Gmsh or Netgen
    mesher) on the CAD it was made from.

    shape       as for :func:`mesh` (one solid).
    nodes       (N, 3) coordinates; the boundary nodes must lie on the CAD (within 1e-5 of its
                bounding diagonal).
    tetrahedra  (E, 4) 0-based node indices (either orientation; corner nodes only).

    Each boundary node is put on the CAD vertex, edge or face it lies on, the mesh is raised to
    ``order`` with its boundary nodes on the CAD and, with ``optimise`` > 0, optimised with them
    sliding on it (stages "classify", "high_order", "optimise", ...). progress, cancel,
    optimise_seconds, job_seconds, facet_weight, threads and name as for :func:`mesh`. Raises ParameterError, CadError or MeshingError (naming the
    boundary node that lies on no CAD face).
    """
    order, threads, verbosity, optimise, progress, optimise_seconds = _job_arguments(
        order, threads, verbosity, optimise, progress, cancel, optimise_seconds)
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    tetrahedra = np.ascontiguousarray(tetrahedra, dtype=np.int64)
    if nodes.ndim != 2 or nodes.shape[1] != 3:
        raise ParameterError("nodes must be an (N, 3) array, got shape %s" % (nodes.shape,))
    if tetrahedra.ndim != 2 or tetrahedra.shape[1] != 4:
        raise ParameterError("tetrahedra must be an (E, 4) array of corner nodes, got shape %s"
                             % (tetrahedra.shape,))
    limits = {"optimise_seconds": optimise_seconds,
              "job_seconds": _check_seconds(job_seconds, "job_seconds"),
              "facet_weight": _check_number(facet_weight, "facet_weight")}
    kind, value, label = _cad_source(shape, name)
    if kind == "brep":
        core = _core.curve_brep(value, label, nodes, tetrahedra, order, threads, verbosity,
                                progress, optimise, cancel, limits)
    else:
        core = _core.curve_file(value, nodes, tetrahedra, order, threads, verbosity, progress,
                                optimise, cancel, limits)
    return HighOrderMesh(core)


_BOUNDARY_LAYER_KEYS = ("faces", "thickness", "layers", "progression")


def _boundary_layer(spec):
    """The boundary-layer dict the core takes (keys and types checked here, ranges by the
    core), or None."""
    if spec is None:
        return None
    if not isinstance(spec, dict):
        raise ParameterError("boundary_layer must be a dict with faces and thickness, got %r"
                             % (spec,))
    unknown = sorted(set(spec) - set(_BOUNDARY_LAYER_KEYS))
    if unknown:
        raise ParameterError("boundary_layer: unknown key %r (keys: %s)"
                             % (unknown[0], ", ".join(_BOUNDARY_LAYER_KEYS)))
    for key in ("faces", "thickness"):
        if key not in spec:
            raise ParameterError("boundary_layer needs %r" % key)
    faces = spec["faces"]
    if isinstance(faces, numbers.Integral) and not isinstance(faces, bool):
        faces = [faces]
    out = {"faces": [_check_int("boundary_layer faces", f) for f in faces]}
    thickness = spec["thickness"]
    if isinstance(thickness, bool) or not isinstance(thickness, (numbers.Real, str)):
        raise ParameterError("boundary_layer thickness must be a number or an expression of "
                             "x, y, z, got %r" % (thickness,))
    out["thickness"] = thickness if isinstance(thickness, str) else repr(float(thickness))
    if "layers" in spec:
        out["layers"] = _check_int("boundary_layer layers", spec["layers"])
    if "progression" in spec:
        r = spec["progression"]
        if isinstance(r, bool) or not isinstance(r, numbers.Real):
            raise ParameterError("boundary_layer progression must be a number, got %r" % (r,))
        out["progression"] = float(r)
    return out


def _check_number(value, name, what="a number"):
    """A real number (the core checks its range); ``what`` names it in the message."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError("%s must be %s, got %r" % (name, what, value))
    return float(value)


def _check_seconds(value, name="optimise_seconds"):
    """A time limit in seconds: a number (the core checks its range)."""
    return _check_number(value, name, "a number of seconds")


_INT32_MAX = 2**31 - 1


def _check_int(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ParameterError("%s must be an integer, got %r" % (name, value))
    if not -_INT32_MAX <= value <= _INT32_MAX:
        raise ParameterError("%s is out of range: %d" % (name, value))
    return int(value)


def _cell_dim(element_type):
    return {"line": 1, "tri": 2, "quad": 2}.get(element_type, 3)
