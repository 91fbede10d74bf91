"""FreeCAD FEM both ways.

Quality: :func:`read_fem_mesh` gives a ``Fem::FemMesh`` as it is (linear or quadratic, every
cell) with the certified validity of its curved elements, read from FEM's own UNV writer.

In: the nodes and volume cells of a ``Fem::FemMesh`` (tetrahedra, pyramids, prisms, hexahedra
from FEM's Gmsh or Netgen mesher, first or second order: only the corner nodes are used; a 2D
mesh's triangles and quadrilaterals), for
:func:`homesh.curve` to put on the CAD and curve. Out: a ``Fem::FemMesh`` of order 2 at most
(what FEM's solvers and post-processing hold) from a HOMesh mesh: order 1 and 2 meshes as they are, higher orders through their own map at the
order-2 nodes, so the FEM mesh's edges are the parabolas through the curved elements' midpoints.

Node orders: Gmsh's (ours) and SMESH's (FEM's) tetrahedra are oriented oppositely (SMESH's first
three corners turn clockwise seen from the fourth) and number the mid-edge nodes differently;
``_SMESH_FROM_GMSH`` maps one to the other. Triangles agree.
"""

import os
import shutil
import tempfile

import numpy as np

from .stored_mesh import get_mesh

# SMESH's node k is Gmsh's node _SMESH_FROM_GMSH[type][k] (order 2; order 1: the first corners).
# Tetrahedra: SMESH corners (g0, g2, g1, g3); SMESH edges (0,1) (1,2) (2,0) (0,3) (1,3) (2,3) are
# Gmsh's edges (0,2) (1,2) (0,1) (0,3) (2,3) (1,3), Gmsh's nodes 6, 5, 4, 7, 8, 9.
_SMESH_FROM_GMSH = {"tet": [0, 2, 1, 3, 6, 5, 4, 7, 8, 9], "tri": [0, 1, 2, 3, 4, 5]}
_CORNERS = {"tet": 4, "tri": 3}


# A FEM volume element's type by its node count (SMESH's linear, quadratic and bi/tri-quadratic
# cells) and its corner count: the corners come first in each, and SMESH's corners are Gmsh's up
# to a mirror (pyramids: the base, then the apex; prisms and hexahedra: one end, then the other,
# corner k joined to corner k + 3 or k + 4), which homesh.curve undoes by making cells positive.
_VOLUME_TYPES = {4: ("tet", 4), 10: ("tet", 4), 5: ("pyramid", 5), 13: ("pyramid", 5),
                 6: ("prism", 6), 15: ("prism", 6), 18: ("prism", 6), 8: ("hex", 8),
                 20: ("hex", 8), 27: ("hex", 8)}


# A FEM face element's type by its node count, for a 2D mesh (no volume elements): triangles
# and quadrilaterals, linear or quadratic, corners first.
_FACE_TYPES = {3: ("tri", 3), 6: ("tri", 3), 4: ("quad", 4), 8: ("quad", 4), 9: ("quad", 4)}


def fem_mesh_arrays(fem_mesh):
    """(nodes (N, 3), cells {type: (E, corners) 0-based}) of a ``Fem::FemMesh``'s volume
    elements (tetrahedra, pyramids, prisms, hexahedra, linear or quadratic: their corners, in
    :func:`homesh.curve`'s dict) or, when it has none, of its face elements (a planar 2D mesh:
    triangles, quadrilaterals), with the nodes no corner uses left out. ValueError when it has
    neither or one of another kind."""
    elements, types, what = list(fem_mesh.Volumes), _VOLUME_TYPES, "volume"
    if not elements:
        elements, types, what = list(getattr(fem_mesh, "Faces", ())), _FACE_TYPES, "face"
    if not elements:
        raise ValueError("the FEM mesh has no volume or face elements to curve")
    corners = {}
    for v in elements:
        nodes = fem_mesh.getElementNodes(v)
        if len(nodes) not in types:
            raise ValueError("the FEM mesh has a %s element of %d nodes (element %d): only "
                             "tetrahedra, pyramids, prisms and hexahedra, or in 2D triangles and "
                             "quadrilaterals (linear or quadratic) can be curved"
                             % (what, len(nodes), v))
        kind, count = types[len(nodes)]
        corners.setdefault(kind, []).append(nodes[:count])
    used = sorted({n for cells in corners.values() for c in cells for n in c})
    index = {n: k for k, n in enumerate(used)}
    points = fem_mesh.Nodes
    nodes = np.array([[points[n].x, points[n].y, points[n].z] for n in used], dtype=float)
    cells = {kind: np.array([[index[n] for n in c] for c in cs], dtype=np.int64)
             for kind, cs in corners.items()}
    return nodes, cells


