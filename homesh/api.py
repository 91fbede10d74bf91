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
        return "<HighOrderMesh: %s>" % self.headline()

    def headline(self):
        """One line: nodes, elements and order, the certified scaled Jacobian's min and mean,
        and whether every element is proven valid (else how many are not, and where on the CAD).
        The command line prints the same line; a FreeCAD mesh object's Status starts with it."""
        return self._core.headline()

    def summary(self):
        """What the job that made this mesh has to say, the lines ``homesh mesh`` prints: what
        healing did, notes, the sizing and prediction, :meth:`headline`, the boundary layer,
        each repair round and the job's time budget (a list of str)."""
        return list(self._core.summary_lines())

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

    def optimise(self, **options):
        """Curves the interior by the variational optimiser, in place, and returns its record.

        At most ``optimise`` sweeps (the keyword :func:`mesh` uses for the same count); stops
        earlier when no node moves more than ``tolerance`` times its smallest element's size.
        ``region``: move only nodes near elements whose scaled Jacobian is below it (with
        ``region_layers`` layers of neighbours). ``focus``: extra passes over the worst
        elements' nodes after each sweep. On a mesh made from CAD, nodes on CAD curves and faces
        slide on them (CAD vertices stay); on a mesh read from a file, boundary nodes (and nodes
        on interfaces between volumes unless ``free_interfaces``) stay fixed. ``facet_weight``:
        on a mesh made from CAD, once every element is proven valid, also keep the sliding
        boundary facets' nodes evenly spread, so that the curved boundary stays on the CAD
        between them (as in :func:`mesh`); ``fidelity_weight``: also pull the sliding boundary
        facets towards the CAD (distance and normal at their quadrature points), node by node
        once its elements are proven valid.

        The mesh kept is never worse than before in worst scaled Jacobian or invalid count.
        Returns a dict: functional, iterations, converged, stopped (the rule that ended the
        run: displacement, energy, stalled, iterations, time budget, cancelled),
        kept_iteration, worst_before, worst_after, invalid_before, invalid_after,
        nodal_worst_before/after (min J / max J at the nodes, NekMesh's measure), seconds,
        history (per sweep) and more.
        """
        core, record = self._core.optimise(options)
        self.__init__(core)
        return json.loads(record)["optimiser"]

    def geometry(self):
        """How closely the boundary follows the CAD, for a mesh made from CAD or read with
        ``cad=`` (None for a mesh read from a file without it): the report's "geometry" record as a dict, with ``max_distance`` (and
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
        """Writes .msh (Gmsh 4.1), .vtu (VTK Lagrange cells), .xml (Nektar++), .cgns (CGNS,
        orders 1 to 4) or .npz (this object's arrays). ``binary``: binary MSH, raw appended VTU
        data; ``compressed``: compressed Nektar++ XML (B64Z-LittleEndian). ``groups``: named
        boundary groups, a dict such as ``{"wall": [1, 2], "inlet": [3]}`` (boundary faces,
        FaceN; 2D: curves, EdgeN) written as one physical group (MSH), composite (Nektar++) or
        boundary condition (CGNS) each, named so, in place of "FaceN"; VTU has no boundary
        cells, hence no groups."""
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
        # Nektar++ rebuilds 3D element interiors from the faces: the solver's geometry is the
        # file read back, not this mesh; the core says so when it is not proven valid.
        not_proven = self._core.write(path, bool(binary), bool(compressed), pairs)
        if not_proven:
            warnings.warn(not_proven, stacklevel=2)

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
        # The CAD file's numbers to the meshed model's, where healing or imprinting changed
        # them: write(groups=...) of the loaded mesh maps the file's numbers as this one does.
        numbering = self._core.numbering_text()
        if numbering:
            arrays["numbering"] = np.array([numbering])
        try:
            with open(path, "wb") as f:
                np.savez_compressed(f, **arrays)
        except OSError as e:
            raise FileError("cannot write '%s': %s" % (path, e.strerror)) from None


_PARAMETERS = None


def parameters():
    """The core's one parameter table: a list of dicts with key (the keyword of :func:`mesh`),
    property (the FreeCAD property), option (the command line's), label, kind ("integer",
    "real", "length", "boolean", "choice"), min, max, min_exclusive, default (a choice's:
    the index into choices), zero_is_automatic, switchable, group, doc, range (in words) and
    choices (a choice's names). The core, the command line and the FreeCAD objects all check against
    it."""
    global _PARAMETERS
    if _PARAMETERS is None:
        _PARAMETERS = [dict(p) for p in _core.parameters()]
    return [dict(p) for p in _PARAMETERS]


def read(path, cad=None, **options):
    """Reads a mesh file: .msh (Gmsh 2.2 or 4.1, ASCII or binary), .xml (Nektar++, plain or
    compressed), or FreeCAD FEM's .unv (I-DEAS), .vtk (legacy VTK) and .vtu (VTK XML), linear or
    quadratic, and evaluates its quality. Solids a FEM file lists left-handed (FreeCAD's VTK
    export) are read mirrored: ``report()["notes"]`` says so. Raises FileError naming the file,
    the line or data array and the element.

    With ``cad`` (the path of the CAD file the mesh was made from, as ``homesh quality --cad``
    takes it), ``geometry()`` measures how closely the boundary follows it: each boundary cell
    the file holds is put on the CAD face or curve its corners lie on (within
    ``classify_tolerance``), and a corner on no CAD entity raises MeshingError naming it."""
    if cad is None and "classify_tolerance" in options:
        raise ParameterError("read: classify_tolerance needs cad, the CAD file to measure against")
    return HighOrderMesh(_core.read_mesh(os.fspath(path), os.fspath(cad) if cad else "",
                                         options))


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
                blocks, tuple(float(x) for x in data["plane_normal"]),
                str(data["numbering"][0]) if "numbering" in data.files else "")
    except HOMeshError:
        raise
    except (KeyError, ValueError, TypeError, OSError, zipfile.BadZipFile) as e:
        raise FileError("'%s' is not a HOMesh array file: %s" % (path, e)) from None
    return HighOrderMesh(core)


def _sources(sources):
    """Refinement source dicts checked field by field (messages name the source and field)."""
    return [_source(i + 1, src) for i, src in enumerate(sources or ())]


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


def predict(shape, write_octree=None, name=None, sources=(), **options):
    """The element count the linear mesh of a CAD shape will have, without making it.

    Builds the sizing octree (curvature sizes between min_delta and max_delta with sagitta
    ratio eps, graded by 0.2; not given: automatic, see ``homesh mesh --help``) and integrates
    it. sources: refinement regions, dicts such as ``{"kind": "sphere", "a": (0, 0, 0),
    "radius": 1, "delta": 0.05}``, ``{"kind": "segment", "a": ..., "b": ..., "radius": ...,
    "delta": ...}``, ``{"kind": "box", "a": lo, "b": hi, "delta": ...}`` or ``{"kind":
    "curve", "edge": 3, "radius": ..., "delta": ...}``. write_octree: a .vtu path for the
    octree's leaves and sizes. shape may be a NekMesh .mcf path: its CAD (in metres) and,
    unless given here, its sizes are used (likewise in :func:`mesh`). The CAD check and healing
    are as for :func:`mesh` (the prediction is of the model meshed; for a surface mesh, of its
    triangles).

    Returns the report as a dict: "predicted_elements", "dimension" and "sizing" (parameters,
    integrals and octree statistics).
    """
    octree = "" if write_octree is None else os.fspath(write_octree)
    given = dict(options, sources=_sources(sources))
    kind, value, label = _cad_source(shape, name)
    if kind == "brep":
        text = _core.predict_brep(value, label, given, octree)
    else:
        text = _core.predict_file(value, given, octree)
    return json.loads(text)


def size_field(shape, name=None, sources=(), **options):
    """The sizing octree's leaves inside the model or on its boundary, for drawing the size
    field: a dict of numpy arrays ``centre`` (L, 3), ``half_width`` (L,), ``delta`` (L,), the
    size there, and ``boundary`` (L,) 1 where the model's boundary passes through the leaf,
    with ``predicted_elements``. Arguments as for :func:`predict` (a shape, or BRep text)."""
    kind, value, label = _cad_source(shape, name)
    if kind != "brep":
        raise ParameterError("size_field takes a shape or BRep text, not a file path")
    return dict(_core.size_field(value, label, dict(options, sources=_sources(sources))))


def mesh(shape, progress=None, cancel=None, name=None, sources=(), boundary_layer=None,
         **options):
    """Meshes a CAD shape with curved elements of the given order.

    shape     a FreeCAD ``Part.Shape`` (or any object with ``exportBrepToString()``), a path to
              a .step/.stp/.iges/.igs/.brep/.brp file, or BRep text.
    sources   refinement regions of the sizing octree, as for :func:`predict`. With
              min_delta, max_delta, eps or sources (and no size), ``report()`` has
              "predicted_elements" and "sizing"; with none of them, automatic sizing.
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
    boundary_layer
              a 3D boundary layer: ``{"faces": [1, 8], "thickness": 0.04, "layers": 6,
              "progression": 1.5}`` (faces as FreeCAD numbers them, FaceN; thickness a number
              or an expression of x, y, z such as ``"0.01+0.05*x"``; layers and progression
              optional, with the defaults below; ``"solids": [2]``, where a layer face lies
              between two solids, names the one it grows into, SolidN). A macro prism layer is
              grown, curved and optimised with the rest, then split
              (``report()["boundary_layer"]``). For a
              NekMesh .mcf file, its BndLayer* keys are used when this is None.

    The options (keywords, from the one parameter table; None or left out: the default) are
    listed below. ``optimise=True`` asks for the table's default number of sweeps. Elements
    still not proven valid after the optimiser go through the repair rounds; a job's time
    budget (job_seconds) keeps the best mesh so far (``report()["job"]``). Raises
    ParameterError, FileError, CadError, MeshingError or CancelledError.
    """
    layer = _boundary_layer(boundary_layer)
    given = dict(options, sources=_sources(sources), boundary_layer=layer)
    progress = _progress(progress, cancel)
    kind, value, label = _cad_source(shape, name)
    if kind == "brep":
        core = _core.mesh_brep(value, label, given, progress, cancel)
    else:
        core = _core.mesh_file(value, given, progress, cancel)
    return HighOrderMesh(core)


def _progress(progress, cancel):
    """The progress callable in the core's four-argument form, with the types of progress and
    cancel checked."""
    if progress is not None and not callable(progress):
        raise ParameterError("progress must be callable")
    if cancel is not None and not isinstance(cancel, _core.CancelToken):
        raise ParameterError("cancel must be a homesh.CancelToken, got %r" % (cancel,))
    return _four_argument_progress(progress)


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


_CURVE_CELLS = {"tet": 4, "prism": 6, "pyramid": 5, "hex": 8, "tri": 3, "quad": 4}


def curve(shape, nodes, cells, progress=None, cancel=None, name=None, **options):
    """Curves a linear volume mesh made by another tool (FreeCAD FEM's Gmsh or Netgen mesher,
    Gmsh, an industrial mesher's hybrid mesh) on the CAD it was made from, or a planar 2D mesh on
    the faces it was made from.

    shape   as for :func:`mesh` (one solid; for a 2D mesh, faces without a solid).
    nodes   (N, 3) coordinates; the boundary nodes must lie on the CAD (within
            ``classify_tolerance``, by default 1e-5, of its bounding diagonal).
    cells   an (E, 4) array of tetrahedra, or a dict of corner arrays by cell type: ``"tet"``
            (E, 4), ``"prism"`` (E, 6), ``"pyramid"`` (E, 5), ``"hex"`` (E, 8), or in 2D
            ``"tri"`` (E, 3), ``"quad"`` (E, 4); 0-based node indices, corners only, in Gmsh's
            order (either orientation).

    Each boundary node is put on the CAD vertex, edge or face it lies on; prisms stacked on the
    wall (a boundary layer) are joined into one macro prism per column; the mesh is raised to
    ``order`` with its boundary nodes on the CAD and, with ``optimise``, optimised with them
    sliding on it; the macro layer is split back into the given layers (stages "classify",
    "high_order", "optimise", "split_layers", ...). progress, cancel and name as for
    :func:`mesh`; the options are listed below. Raises ParameterError, CadError or MeshingError
    (naming the boundary node that lies on no CAD face, or the cell that cannot be curved).
    """
    progress = _progress(progress, cancel)
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    if nodes.ndim != 2 or nodes.shape[1] != 3:
        raise ParameterError("nodes must be an (N, 3) array, got shape %s" % (nodes.shape,))
    if not isinstance(cells, dict):
        cells = {"tet": cells}
    unknown = sorted(set(cells) - set(_CURVE_CELLS))
    if unknown:
        raise ParameterError("cells: unknown cell type %r (types: %s)"
                             % (unknown[0], ", ".join(_CURVE_CELLS)))
    arrays = {}
    for kind, array in cells.items():
        array = np.ascontiguousarray(array, dtype=np.int64)
        corners = _CURVE_CELLS[kind]
        if array.ndim != 2 or array.shape[1] != corners:
            raise ParameterError("%s cells must be an (E, %d) array of corner nodes, got shape %s"
                                 % (kind, corners, array.shape))
        arrays[kind] = array
    kind, value, label = _cad_source(shape, name)
    if kind == "brep":
        core = _core.curve_brep(value, label, nodes, arrays, options, progress, cancel)
    else:
        core = _core.curve_file(value, nodes, arrays, options, progress, cancel)
    return HighOrderMesh(core)


_BOUNDARY_LAYER_KEYS = ("faces", "thickness", "layers", "progression", "solids")


def _boundary_layer(spec):
    """The boundary-layer dict the core takes (keys, faces and thickness checked here, layers
    and progression by the core), or None."""
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
    solids = spec.get("solids", [])
    if isinstance(solids, numbers.Integral) and not isinstance(solids, bool):
        solids = [solids]
    if solids:
        out["solids"] = [_check_int("boundary_layer solids", s) for s in solids]
    thickness = spec["thickness"]
    if isinstance(thickness, bool) or not isinstance(thickness, (numbers.Real, str)):
        raise ParameterError("boundary_layer thickness must be a number or an expression of "
                             "x, y, z, got %r" % (thickness,))
    out["thickness"] = thickness if isinstance(thickness, str) else repr(float(thickness))
    for key in ("layers", "progression"):  # kind and range: the core's parameter table
        if key in spec:
            out[key] = spec[key]
    return out


_INT32_MAX = 2**31 - 1


def _check_int(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ParameterError("%s must be an integer, got %r" % (name, value))
    if not -_INT32_MAX <= value <= _INT32_MAX:
        raise ParameterError("%s is out of range: %d" % (name, value))
    return int(value)


def _cell_dim(element_type):
    return {"line": 1, "tri": 2, "quad": 2}.get(element_type, 3)


def _keyword_default(p):
    """A table entry's default as a Python keyword's: None where 0 is automatic, False for a
    switchable count (the optimiser is asked for with True or a number)."""
    if p["zero_is_automatic"]:
        return None
    if p["switchable"]:
        return False
    if p["kind"] == "boolean":
        return bool(p["default"])
    if p["kind"] == "choice":
        return p["choices"][int(p["default"])]
    return int(p["default"]) if p["kind"] == "integer" else p["default"]


def _document(function, table_function):
    """Gives ``function`` the table's keywords: a signature that help() and editors show, and a
    docstring section listing each with its default, range and meaning."""
    import inspect
    import textwrap
    table = {p["key"]: p for p in parameters()}
    keys = list(_core.option_keys(table_function))
    signature = inspect.signature(function)
    fixed = [q for q in signature.parameters.values() if q.kind != q.VAR_KEYWORD]
    extra = [inspect.Parameter(k, inspect.Parameter.KEYWORD_ONLY,
                               default=_keyword_default(table[k])) for k in keys]
    function.__signature__ = signature.replace(parameters=fixed + extra)
    lines = ["", "    Options:"]
    for k in keys:
        p = table[k]
        head = "%s = %r: %s" % (k, _keyword_default(p), p["range"])
        if p["zero_is_automatic"]:
            head += " (None: automatic)"
        lines.append(textwrap.fill(head + ". " + p["doc"] + ".", 96,
                                   initial_indent="    ", subsequent_indent="        "))
    function.__doc__ = (function.__doc__ or "").rstrip() + "\n" + "\n".join(lines) + "\n"


_document(mesh, "mesh")
_document(curve, "curve")
_document(predict, "sizing")
_document(size_field, "sizing")
_document(read, "read")
_document(HighOrderMesh.optimise, "optimise")
