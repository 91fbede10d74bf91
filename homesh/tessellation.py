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


def curved_triangles(nodes, elements, order, level):
    """Samples curved triangles (Gmsh order) on a level-``level`` lattice.

    Returns (points (E*k, 3), triangles (E*t, 3) indices into points, owner (E*t,) element).
    """
    ref, sub = triangle_lattice(level)
    basis = _core.lagrange_basis("tri", order, ref)          # (k, nodes per element)
    points = np.einsum("kn,enc->ekc", basis, nodes[elements])  # (E, k, 3)
    count = len(elements)
    offsets = (np.arange(count) * len(ref))[:, None, None]
    triangles = (sub[None, :, :] + offsets).reshape(-1, 3)
    owner = np.repeat(np.arange(count), len(sub))
    return points.reshape(-1, 3), triangles, owner


def triangle_edges(elements, order):
    """Unique edges of triangles (Gmsh order) as order-P line elements (Gmsh line order)."""
    p = order
    seen = {}
    for element in elements:
        for k in range(3):
            a, b = int(element[k]), int(element[(k + 1) % 3])
            inner = [int(n) for n in element[3 + k * (p - 1): 3 + (k + 1) * (p - 1)]]
            key = (min(a, b), max(a, b))
            if key not in seen:
                seen[key] = [a, b] + inner
    return np.array(list(seen.values()), dtype=np.int64).reshape(-1, p + 1)


def curved_polylines(nodes, lines, order, level):
    """Samples order-P lines (Gmsh order) at ``level + 1`` points each: (L, level + 1, 3)."""
    t = np.linspace(0.0, 1.0, level + 1)[:, None]
    basis = _core.lagrange_basis("line", order, t)
    return np.einsum("kn,lnc->lkc", basis, nodes[lines])


def face_owners(elements, element_type, faces):
    """For each boundary triangle (corner nodes = first 3 entries), the index of a volume
    element having it as a face, or -1."""
    if element_type != "tet":
        return np.full(len(faces), -1, dtype=np.int64)
    corners = elements[:, :4]
    lookup = {}
    for e, t in enumerate(corners):
        for skip in range(4):
            key = tuple(sorted(int(t[i]) for i in range(4) if i != skip))
            lookup.setdefault(key, e)
    return np.array([lookup.get(tuple(sorted(int(x) for x in f[:3])), -1) for f in faces],
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

    The drawn surface is the boundary triangles (3D) or the triangles themselves (2D), coloured
    by the scaled Jacobian of the element they belong to. Returns a dict with ``points``,
    ``triangles``, ``colors`` (per triangle), ``edge_points`` and ``edge_polylines``
    (each row indexes edge_points).
    """
    order = mesh.order
    level = level or max(2, 2 * order)
    quality = mesh.quality()["scaled_jacobian"]
    if mesh.dim == 3:
        blocks = [b.elements for b in mesh.boundary if b.element_type == "tri"]
        per_face = (order + 1) * (order + 2) // 2
        faces = np.concatenate(blocks) if blocks else np.zeros((0, per_face), dtype=np.int64)
        owners = face_owners(mesh.elements, mesh.element_type, faces)
        face_quality = np.where(owners >= 0, quality[np.maximum(owners, 0)], 1.0)
    else:
        faces = mesh.elements
        face_quality = quality
    points, triangles, owner = curved_triangles(mesh.nodes, faces, order, level)
    colors = quality_colors(face_quality)[owner]
    edges = triangle_edges(faces, order)
    polylines = curved_polylines(mesh.nodes, edges, order, level)
    edge_points = polylines.reshape(-1, 3)
    edge_index = np.arange(len(edge_points)).reshape(len(edges), level + 1)
    return {"points": points, "triangles": triangles, "colors": colors,
            "edge_points": edge_points, "edge_polylines": edge_index}
