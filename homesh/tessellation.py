"""Geometry for drawing curved elements: sub-triangles and polylines sampled through the
elements' own Lagrange maps (pure numpy plus the core's basis; no FreeCAD needed)."""

import numpy as np

from . import _core


def triangle_lattice(level):
    """Reference points and sub-triangles of a triangle split ``level`` times per edge."""
    index = {}
    points = []
    for j in range(level + 1):
        for i in range(level + 1 - j):
            index[(i, j)] = len(points)
            points.append((i / level, j / level))
    tris = []
    for j in range(level):
        for i in range(level - j):
            tris.append((index[(i, j)], index[(i + 1, j)], index[(i, j + 1)]))
            if i + j + 1 < level:
                tris.append((index[(i + 1, j)], index[(i + 1, j + 1)], index[(i, j + 1)]))
    return np.array(points, dtype=float), np.array(tris, dtype=np.int64)


def quad_lattice(level):
    """Reference points and sub-triangles of a quadrilateral split ``level`` times per edge."""
    n = level + 1
    points = [(i / level, j / level) for j in range(n) for i in range(n)]
    tris = []
    for j in range(level):
        for i in range(level):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i
            tris += [(a, b, c), (a, c, d)]
    return np.array(points, dtype=float), np.array(tris, dtype=np.int64)


_LATTICE = {"tri": triangle_lattice, "quad": quad_lattice}
_CORNERS = {"tri": 3, "quad": 4}


def curved_faces(nodes, elements, order, level, element_type="tri"):
    """Samples curved triangles or quadrilaterals (Gmsh order) on a level-``level`` lattice.

    Returns (points (E*k, 3), triangles (E*t, 3) indices into points, owner (E*t,) element).
    """
    ref, sub = _LATTICE[element_type](level)
    basis = _core.lagrange_basis(element_type, order, ref)   # (k, nodes per element)
    points = np.einsum("kn,enc->ekc", basis, nodes[elements])  # (E, k, 3)
    count = len(elements)
    offsets = (np.arange(count) * len(ref))[:, None, None]
    triangles = (sub[None, :, :] + offsets).reshape(-1, 3)
    owner = np.repeat(np.arange(count), len(sub))
    return points.reshape(-1, 3), triangles, owner


def face_edges(elements, order, element_type="tri"):
    """Unique edges of triangles or quadrilaterals (Gmsh order: corners, then the nodes of
    edge 0-1, 1-2, ... in turn) as order-P line elements (Gmsh line order)."""
    p = order
    corners = _CORNERS[element_type]
    seen = {}
    for element in elements:
        for k in range(corners):
            a, b = int(element[k]), int(element[(k + 1) % corners])
            inner = [int(n) for n in element[corners + k * (p - 1): corners + (k + 1) * (p - 1)]]
            key = (min(a, b), max(a, b))
            if key not in seen:
                seen[key] = [a, b] + inner
    return np.array(list(seen.values()), dtype=np.int64).reshape(-1, p + 1)


def curved_polylines(nodes, lines, order, level):
    """Samples order-P lines (Gmsh order) at ``level + 1`` points each: (L, level + 1, 3)."""
    t = np.linspace(0.0, 1.0, level + 1)[:, None]
    basis = _core.lagrange_basis("line", order, t)
    return np.einsum("kn,lnc->lkc", basis, nodes[lines])


# Faces of each volume shape by corner (Gmsh corner order).
_VOLUME_FACES = {
    "tet": ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)),
    "prism": ((0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)),
    "hex": ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)),
}


def face_owners(element_blocks, faces, corners):
    """For each boundary face (its first ``corners`` entries are its corners), the index (over
    all volume elements, block after block) of a volume element having it as a face, or -1."""
    lookup = {}
    first = 0
    for block in element_blocks:
        for e, element in enumerate(block.elements):
            for face in _VOLUME_FACES.get(block.element_type, ()):
                lookup.setdefault(tuple(sorted(int(element[i]) for i in face)), first + e)
        first += len(block.elements)
    return np.array([lookup.get(tuple(sorted(int(x) for x in f[:corners])), -1) for f in faces],
                    dtype=np.int64)


def quality_colors(values):
    """RGB in [0, 1] for scaled-Jacobian values: red (0) - yellow (0.5) - green (1);
    invalid (<= 0) in magenta."""
    q = np.clip(np.asarray(values, dtype=float), 0.0, 1.0)
    red = np.where(q < 0.5, 1.0, 2.0 * (1.0 - q))
    green = np.where(q < 0.5, 2.0 * q, 1.0)
    colors = np.stack([red, green, np.zeros_like(q)], axis=1) * 0.85 + 0.1
    colors[np.asarray(values) <= 0.0] = (0.8, 0.0, 0.8)
    return colors


def surface_and_edges(mesh, level=None):
    """Display geometry of a :class:`homesh.HighOrderMesh`.

    The drawn surface is the boundary triangles and quadrilaterals (3D) or the elements
    themselves (2D), coloured by the scaled Jacobian of the element they belong to. Returns a dict with ``points``,
    ``triangles``, ``colors`` (per triangle), ``edge_points`` and ``edge_polylines``
    (each row indexes edge_points).
    """
    order = mesh.order
    level = level or max(2, 2 * order)
    quality = mesh.quality()["scaled_jacobian"]
    if mesh.dim == 3:
        groups = [(b.element_type, b.elements) for b in mesh.boundary
                  if b.element_type in _LATTICE]
    else:
        groups = [(b.element_type, b.elements) for b in mesh.element_blocks]
    points, triangles, colors, edges = [], [], [], []
    first = 0  # 2D: the group's first element among all elements
    for element_type, faces in groups:
        if mesh.dim == 3:
            owners = face_owners(mesh.element_blocks, faces, _CORNERS[element_type])
            face_quality = np.where(owners >= 0, quality[np.maximum(owners, 0)], 1.0)
        else:
            face_quality = quality[first:first + len(faces)]
            first += len(faces)
        p, t, owner = curved_faces(mesh.nodes, faces, order, level, element_type)
        triangles.append(t + sum(len(x) for x in points))
        points.append(p)
        colors.append(quality_colors(face_quality)[owner])
        edges.append(face_edges(faces, order, element_type))
    points = np.concatenate(points) if points else np.zeros((0, 3))
    triangles = np.concatenate(triangles) if triangles else np.zeros((0, 3), dtype=np.int64)
    colors = np.concatenate(colors) if colors else np.zeros((0, 3))
    edges = np.concatenate(edges) if edges else np.zeros((0, order + 1), dtype=np.int64)
    polylines = curved_polylines(mesh.nodes, edges, order, level)
    edge_points = polylines.reshape(-1, 3)
    edge_index = np.arange(len(edge_points)).reshape(len(edges), level + 1)
    return {"points": points, "triangles": triangles, "colors": colors,
            "edge_points": edge_points, "edge_polylines": edge_index}