def read_fem_mesh(fem_mesh):
    """A ``Fem::FemMesh`` as a :class:`homesh.HighOrderMesh` with its quality: every cell as FEM
    holds it (tetrahedra and triangles of order 1 or 2, their mid-edge nodes where FEM put them,
    on the CAD for its Gmsh and Netgen meshes), written by FEM itself to a temporary .unv (17
    digits, right-handed) and read by :func:`homesh.read`. Raises homesh.FileError for cells
    HOMesh does not hold (8-node quadrilaterals, 20-node hexahedra, ...), naming the element."""
    from .. import api
    folder = tempfile.mkdtemp(prefix="homesh-fem-")
    try:
        path = os.path.join(folder, "fem_mesh.unv")
        fem_mesh.write(path)
        return api.read(path)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def order_two_elements(mesh):
    """(element type, nodes (N, 3), connectivity (E, k) in Gmsh order) of ``mesh`` at order
    min(order, 2). Orders above 2 are sampled through each element's own map at the order-2
    reference nodes; a node shared by elements (a corner, an edge's midpoint) is made once."""
    from .. import _core
    blocks = mesh.element_blocks
    kinds = sorted({b.element_type for b in blocks})
    if len(blocks) != 1 or kinds[0] not in _CORNERS:
        raise ValueError("a FEM mesh can be made of tetrahedra (triangles in 2D) only; this "
                         "mesh has %s" % ", ".join(kinds))
    block = blocks[0]
    kind = block.element_type
    if mesh.order <= 2:
        return kind, mesh.nodes, block.elements, mesh.order
    ref = np.asarray(_core.reference_nodes(kind, 2), dtype=float)
    basis = _core.lagrange_basis(kind, mesh.order, ref)          # (k2, kP)
    points = np.einsum("kn,enc->ekc", basis, mesh.nodes[block.elements])  # (E, k2, 3)
    corners = _CORNERS[kind]
    edges = _reference_edges(ref, corners)
    ids = {}
    nodes = []
    connectivity = np.empty((len(block.elements), len(ref)), dtype=np.int64)
    for e, element in enumerate(block.elements):
        for k in range(len(ref)):
            if k < corners:
                key = (int(element[k]),)
            else:
                a, b = edges[k]
                key = tuple(sorted((int(element[a]), int(element[b]))))
            node = ids.get(key)
            if node is None:
                node = ids[key] = len(nodes)
                nodes.append(points[e, k])
            connectivity[e, k] = node
    return kind, np.array(nodes), connectivity, 2


def _reference_edges(ref, corners):
    """For each order-2 reference node past the corners, the two corners it lies between."""
    out = {}
    for k in range(corners, len(ref)):
        for a in range(corners):
            for b in range(a + 1, corners):
                if np.allclose(ref[k], 0.5 * (ref[a] + ref[b]), atol=1e-12):
                    out[k] = (a, b)
    return out


def to_fem_mesh(mesh):
    """A ``Fem::FemMesh`` holding ``mesh`` at order min(order, 2) (see order_two_elements)."""
    import Fem
    import FreeCAD
    kind, nodes, connectivity, order = order_two_elements(mesh)
    fem = Fem.FemMesh()
    for i, p in enumerate(nodes):
        fem.addNode(float(p[0]), float(p[1]), float(p[2]), i + 1)
    permutation = _SMESH_FROM_GMSH[kind][:len(connectivity[0])] if order == 2 else \
        _SMESH_FROM_GMSH[kind][:_CORNERS[kind]]
    add = fem.addVolume if kind == "tet" else fem.addFace
    for e, element in enumerate(connectivity):
        add([int(element[k]) + 1 for k in permutation], e + 1)
    fem.Placement = FreeCAD.Placement()
    return fem


def make_fem_mesh_object(doc, obj, name=None):
    """A ``Fem::FemMeshObject`` in ``doc`` holding the mesh of HighOrderMesh ``obj`` at order 2
    at most (FEM's solvers and post-processing take it)."""
    mesh = get_mesh(obj)
    if mesh is None:
        raise ValueError("%s has no mesh (recompute it first)" % obj.Label)
    fem_object = doc.addObject("Fem::FemMeshObject", name or obj.Label + "_FEM")
    fem_object.FemMesh = to_fem_mesh(mesh)
    return fem_object


def is_fem_mesh(obj):
    """Whether ``obj`` is a FEM mesh object (Gmsh, Netgen or plain FemMeshObject)."""
    return obj is not None and hasattr(obj, "FemMesh") and \
        obj.isDerivedFrom("Fem::FemMeshObject")


def fem_shape_object(obj):
    """The shape object a FEM mesh object was made from (FEM's Gmsh and Netgen meshers link it
    as ``Part`` or ``Shape``), or None."""
    for prop in ("Part", "Shape"):
        linked = getattr(obj, prop, None)
        if linked is not None and hasattr(linked, "Shape") and hasattr(linked.Shape, "isNull"):
            return linked
    return None
