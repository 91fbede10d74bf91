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
    "pyramid": ((0, 1, 2, 3), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)),
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


MEASURES = {"Scaled Jacobian": "scaled_jacobian", "Distortion": "distortion"}


def element_values(mesh, measure="Scaled Jacobian"):
    """Per element (block after block) the measure drawn: the certified scaled Jacobian or
    the sampled distortion quality (both 1 ideal, <= 0 inverted)."""
    return np.asarray(mesh.quality()[MEASURES[measure]], dtype=float)


def _reference_face_points(element_type, face, level):
    """Reference coordinates of a level-``level`` lattice on one face of a volume shape
    (corner indices ``face``), and its sub-triangles."""
    corners = np.asarray(_core.reference_nodes(element_type, 1), dtype=float)[list(face)]
    if len(face) == 3:
        ref, sub = triangle_lattice(level)
        s, t = ref[:, :1], ref[:, 1:]
        points = corners[0] + s * (corners[1] - corners[0]) + t * (corners[2] - corners[0])
    else:
        ref, sub = quad_lattice(level)
        s, t = ref[:, :1], ref[:, 1:]
        points = ((1 - s) * (1 - t) * corners[0] + s * (1 - t) * corners[1]
                  + s * t * corners[2] + (1 - s) * t * corners[3])
    return points, sub


def element_surfaces(mesh, selected, level=None, measure="Scaled Jacobian"):
    """Display geometry of the chosen elements themselves (indices over all elements, block
    after block): every face of each chosen volume element (3D) or the chosen elements (2D),
    sampled through the element's own map, so the inside of the mesh can be seen. Same dict
    as :func:`surface_and_edges` (edges: the chosen elements' face boundaries)."""
    order = mesh.order
    level = level or max(2, 2 * order)
    values = element_values(mesh, measure)
    selected = np.asarray(sorted(set(int(i) for i in selected)), dtype=np.int64)
    points, triangles, colors, polylines = [], [], [], []
    count = 0
    first = 0
    for block in mesh.element_blocks:
        n = len(block.elements)
        mine = selected[(selected >= first) & (selected < first + n)] - first
        first += n
        if len(mine) == 0:
            continue
        nodes = mesh.nodes[block.elements[mine]]  # (e, k, 3)
        block_values = values[mine + first - n]
        faces = _VOLUME_FACES.get(block.element_type) if mesh.dim == 3 else None
        lattices = ([_reference_face_points(block.element_type, f, level) for f in faces]
                    if faces else [_LATTICE[block.element_type](level)])
        for ref, sub in lattices:
            basis = _core.lagrange_basis(block.element_type, order, ref)
            p = np.einsum("kn,enc->ekc", basis, nodes)  # (e, k, 3)
            offsets = (count + np.arange(len(mine)) * len(ref))[:, None, None]
            triangles.append((sub[None, :, :] + offsets).reshape(-1, 3))
            points.append(p.reshape(-1, 3))
            count += p.shape[0] * p.shape[1]
            colors.append(np.repeat(quality_colors(block_values), len(sub), axis=0))
            # The face's boundary, one polyline of level + 1 lattice points per side (so that
            # triangle and quadrilateral faces, as a prism's or a pyramid's, stack alike).
            corners = 3 if len(ref) == (level + 1) * (level + 2) // 2 else 4
            border = _lattice_border(level, corners)
            for side in range(corners):
                polylines.append(p[:, border[side * level:(side + 1) * level + 1], :])
    points = np.concatenate(points) if points else np.zeros((0, 3))
    triangles = np.concatenate(triangles) if triangles else np.zeros((0, 3), dtype=np.int64)
    colors = np.concatenate(colors) if colors else np.zeros((0, 3))
    lines = np.concatenate(polylines) if polylines else np.zeros((0, level + 1, 3))
    edge_points = lines.reshape(-1, 3)
    edge_index = np.arange(len(edge_points)).reshape(len(lines), -1)
    return {"points": points, "triangles": triangles, "colors": colors,
            "edge_points": edge_points, "edge_polylines": edge_index}


def _lattice_border(level, corners):
    """Indices of a triangle_lattice's or quad_lattice's boundary points, in order round the
    face and closed."""
    if corners == 3:
        # triangle_lattice order: rows j, points i = 0..level-j.
        index = {}
        k = 0
        for j in range(level + 1):
            for i in range(level + 1 - j):
                index[(i, j)] = k
                k += 1
        loop = ([index[(i, 0)] for i in range(level + 1)]
                + [index[(level - j, j)] for j in range(1, level + 1)]
                + [index[(0, j)] for j in range(level - 1, -1, -1)])
    else:
        n = level + 1
        loop = ([i for i in range(n)] + [j * n + level for j in range(1, n)]
                + [level * n + i for i in range(level - 1, -1, -1)]
                + [j * n for j in range(level - 1, -1, -1)])
    return np.asarray(loop, dtype=np.int64)


def surface_and_edges(mesh, level=None, measure="Scaled Jacobian"):
    """Display geometry of a :class:`homesh.HighOrderMesh`.

    The drawn surface is the boundary triangles and quadrilaterals (3D) or the elements
    themselves (2D), coloured by ``measure`` (:data:`MEASURES`) of the element they belong to.
    Returns a dict with ``points``, ``triangles``, ``colors`` (per triangle), ``edge_points``
    and ``edge_polylines`` (each row indexes edge_points).
    """
    order = mesh.order
    level = level or max(2, 2 * order)
    quality = element_values(mesh, measure)
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
